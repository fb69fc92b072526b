"""Dual-quaternion algebra (dissertation sections 3.1 and 3.2).

A quaternion is a numpy array ``[h1, h2, h3, h4]`` = h1 + i h2 + j h3 + k h4 (vec4, 3.5);
a dual quaternion is ``[h1..h8]`` = (h1 + i h2 + j h3 + k h4) + eps (h5 + i h6 + j h7 + k h8)
(vec8, the order of DQ Robotics). Functions take and return such arrays; the Hamilton
operators turn products into matrix products: vec(a b) = H+(a) vec(b) = H-(b) vec(a) (3.7, 3.12).
"""

from __future__ import annotations

import math

import numpy as np

Array = np.ndarray

# H+_4(h)[r, c] = sign * h[index]: the table form of eq. 3.6, built once.
_PLUS4_INDEX = np.array([[0, 1, 2, 3], [1, 0, 3, 2], [2, 3, 0, 1], [3, 2, 1, 0]])
_PLUS4_SIGN = np.array([[1, -1, -1, -1], [1, 1, -1, 1], [1, 1, 1, -1], [1, -1, 1, 1]], float)
_MINUS4_SIGN = np.array([[1, -1, -1, -1], [1, 1, 1, -1], [1, -1, 1, 1], [1, 1, -1, 1]], float)


def _block_tables(sign4: Array) -> tuple[Array, Array]:
    """Index and sign tables of the 8x8 operator [[H(P), 0], [H(D), H(P)]] (3.12).

    Entries of the zero block index element 8 of a 9-vector whose last entry is 0.
    """
    index = np.full((8, 8), 8)
    sign = np.zeros((8, 8))
    index[:4, :4] = index[4:, 4:] = _PLUS4_INDEX
    index[4:, :4] = _PLUS4_INDEX + 4
    sign[:4, :4] = sign[4:, 4:] = sign[4:, :4] = sign4
    return index, sign


_PLUS8_INDEX, _PLUS8_SIGN = _block_tables(_PLUS4_SIGN)
_MINUS8_INDEX, _MINUS8_SIGN = _block_tables(_MINUS4_SIGN)
_ZERO = np.zeros(1)
_CONJ8 = np.array([1.0, -1, -1, -1, 1, -1, -1, -1])
C4 = np.diag([1.0, -1, -1, -1])
"""Conjugating matrix: vec4(h*) = C4 vec4(h) (3.8)."""
C8 = np.diag(_CONJ8)
"""vec8(x*) = C8 vec8(x)."""

ONE = np.array([1.0, 0, 0, 0, 0, 0, 0, 0])
I_ = np.array([0.0, 1, 0, 0])
J_ = np.array([0.0, 0, 1, 0])
K_ = np.array([0.0, 0, 0, 1])


def hamiplus4(h: Array) -> Array:
    """H+_4(h), with vec4(h a) = H+_4(h) vec4(a) (3.6)."""
    return h[_PLUS4_INDEX] * _PLUS4_SIGN


def haminus4(h: Array) -> Array:
    """H-_4(h), with vec4(a h) = H-_4(h) vec4(a) (3.6)."""
    return h[_PLUS4_INDEX] * _MINUS4_SIGN


def hamiplus8(x: Array) -> Array:
    """H+(x) = [[H+_4(P), 0], [H+_4(D), H+_4(P)]], with vec8(x a) = H+(x) vec8(a) (3.12)."""
    return np.concatenate((x, _ZERO))[_PLUS8_INDEX] * _PLUS8_SIGN


def haminus8(x: Array) -> Array:
    """H-(x) = [[H-_4(P), 0], [H-_4(D), H-_4(P)]], with vec8(a x) = H-(x) vec8(a) (3.12)."""
    return np.concatenate((x, _ZERO))[_MINUS8_INDEX] * _MINUS8_SIGN


def hamiplus4_stack(h: Array) -> Array:
    """H+_4 of each quaternion of a stack (k, 4): (k, 4, 4)."""
    return h[:, _PLUS4_INDEX] * _PLUS4_SIGN


def haminus4_stack(h: Array) -> Array:
    """H-_4 of each quaternion of a stack (k, 4): (k, 4, 4)."""
    return h[:, _PLUS4_INDEX] * _MINUS4_SIGN


def haminus8_stack(x: Array) -> Array:
    """H- of each dual quaternion of a stack (k, 8): (k, 8, 8). One call for k frames costs
    about what one ``haminus8`` does."""
    padded = np.concatenate((x, np.zeros((x.shape[0], 1))), axis=1)
    return padded[:, _MINUS8_INDEX] * _MINUS8_SIGN


def qmul(a: Array, b: Array) -> Array:
    """Hamilton product of two quaternions (3.1)."""
    return hamiplus4(a) @ b


def qconj(h: Array) -> Array:
    """Quaternion conjugate h* = Re(h) - Im(h) (3.3)."""
    return h * _CONJ8[:4]


def mul(a: Array, b: Array) -> Array:
    """Dual-quaternion product, with eps^2 = 0 (3.10)."""
    return hamiplus8(a) @ b


def conj(x: Array) -> Array:
    """Dual-quaternion conjugate x* = P(x)* + eps D(x)* (3.11)."""
    return x * _CONJ8


def primary(x: Array) -> Array:
    """P(x), the primary part (a quaternion)."""
    return x[:4]


def dual(x: Array) -> Array:
    """D(x), the dual part (a quaternion)."""
    return x[4:]


def from_parts(p: Array, d: Array) -> Array:
    """The dual quaternion p + eps d."""
    return np.concatenate((p, d))


def norm(x: Array) -> Array:
    """||x|| = sqrt(x* x), a dual number returned as a dual quaternion (definition 3.11).

    For x* x = a + eps b (a > 0, both real), sqrt is sqrt(a) + eps b / (2 sqrt(a)).
    """
    squared = mul(conj(x), x)
    a, b = squared[0], squared[4]
    root = math.sqrt(a)
    out = np.zeros(8)
    out[0] = root
    out[4] = b / (2.0 * root) if root > 0.0 else 0.0
    return out


def normalize(x: Array) -> Array:
    """The unit dual quaternion nearest x: P' = P/|P|, D' = D/|P| - (P'.D/|P|) P', so that
    |P'| = 1 and P'.D' = 0 (removes the drift of long products of measured poses)."""
    scale = float(np.linalg.norm(x[:4]))
    p, d = x[:4] / scale, x[4:] / scale
    return from_parts(p, d - float(np.dot(p, d)) * p)


def is_unit(x: Array, tol: float = 1e-9) -> bool:
    """True when x* x = 1, i.e. x represents a rigid motion."""
    return bool(np.allclose(mul(conj(x), x), ONE, atol=tol))


def rotation_quaternion(angle: float, axis: Array) -> Array:
    """r = cos(phi/2) + n sin(phi/2) for a unit axis n (3.13)."""
    axis = np.asarray(axis, dtype=float)
    half = 0.5 * angle
    return np.concatenate(([math.cos(half)], math.sin(half) * axis / np.linalg.norm(axis)))


def rotation_matrix(r: np.ndarray) -> np.ndarray:
    """R with R v = Im(r v r*): the lower 3x3 of H+(r) H-(r*) (3.6)."""
    return (hamiplus4(r) @ haminus4(qconj(r)))[1:, 1:]


def quaternion_of_matrix(rotation: np.ndarray) -> np.ndarray:
    """The unit quaternion r (r_1 >= 0) of a rotation matrix, by Shepperd's method."""
    m = rotation
    trace = np.trace(m)
    squares = np.array([1.0 + trace, 1.0 + 2.0 * m[0, 0] - trace, 1.0 + 2.0 * m[1, 1] - trace])
    squares = np.append(squares, 1.0 + 2.0 * m[2, 2] - trace)  # 4 r_k^2, k = 1..4
    k = int(np.argmax(squares))
    pivot = 0.5 * np.sqrt(squares[k])  # |r_k|
    # 4 r_1 r_i = (m_kj - m_jk) terms, 4 r_i r_j = (m_ij + m_ji): the off-diagonal identities.
    others = np.array(
        [
            [m[2, 1] - m[1, 2], m[0, 2] - m[2, 0], m[1, 0] - m[0, 1]],
            [m[2, 1] - m[1, 2], m[0, 1] + m[1, 0], m[0, 2] + m[2, 0]],
            [m[0, 2] - m[2, 0], m[0, 1] + m[1, 0], m[1, 2] + m[2, 1]],
            [m[1, 0] - m[0, 1], m[0, 2] + m[2, 0], m[1, 2] + m[2, 1]],
        ]
    )[k] / (4.0 * pivot)
    r = np.insert(others, k, pivot)
    r = r / np.linalg.norm(r)
    return -r if r[0] < 0.0 else r


def pose(rotation: Array, translation: Array) -> Array:
    """Unit dual quaternion x = r + eps (1/2) p r of rotation r and translation p (3.15).

    ``translation`` is a 3-vector or a pure quaternion.
    """
    t = np.asarray(translation, dtype=float)
    p = t if t.shape == (4,) else np.concatenate(([0.0], t))
    return from_parts(rotation, 0.5 * qmul(p, rotation))


def rotation(x: Array) -> Array:
    """The rotation quaternion r = P(x) of a unit dual quaternion."""
    return x[:4].copy()


def translation(x: Array) -> Array:
    """The translation p = 2 D(x) P(x)* as a pure quaternion (4.12)."""
    return 2.0 * qmul(x[4:], qconj(x[:4]))


def log(x: Array) -> Array:
    """log x = n phi / 2 + eps p / 2 of a unit dual quaternion (3.16)."""
    r = x[:4]
    imaginary = float(np.linalg.norm(r[1:]))
    half_angle = math.atan2(imaginary, r[0])
    # n phi/2 = Im(r) (phi/2) / sin(phi/2); at r = +-1 exactly the axis is undefined and
    # Im(r) = 0 is returned (log 1 = 0).
    scale = half_angle / imaginary if imaginary > 0.0 else 1.0
    out = np.zeros(8)
    out[1:4] = scale * r[1:]
    out[4:] = 0.5 * translation(x)
    return out


def exp(a: Array) -> Array:
    """exp a = P(exp a) + eps D(a) P(exp a) of a pure dual quaternion (3.17)."""
    phi = float(np.linalg.norm(a[:4]))
    p = np.array([math.cos(phi), 0.0, 0.0, 0.0])
    if phi > 0.0:
        p = p + (math.sin(phi) / phi) * a[:4]
    return from_parts(p, qmul(a[4:], p))


def power(x: Array, exponent: float) -> Array:
    """x^{lambda} = exp(lambda log x) (3.18)."""
    return exp(exponent * log(x))


def nearest_equivalent(x_desired: Array, x: Array) -> Array:
    """The one of {x_d, -x_d} nearer to x: both are the same pose, the nearer one turns short."""
    # ||x - x_d||^2 - ||x + x_d||^2 = -4 x . x_d
    return -x_desired if np.dot(x, x_desired) < 0.0 else x_desired
