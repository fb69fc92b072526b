"""YAML text parsed by libyaml where PyYAML has it (several times faster: every process reads its
profile and its robot at start), told in PyYAML's own words when it is not YAML."""

from __future__ import annotations

import yaml

FAST_LOADER: type = getattr(yaml, "CSafeLoader", yaml.SafeLoader)
"""libyaml's safe loader (PyYAML's own where it was built without it): the same constructor."""


def parse_yaml(
    text: str, name: str, fast: type = FAST_LOADER, slow: type = yaml.SafeLoader
) -> object:
    """The document in ``text`` (the file ``name``), read by the ``fast`` loader; a document it
    refuses is read again by the ``slow`` one (PyYAML's parser), whose ``yaml.YAMLError`` says
    where and what, as it always said."""
    try:
        return _load(fast, text, name)
    except yaml.YAMLError:
        pass  # libyaml says it in other words: read again for PyYAML's
    return _load(slow, text, name)


def _load(loader_class: type, text: str, name: str) -> object:
    loader = loader_class(text)
    loader.name = name
    try:
        return loader.get_single_data()
    finally:
        loader.dispose()


def error_place(error: yaml.YAMLError, name: str) -> str:
    """``name:line:column`` of a YAML error that has a mark, else ``name``."""
    mark = getattr(error, "problem_mark", None)
    return f"{name}:{mark.line + 1}:{mark.column + 1}" if mark else name
