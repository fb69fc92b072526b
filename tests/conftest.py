"""How the suite runs in parallel (pytest-xdist, ``--dist loadgroup``).

Tests that share a set-up wider than one test (a module- or session-scoped fixture of the
project's: a launched system, a recorded run) run on one worker, so the set-up runs once;
every other test goes to whichever worker is free. Tests marked ``heavy`` (minutes each) are
handed out first, so none of them starts last and finishes after all the others.
"""

from __future__ import annotations

from collections.abc import Iterator

import pytest

SHARED_SCOPES = ("module", "package", "session")


def _shared_group(item: pytest.Item) -> str | None:
    """The set-up ``item`` shares with other tests: its widest fixture of the project's."""
    definitions = getattr(item, "_fixtureinfo", None)
    if definitions is None:
        return None
    widest: tuple[int, str] | None = None
    for name, defs in definitions.name2fixturedefs.items():
        definition = defs[-1]
        if definition.scope not in SHARED_SCOPES:
            continue
        if not definition.baseid:
            continue  # a plugin's (tmp_path_factory, ...), nothing expensive
        rank = SHARED_SCOPES.index(definition.scope)
        key = (
            item.nodeid.split("::")[0]
            if definition.scope == "module"
            else f"{definition.baseid}:{name}"
        )
        if widest is None or rank > widest[0]:
            widest = (rank, key)
    return None if widest is None else widest[1]


@pytest.hookimpl(wrapper=True)
def pytest_collection_modifyitems(items: list[pytest.Item]) -> Iterator[None]:
    """Grouped before any other plugin's hook runs: xdist reads the groups in its own."""
    for item in items:
        group = _shared_group(item)
        if group is not None and item.get_closest_marker("xdist_group") is None:
            item.add_marker(pytest.mark.xdist_group(group))
    items.sort(key=lambda item: item.get_closest_marker("heavy") is None)  # stable
    return (yield)
