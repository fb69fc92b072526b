"""A profile's YAML files: read safely (UTF-8, no alias bomb), ``extends`` resolved and merged
into one mapping, the paths it names made absolute; what ``profiles.profile`` validates."""

from __future__ import annotations

from pathlib import Path

import yaml

from wbc.yaml_text import FAST_LOADER, error_place, parse_yaml

TLS_FILES = ("root_ca_certificate", "listen_certificate", "listen_private_key")
"""The files of a profile's ``zenoh.tls``: made absolute against the file that names them."""


class ProfileError(Exception):
    """A profile that cannot be used; the message says where and what was expected."""


MAX_YAML_VALUES = 100_000
"""A profile expands to at most this many YAML values, aliases counted where they point."""


class _Bounded:
    """A safe YAML loader whose document, aliases expanded, holds at most ``MAX_YAML_VALUES``
    values: a few hundred bytes of aliases inside aliases expand into gigabytes (an alias bomb)."""

    name: str

    def get_single_node(self):  # noqa: ANN201 - PyYAML's own signature
        node = super().get_single_node()
        if node is not None and _expanded(node, {}) > MAX_YAML_VALUES:
            raise ProfileError(
                f"{self.name}: expands to more than {MAX_YAML_VALUES} values "
                "(aliases inside aliases?)"
            )
        return node


class _ProfileLoader(_Bounded, yaml.SafeLoader):
    """PyYAML's own parser: the one whose words a syntax error is told in."""


class _FastProfileLoader(_Bounded, FAST_LOADER):
    """libyaml's parser where PyYAML has it (``wbc.yaml_text``)."""


def _expanded(node: yaml.Node, sizes: dict[int, int]) -> int:
    """How many values ``node`` stands for once every alias is expanded (each shared node
    counted once per use, computed once)."""
    if id(node) not in sizes:
        if isinstance(node, yaml.SequenceNode):
            children = node.value
        elif isinstance(node, yaml.MappingNode):
            children = [item for pair in node.value for item in pair]
        else:
            children = []
        sizes[id(node)] = 1 + sum(_expanded(child, sizes) for child in children)
    return sizes[id(node)]


def _read_yaml(path: Path) -> object:
    try:
        text = path.read_bytes().decode("utf-8")
    except OSError as error:
        raise ProfileError(f"{path}: cannot read profile: {error.strerror}") from error
    except UnicodeDecodeError as error:
        raise ProfileError(f"{path}: not UTF-8 text (byte {error.start})") from None
    try:
        return parse_yaml(text, str(path), _FastProfileLoader, _ProfileLoader)
    except yaml.YAMLError as error:
        problem = getattr(error, "problem", None) or str(error)
        raise ProfileError(
            f"{error_place(error, str(path))}: YAML syntax error: {problem}"
        ) from error


def merge(base: object, override: object) -> object:
    """``override`` laid over ``base``: mappings merge key by key, ``components`` by name (an
    entry with a known name merges into it, a new name is appended), anything else is replaced.
    """
    if isinstance(base, dict) and isinstance(override, dict):
        merged = dict(base)
        for key, value in override.items():
            if key == "components" and isinstance(value, list) and isinstance(base.get(key), list):
                merged[key] = _merge_components(base[key], value)
            else:
                merged[key] = merge(base[key], value) if key in base else value
        return merged
    return override


def _merge_components(base: list, override: list) -> list:
    merged = list(base)
    names = [entry.get("name") if isinstance(entry, dict) else None for entry in base]
    for entry in override:
        name = entry.get("name") if isinstance(entry, dict) else None
        if name is not None and name in names:
            index = names.index(name)
            merged[index] = merge(merged[index], entry)
        else:
            merged.append(entry)
    return merged


def read_profile_data(path: Path, chain: tuple[Path, ...] = ()) -> dict:
    """The profile's mapping, with ``extends: other.yaml`` (relative to the file) resolved.

    A relative ``robot`` path is made absolute against the file that names it.
    """
    data = _read_yaml(path)
    if not isinstance(data, dict):
        got = type(data).__name__
        raise ProfileError(f"{path}: expected a mapping at the top level, got {got}")
    if isinstance(data.get("robot"), str):
        data["robot"] = str((path.parent / data["robot"]).resolve())
    settings = data.get("zenoh") if isinstance(data.get("zenoh"), dict) else {}
    for section, names in (("access", ("credentials",)), ("tls", TLS_FILES)):
        files = settings.get(section)
        for name in names if isinstance(files, dict) else ():
            if isinstance(files.get(name), str):
                files[name] = str((path.parent / files[name]).resolve())
    parent = data.pop("extends", None)
    if parent is None:
        return data
    if not isinstance(parent, str):
        raise ProfileError(f"{path}: extends: expected the path of a profile, got {parent!r}")
    base_path = (path.parent / parent).resolve()
    if base_path in chain or base_path == path.resolve():
        cycle = " -> ".join(str(p) for p in (*chain, path.resolve(), base_path))
        raise ProfileError(f"{path}: extends: profiles extend each other in a circle: {cycle}")
    if not base_path.is_file():
        raise ProfileError(f"{path}: extends: no profile at {base_path}")
    base = read_profile_data(base_path, (*chain, path.resolve()))
    return merge(base, data)  # type: ignore[return-value]
