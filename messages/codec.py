"""The one wire format of the project.

A payload is the msgpack encoding of a three-element array::

    [FORMAT_TAG, type_name, fields]

``FORMAT_TAG`` is ``"parsimony/<FORMAT_VERSION>"``, ``type_name`` the model's
class name and ``fields`` a map from field name to value, nested models as maps,
tuples as arrays, ``bytes`` as msgpack bin (an image goes on the wire as its raw
pixels, no base64), floats as float64. Decoding checks the tag, the type name
and then every field with the model's own validation in strict mode (no
coercion: a string is not a float, an array is not bytes), so a decoded message
is always a whole, valid one.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any, TypeVar

import msgpack
from pydantic import BaseModel, ValidationError

FORMAT_VERSION = 1
"""Bumped whenever a change makes old payloads unreadable."""

FORMAT_TAG = f"parsimony/{FORMAT_VERSION}"
"""First element of every payload."""

_TAG_FAMILY = "parsimony/"

_INLINE_LIMIT = 4096
"""``bytes`` fields longer than this are spliced into the payload, not packed."""

M = TypeVar("M", bound=BaseModel)


class DecodeError(ValueError):
    """A payload that is not a valid message of the expected type.

    ``key`` is the key expression it came from (may be empty), ``type_name`` the
    expected type's name and ``field`` the dotted path of the offending field
    (``"arm_joints.2"``), empty when the fault is not in one field.
    """

    def __init__(self, key: str, type_name: str, field: str, reason: str) -> None:
        self.key = key
        self.type_name = type_name
        self.field = field
        self.reason = reason
        where = f"{type_name}.{field}" if field else type_name
        super().__init__(f"{key}: {where}: {reason}" if key else f"{where}: {reason}")


def encode(message: BaseModel) -> bytes:
    """The payload of ``message``: msgpack of ``[FORMAT_TAG, type_name, fields]``.

    Large top-level ``bytes`` fields (images) are written last and joined into
    the payload directly, so their content is copied exactly once.
    """
    fields = message.model_dump()
    envelope = [FORMAT_TAG, type(message).__name__, fields]
    large = [name for name, value in fields.items() if _is_large_bytes(value)]
    if not large:
        return msgpack.packb(envelope, use_bin_type=True)
    packer = msgpack.Packer(use_bin_type=True, buf_size=1024)
    parts = [
        packer.pack_array_header(3),
        packer.pack(envelope[0]),
        packer.pack(envelope[1]),
        packer.pack_map_header(len(fields)),
    ]
    for name, value in fields.items():
        if name not in large:
            parts += [packer.pack(name), packer.pack(value)]
    for name in large:
        parts += [packer.pack(name), _bin_header(len(fields[name])), fields[name]]
    return b"".join(parts)


def decode(payload: bytes | bytearray | memoryview, expected: type[M], key: str = "") -> M:
    """The message of type ``expected`` in ``payload``, or ``DecodeError``.

    ``key`` (the key expression the payload arrived on) only serves the error
    message.
    """
    type_name = expected.__name__
    try:
        envelope = msgpack.unpackb(payload, raw=False, use_list=False)
    except (ValueError, msgpack.UnpackException) as error:
        raise DecodeError(key, type_name, "", f"not msgpack ({error})") from error
    fields = _open_envelope(envelope, key, type_name)
    try:
        return expected.model_validate(fields, strict=True)
    except ValidationError as error:
        raise _validation_error(error, key, type_name) from error


def _is_large_bytes(value: object) -> bool:
    return isinstance(value, bytes) and len(value) > _INLINE_LIMIT


def _bin_header(length: int) -> bytes:
    """The msgpack bin 16/32 header of a string longer than ``_INLINE_LIMIT`` bytes."""
    if length < 1 << 16:
        return b"\xc5" + length.to_bytes(2, "big")
    return b"\xc6" + length.to_bytes(4, "big")


def _open_envelope(envelope: Any, key: str, type_name: str) -> dict[str, Any]:
    if not isinstance(envelope, tuple) or len(envelope) != 3:
        raise DecodeError(
            key, type_name, "", "not a parsimony message (expected [tag, type, fields])"
        )
    tag, received_type, fields = envelope
    if tag != FORMAT_TAG:
        if isinstance(tag, str) and tag.startswith(_TAG_FAMILY):
            reason = f"wire format {tag!r} is not supported, expected {FORMAT_TAG!r}"
        else:
            reason = f"not a parsimony message (tag {tag!r}, expected {FORMAT_TAG!r})"
        raise DecodeError(key, type_name, "", reason)
    if received_type != type_name:
        raise DecodeError(key, type_name, "", f"payload holds a {received_type!r}")
    if not isinstance(fields, dict):
        raise DecodeError(key, type_name, "", f"fields are a {type(fields).__name__}, not a map")
    return fields


def _validation_error(error: ValidationError, key: str, type_name: str) -> DecodeError:
    errors = error.errors(include_url=False, include_input=False)
    first = errors[0]
    reason = first["msg"]
    if len(errors) > 1:
        reason += f" (and {len(errors) - 1} more)"
    return DecodeError(key, type_name, _dotted(first["loc"]), reason)


def _dotted(loc: Sequence[int | str]) -> str:
    return ".".join(str(part) for part in loc)
