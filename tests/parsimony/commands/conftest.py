"""Fixtures of the command tests: the launcher's, shared with tests/launch (one definition)."""

from tests.launch.conftest import launch, running_pub, write_profile

__all__ = ["launch", "running_pub", "write_profile"]
