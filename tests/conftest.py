"""How the suite runs in parallel (pytest-xdist, ``--dist loadfile``: see the Makefile).

Each test file runs on one worker, so a set-up it shares between its tests (a module-scoped
fixture: a launched system, a recorded run) runs once. Tests marked ``heavy`` (minutes each)
are handed out first, so none of them starts last and finishes after all the others.
"""

from __future__ import annotations

import pytest


def pytest_collection_modifyitems(items: list[pytest.Item]) -> None:
    items.sort(key=lambda item: item.get_closest_marker("heavy") is None)  # stable
