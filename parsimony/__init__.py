"""Parsimony: whole-body LP control of nonholonomic mobile manipulators.

``parsimony launch`` holds OpenBLAS to one thread (unless the environment says otherwise),
before anything imports NumPy: its launcher then has one thread until its router opens, and
forks its fork server (``launch.fork_server``) instead of starting an interpreter for it. Its
components compute on matrices of a few dozen rows, which one thread serves (the server's
children have one already)."""

import os
import sys

if sys.argv[1:2] == ["launch"]:
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
