"""Parsimony: whole-body LP control of nonholonomic mobile manipulators."""
