"""The studies: the experiments on the whole simulated loop, the reproduction of chapter 6, the
benchmark, the goal sets and their families, the experiments' gain sets and the bench scripts.

It sits above everything but the command line (``parsimony``), which calls it.
"""
