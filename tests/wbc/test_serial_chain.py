"""A serial arm as its constant parts (wbc.serial_chain): a DH link against the homogeneous
transform Rz(theta) Tz(d) Tx(a) Rx(alpha) built by hand, a chain's links at any q from its
constant parts, and the DH tables and names it refuses."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc import dq
from wbc.serial_chain import RobotDescriptionError, dh_link, from_dh

DH = np.array(
    [
        [0.3, 0.0, -0.4],  # theta
        [0.2, 0.1, 0.05],  # d
        [0.0, 0.25, 0.1],  # a
        [math.pi / 2, 0.0, -0.7],  # alpha
        [0.0, 1.0, 0.0],  # type: revolute, prismatic, revolute
    ]
)


def homogeneous(theta: float, d: float, a: float, alpha: float) -> np.ndarray:
    ct, st, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    rz = np.array([[ct, -st, 0, 0], [st, ct, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]])
    rx = np.array([[1, 0, 0, 0], [0, ca, -sa, 0], [0, sa, ca, 0], [0, 0, 0, 1]])
    tz, tx = np.eye(4), np.eye(4)
    tz[2, 3], tx[0, 3] = d, a
    return rz @ tz @ tx @ rx


def as_matrix(pose: np.ndarray) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3] = dq.rotation_matrix(pose[:4])
    matrix[:3, 3] = dq.translation(pose)[1:]
    return matrix


@pytest.mark.parametrize("link", [(0.3, 0.2, 0.0, math.pi / 2), (-1.1, -0.05, 0.4, -0.7)])
def test_a_dh_link_is_rz_tz_tx_rx(link: tuple[float, float, float, float]) -> None:
    np.testing.assert_allclose(as_matrix(dh_link(*link)), homogeneous(*link), atol=1e-12)


@pytest.mark.parametrize("q", [0.0, 0.4, -1.3])
def test_each_link_at_q_is_its_dh_link_moved_by_its_joint(q: float) -> None:
    """A revolute joint adds q to theta (cos(q/2) A + sin(q/2) B), a prismatic one to d
    (A + q B); H+(x) 1 = x reads the link off its operator."""
    chain = from_dh(DH)
    for i, kind in enumerate(chain.types):
        theta, d, a, alpha = DH[:4, i]
        if kind == "revolute":
            operator = math.cos(q / 2) * chain.link_cos[i] + math.sin(q / 2) * chain.link_sin[i]
            expected = homogeneous(theta + q, d, a, alpha)
        else:
            operator = chain.link_cos[i] + q * chain.link_sin[i]
            expected = homogeneous(theta, d + q, a, alpha)
        np.testing.assert_allclose(as_matrix(operator @ dq.ONE), expected, atol=1e-12)


def test_a_chain_names_and_kinds_its_joints() -> None:
    chain = from_dh(DH)
    assert chain.names == ("q1", "q2", "q3") and chain.dof == 3
    assert chain.prismatic.tolist() == [False, True, False]
    assert chain.shared_axis is None  # a prismatic joint's axis is its own
    revolute = DH.copy()
    revolute[4] = 0.0
    assert from_dh(revolute, ["a", "b", "c"]).shared_axis is not None


@pytest.mark.parametrize(
    ("dh", "names", "complaint"),
    [
        (np.zeros((4, 3)), None, r"dh: expected shape \(5, 3\)"),
        (np.where(np.arange(5)[:, None] == 4, 2.0, DH), None, "dh.type: expected revolute"),
        (np.where(np.isclose(DH, 0.25), np.nan, DH), None, "dh: values must be finite"),
        (DH, ["a", "a", "b"], "names: expected 3 different names"),
        (DH, ["a", "b"], "names: expected 3 different names"),
    ],
)
def test_a_table_or_names_that_cannot_be_a_chain_are_refused_naming_the_field(
    dh: np.ndarray, names: list[str] | None, complaint: str
) -> None:
    with pytest.raises(RobotDescriptionError, match=complaint):
        from_dh(dh, names)
