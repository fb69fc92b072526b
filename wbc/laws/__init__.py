"""The control laws: the LP (5.29) with its constraints (``constraints``) and objective terms
(``objectives``), the QP, the pseudo-inverse and cascade laws, their gains and outputs, and
kinematic runs of any of them. Imports the collision geometry and the kinematics only."""
