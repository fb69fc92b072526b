"""Dual-quaternion algebra (wbc/dq.py) against its axioms (sections 3.1-3.2) and DQ Robotics."""

from __future__ import annotations

import math

import dqrobotics
import numpy as np
from dqrobotics import DQ
from hypothesis import given, settings
from hypothesis import strategies as st

from wbc import dq

NO_DEADLINE = settings(deadline=None)

PRODUCT_TOL = 1e-12
LOG_TOL = 1e-9

coordinate = st.floats(-2.0, 2.0, allow_nan=False, allow_infinity=False)
vector3 = st.tuples(coordinate, coordinate, coordinate).map(np.array)
axes = (
    st.tuples(coordinate, coordinate, coordinate)
    .map(np.array)
    .filter(lambda v: np.linalg.norm(v) > 1e-3)
)
# Rotation angles of the double cover, r and -r both occurring; r = -1 itself (angle +-2 pi) is
# left to test_exp_of_log_near_a_full_turn.
angles = st.floats(-2.0 * math.pi + 1e-6, 2.0 * math.pi - 1e-6)
unit_quaternions = st.builds(lambda angle, axis: dq.rotation_quaternion(angle, axis), angles, axes)
unit_dqs = st.builds(dq.pose, unit_quaternions, vector3)
general_dqs = st.tuples(*[coordinate] * 8).map(np.array)
general_quaternions = st.tuples(*[coordinate] * 4).map(np.array)
# Angles in [0, 2 pi): the range of the angle that log (3.16) recovers (r = -1 left out as above).
principal_angles = st.floats(0.0, 2.0 * math.pi - 1e-6)


def assert_close(actual: np.ndarray, expected: np.ndarray, tol: float = PRODUCT_TOL) -> None:
    np.testing.assert_allclose(actual, expected, rtol=0.0, atol=tol)


def vec8(x: DQ) -> np.ndarray:
    return np.asarray(x.vec8())


# --- Algebraic identities -------------------------------------------------------------------


@NO_DEADLINE
@given(general_dqs, general_dqs, general_dqs)
def test_mul_is_associative(a: np.ndarray, b: np.ndarray, c: np.ndarray) -> None:
    assert_close(dq.mul(dq.mul(a, b), c), dq.mul(a, dq.mul(b, c)), 1e-11)


@NO_DEADLINE
@given(general_dqs, general_dqs)
def test_conj_of_product_reverses_the_factors(a: np.ndarray, b: np.ndarray) -> None:
    assert_close(dq.conj(dq.mul(a, b)), dq.mul(dq.conj(b), dq.conj(a)))


@NO_DEADLINE
@given(general_quaternions, general_quaternions)
def test_hamilton_operators_4(a: np.ndarray, b: np.ndarray) -> None:
    """vec4(a b) = H+_4(a) vec4(b) = H-_4(b) vec4(a) (3.7), with i^2 = j^2 = k^2 = ijk = -1."""
    product = dq.qmul(a, b)
    assert_close(dq.hamiplus4(a) @ b, product)
    assert_close(dq.haminus4(b) @ a, product)


def test_quaternion_units_follow_equation_3_1() -> None:
    minus_one = np.array([-1.0, 0, 0, 0])
    for unit in (dq.I_, dq.J_, dq.K_):
        np.testing.assert_array_equal(dq.qmul(unit, unit), minus_one)
    np.testing.assert_array_equal(dq.qmul(dq.qmul(dq.I_, dq.J_), dq.K_), minus_one)
    np.testing.assert_array_equal(dq.qmul(dq.I_, dq.J_), dq.K_)


@NO_DEADLINE
@given(general_dqs, general_dqs)
def test_hamilton_operators_8(a: np.ndarray, b: np.ndarray) -> None:
    """vec8(a b) = H+(a) vec8(b) = H-(b) vec8(a) (3.12)."""
    product = dq.mul(a, b)
    assert_close(dq.hamiplus8(a) @ b, product)
    assert_close(dq.haminus8(b) @ a, product)


@NO_DEADLINE
@given(general_dqs, general_dqs)
def test_product_has_no_eps_squared_term(a: np.ndarray, b: np.ndarray) -> None:
    """(P_a + eps D_a)(P_b + eps D_b) = P_a P_b + eps (P_a D_b + D_a P_b), as eps^2 = 0 (3.10)."""
    expected = np.concatenate(
        (dq.qmul(a[:4], b[:4]), dq.qmul(a[:4], b[4:]) + dq.qmul(a[4:], b[:4]))
    )
    assert_close(dq.mul(a, b), expected)


@NO_DEADLINE
@given(general_dqs)
def test_conjugating_matrices(x: np.ndarray) -> None:
    assert_close(dq.C8 @ x, dq.conj(x))
    assert_close(dq.C4 @ x[:4], dq.qconj(x[:4]))
    assert_close(dq.conj(x), np.concatenate((dq.qconj(x[:4]), dq.qconj(x[4:]))))


@NO_DEADLINE
@given(unit_dqs)
def test_unit_dq_times_its_conjugate_is_one(x: np.ndarray) -> None:
    assert_close(dq.mul(x, dq.conj(x)), dq.ONE)
    assert_close(dq.mul(dq.conj(x), x), dq.ONE)
    assert dq.is_unit(x)


@NO_DEADLINE
@given(unit_dqs, unit_dqs)
def test_norm_of_unit_dqs_is_one_and_multiplicative(a: np.ndarray, b: np.ndarray) -> None:
    assert_close(dq.norm(a), dq.ONE)
    assert_close(dq.norm(dq.mul(a, b)), dq.mul(dq.norm(a), dq.norm(b)))


@NO_DEADLINE
@given(general_dqs.filter(lambda x: np.linalg.norm(x[:4]) > 1e-2))
def test_norm_squared_is_x_conj_x(x: np.ndarray) -> None:
    """||x||^2 = x* x, a dual number (definition 3.11)."""
    norm = dq.norm(x)
    assert np.all(norm[[1, 2, 3, 5, 6, 7]] == 0.0)
    assert_close(dq.mul(norm, norm), dq.mul(dq.conj(x), x), 1e-10)


@NO_DEADLINE
@given(general_dqs.filter(lambda x: np.linalg.norm(x[:4]) > 1e-2))
def test_general_dq_is_not_unit_unless_normalised(x: np.ndarray) -> None:
    scaled = 1.5 * x / np.linalg.norm(x[:4])
    assert not dq.is_unit(scaled)


# --- Rigid motions ----------------------------------------------------------------------------


@NO_DEADLINE
@given(unit_quaternions, vector3)
def test_pose_round_trips_rotation_and_translation(r: np.ndarray, p: np.ndarray) -> None:
    x = dq.pose(r, p)
    assert dq.is_unit(x)
    assert_close(dq.rotation(x), r)
    assert_close(dq.translation(x), np.concatenate(([0.0], p)))
    assert_close(dq.pose(r, np.concatenate(([0.0], p))), x)


def test_rotation_returns_a_copy() -> None:
    x = dq.pose(dq.rotation_quaternion(0.3, [0, 0, 1]), [1.0, 2.0, 3.0])
    r = dq.rotation(x)
    r[0] = 42.0
    assert x[0] != 42.0


@NO_DEADLINE
@given(unit_dqs, unit_dqs)
def test_composition_composes_translations(a: np.ndarray, b: np.ndarray) -> None:
    """x_2^0 = x_1^0 x_2^1: p_02 = p_01 + r_01 p_12 r_01* (definition 3.16)."""
    r_a = dq.rotation(a)
    rotated = dq.qmul(dq.qmul(r_a, dq.translation(b)), dq.qconj(r_a))
    assert_close(dq.translation(dq.mul(a, b)), dq.translation(a) + rotated, 1e-11)


@NO_DEADLINE
@given(unit_dqs)
def test_exp_of_log_is_identity(x: np.ndarray) -> None:
    assert_close(dq.exp(dq.log(x)), x, LOG_TOL)


@NO_DEADLINE
@given(unit_dqs)
def test_log_is_pure(x: np.ndarray) -> None:
    log = dq.log(x)
    assert abs(log[0]) <= PRODUCT_TOL and abs(log[4]) <= PRODUCT_TOL


def test_exp_of_log_near_a_full_turn() -> None:
    """A rotation of 2 pi - 1e-13 has r ~ -1: log must give n phi/2 with phi/2 ~ pi, not Im(r).

    The small-angle limit Im(r) (phi/2) / sin(phi/2) -> Im(r) holds only for phi -> 0.
    """
    x = dq.pose(dq.rotation_quaternion(2.0 * math.pi - 1e-13, [0, 0, 1]), [0.1, 0.2, 0.3])
    assert_close(dq.log(x)[1:4], [0.0, 0.0, math.pi], LOG_TOL)
    assert_close(dq.exp(dq.log(x)), x, LOG_TOL)


@NO_DEADLINE
@given(unit_dqs)
def test_power_one_is_identity(x: np.ndarray) -> None:
    assert_close(dq.power(x, 1.0), x, LOG_TOL)


@NO_DEADLINE
@given(principal_angles, axes, st.floats(-2.0, 2.0))
def test_square_root_squared_is_x_for_a_screw_along_the_axis(
    angle: float, axis: np.ndarray, distance: float
) -> None:
    """With log (3.16) decoupling rotation and translation, x^{1/2} x^{1/2} = x needs p || n."""
    n = axis / np.linalg.norm(axis)
    x = dq.pose(dq.rotation_quaternion(angle, axis), distance * n)
    root = dq.power(x, 0.5)
    assert_close(dq.mul(root, root), x, LOG_TOL)


@NO_DEADLINE
@given(unit_dqs)
def test_square_root_squared_composes_half_translations(x: np.ndarray) -> None:
    """In general x^{1/2} x^{1/2} has rotation r and translation p/2 + r^{1/2} (p/2) r^{1/2}*."""
    root = dq.power(x, 0.5)
    half_r, half_p = dq.rotation(root), 0.5 * dq.translation(x)
    squared = dq.mul(root, root)
    assert_close(dq.rotation(squared), dq.rotation(x), LOG_TOL)
    expected = half_p + dq.qmul(dq.qmul(half_r, half_p), dq.qconj(half_r))
    assert_close(dq.translation(squared), expected, LOG_TOL)


@NO_DEADLINE
@given(principal_angles, axes, vector3)
def test_square_root_is_half_rotation_and_half_translation(
    angle: float, axis: np.ndarray, p: np.ndarray
) -> None:
    """x^{1/2} = r^{1/2} + eps (1/2) (p/2) r^{1/2} (example 3.1)."""
    x = dq.pose(dq.rotation_quaternion(angle, axis), p)
    root = dq.power(x, 0.5)
    assert_close(dq.rotation(root), dq.rotation_quaternion(0.5 * angle, axis), LOG_TOL)
    assert_close(dq.translation(root)[1:], 0.5 * p, LOG_TOL)


@NO_DEADLINE
@given(vector3)
def test_log_of_pure_translation(p: np.ndarray) -> None:
    log = dq.log(dq.pose(dq.ONE[:4], p))
    assert_close(log, np.concatenate((np.zeros(4), [0.0], 0.5 * p)), LOG_TOL)


@NO_DEADLINE
@given(principal_angles, axes)
def test_log_of_pure_rotation(angle: float, axis: np.ndarray) -> None:
    """log r = n phi / 2 (3.16)."""
    n = axis / np.linalg.norm(axis)
    log = dq.log(dq.pose(dq.rotation_quaternion(angle, axis), np.zeros(3)))
    assert_close(log, np.concatenate(([0.0], 0.5 * angle * n, np.zeros(4))), LOG_TOL)


@NO_DEADLINE
@given(unit_dqs, unit_dqs)
def test_nearest_equivalent_picks_the_closer_sign(x_desired: np.ndarray, x: np.ndarray) -> None:
    chosen = dq.nearest_equivalent(x_desired, x)
    assert np.array_equal(chosen, x_desired) or np.array_equal(chosen, -x_desired)
    assert np.linalg.norm(x - chosen) <= np.linalg.norm(x + chosen)


def test_nearest_equivalent_flips_an_opposite_sign() -> None:
    x = dq.pose(dq.rotation_quaternion(0.2, [1, 0, 0]), [0.5, 0.0, 0.0])
    np.testing.assert_array_equal(dq.nearest_equivalent(-x, x), x)
    np.testing.assert_array_equal(dq.nearest_equivalent(x, x), x)


# --- Against DQ Robotics ----------------------------------------------------------------------


@NO_DEADLINE
@given(general_dqs, general_dqs)
def test_mul_matches_dqrobotics(a: np.ndarray, b: np.ndarray) -> None:
    assert_close(dq.mul(a, b), vec8(DQ(a) * DQ(b)))


@NO_DEADLINE
@given(general_dqs)
def test_conj_matches_dqrobotics(x: np.ndarray) -> None:
    assert_close(dq.conj(x), vec8(dqrobotics.conj(DQ(x))))


@NO_DEADLINE
@given(general_dqs)
def test_hamilton_operators_match_dqrobotics(x: np.ndarray) -> None:
    assert_close(dq.hamiplus8(x), dqrobotics.hamiplus8(DQ(x)))
    assert_close(dq.haminus8(x), dqrobotics.haminus8(DQ(x)))
    assert_close(dq.hamiplus4(x[:4]), dqrobotics.hamiplus4(DQ(x[:4])))
    assert_close(dq.haminus4(x[:4]), dqrobotics.haminus4(DQ(x[:4])))


@NO_DEADLINE
@given(unit_dqs)
def test_translation_matches_dqrobotics(x: np.ndarray) -> None:
    assert_close(dq.translation(x), np.asarray(dqrobotics.translation(DQ(x)).vec4()))


# DQ Robotics takes the angle as 2 acos(Re r), which loses digits near r = +-1; stay away.
log_compatible_dqs = st.builds(
    dq.pose,
    st.builds(dq.rotation_quaternion, st.floats(0.01, 2.0 * math.pi - 0.01), axes),
    vector3,
)


@NO_DEADLINE
@given(log_compatible_dqs)
def test_log_matches_dqrobotics(x: np.ndarray) -> None:
    assert_close(dq.log(x), vec8(dqrobotics.log(DQ(x))), LOG_TOL)


@NO_DEADLINE
@given(log_compatible_dqs)
def test_exp_matches_dqrobotics(x: np.ndarray) -> None:
    a = dq.log(x)
    assert_close(dq.exp(a), vec8(dqrobotics.exp(DQ(a))), LOG_TOL)


@NO_DEADLINE
@given(log_compatible_dqs, st.floats(-2.0, 2.0))
def test_power_matches_dqrobotics(x: np.ndarray, exponent: float) -> None:
    assert_close(dq.power(x, exponent), vec8(dqrobotics.pow(DQ(x), exponent)), LOG_TOL)


@NO_DEADLINE
@given(general_dqs.filter(lambda x: np.linalg.norm(x[:4]) > 1e-2))
def test_norm_matches_dqrobotics(x: np.ndarray) -> None:
    assert_close(dq.norm(x), vec8(dqrobotics.norm(DQ(x))), 1e-10)


def test_rotation_matrix_and_its_quaternion_round_trip() -> None:
    rng = np.random.default_rng(7)
    for _ in range(200):
        r = dq.rotation_quaternion(rng.uniform(-math.pi, math.pi), rng.normal(size=3))
        matrix = dq.rotation_matrix(r)
        v = rng.normal(size=3)
        rotated = dq.qmul(dq.qmul(r, np.concatenate(([0.0], v))), dq.qconj(r))[1:]
        np.testing.assert_allclose(matrix @ v, rotated, atol=1e-12)
        back = dq.quaternion_of_matrix(matrix)
        np.testing.assert_allclose(back, r if r[0] >= 0 else -r, atol=1e-12)
