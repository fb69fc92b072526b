"""Arrays a term of the LP returns unchanged at every step (a switched-off term's rows, a unit
row, a zero bound): read-only and alive for the whole process, so that a step which finds one
in the place it held at the last step knows its numbers unchanged, and the program's buffers
(``wbc.laws.lp_layout``) are not written again."""

from __future__ import annotations

import functools

import numpy as np

Array = np.ndarray

KEPT: dict[int, Array] = {}
"""Every kept array by its id; the dict holds each alive, so no other object takes its id."""


def kept(array: Array) -> Array:
    """``array``, read-only from now on and kept (``KEPT``)."""
    array.flags.writeable = False
    KEPT[id(array)] = array
    return array


@functools.cache
def zeros(*shape: int) -> Array:
    """A kept array of zeros of ``shape``, one per shape."""
    return kept(np.zeros(shape))
