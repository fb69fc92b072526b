"""Collision geometry: the obstacles (circles in the plane, solids in 3-D), the distances of
the robot's parts from them and those distances' Jacobians, and the chapter 6 experiments'
scenes. Imports the kinematics at ``wbc/`` root only."""
