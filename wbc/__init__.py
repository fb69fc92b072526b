"""Whole-body control: the mathematics, no I/O, importing no other package of the project.

Its floors, each importing only the floors below it, none in a circle (tests/wbc mirrors them):

    wbc/planning/  where the base goes and when the arm reaches: the drive planner round the
                   discs, the staging of the base, the staging supervisor and its phases
    wbc/laws/      the control laws (the LP of 5.29, the QP, the pseudo-inverse and the
                   cascade), the LP's constraints and objective terms, gains, kinematic runs
    wbc/geometry/  the obstacles, the distances of the robot's parts from them and their
                   Jacobians, and the scenes of the chapter 6 experiments
    wbc/           the kinematics: dual quaternions, the robot and its collision parts, tasks,
                   SE(2), the base's motion and its estimate, the pose filter, the whole body's
                   conditioning, the input checks
"""
