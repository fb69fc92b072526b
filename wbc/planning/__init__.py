"""Planning: where the base goes and when the arm reaches (the drive planner round the discs,
the staging of the base, the staging supervisor and its phases, the drive tasks). Imports the
laws, the collision geometry and the kinematics; nothing in ``wbc`` imports it."""
