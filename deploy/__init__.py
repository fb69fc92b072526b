"""Deploy profiles, the robot descriptions and the launcher."""
