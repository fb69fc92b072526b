"""The dual-quaternion low-pass filter of eq. 6.1 (wbc/pose_filter.py): mean, then low-pass."""

from __future__ import annotations

import math

import numpy as np
import pytest

from wbc import dq
from wbc.pose_filter import PoseFilter

TILTED = dq.rotation_quaternion(0.7, [0.3, -0.5, 0.8])
"""A common rotation of the translation-only examples, so that body and world axes differ."""


def translated(x: float) -> np.ndarray:
    """The pose of rotation TILTED at (x, 0.2, 0.4)."""
    return dq.pose(TILTED, [x, 0.2, 0.4])


def random_pose(rng: np.random.Generator) -> np.ndarray:
    angle = rng.uniform(-math.pi, math.pi)
    return dq.pose(dq.rotation_quaternion(angle, rng.normal(size=3)), rng.uniform(-1, 1, 3))


def distance(a: np.ndarray, b: np.ndarray) -> float:
    """||log(a* b)|| of the nearer of +-b: half the rotation angle and half the translation."""
    return float(np.linalg.norm(dq.log(dq.mul(dq.conj(a), dq.nearest_equivalent(b, a)))))


def same_pose(a: np.ndarray, b: np.ndarray, tol: float = 1e-9) -> bool:
    return bool(np.allclose(a, b, atol=tol) or np.allclose(a, -b, atol=tol))


def test_the_first_samples_give_the_running_mean_of_the_translation() -> None:
    xs = [0.3, -1.2, 2.5, 0.9, 0.1, -0.4]
    pose_filter = PoseFilter(samples=len(xs))
    for k, x in enumerate(xs, start=1):
        out = pose_filter.update(translated(x))
        assert dq.translation(out)[1:] == pytest.approx([np.mean(xs[:k]), 0.2, 0.4], abs=1e-12)
        assert np.allclose(dq.rotation(out), TILTED, atol=1e-12)
        assert pose_filter.count == k


def test_past_the_samples_the_weight_stays_one_over_samples() -> None:
    """Running mean up to ``samples``; then m_k = m_{k-1} + (x_k - m_{k-1}) / samples."""
    pose_filter = PoseFilter(samples=2)
    pose_filter.update(translated(0.0))
    pose_filter.update(translated(1.0))
    out = pose_filter.update(translated(2.0))
    assert dq.translation(out)[1] == pytest.approx(0.5 + (2.0 - 0.5) / 2, abs=1e-12)


def test_a_constant_input_is_a_fixed_point() -> None:
    pose = random_pose(np.random.default_rng(3))
    pose_filter = PoseFilter(samples=5)
    for _ in range(40):
        assert np.allclose(pose_filter.update(pose), pose, atol=1e-12)


@pytest.mark.parametrize("samples", [1, 4, 10])
def test_a_step_decays_geometrically_with_ratio_one_minus_one_over_samples(samples: int) -> None:
    rng = np.random.default_rng(samples)
    start, target = random_pose(rng), random_pose(rng)
    pose_filter = PoseFilter(samples)
    for _ in range(samples):
        pose_filter.update(start)
    initial = distance(start, target)
    ratio = 1.0 - 1.0 / samples
    errors = [distance(pose_filter.update(target), target) for _ in range(2 * samples)]
    expected = [initial * ratio**n for n in range(1, 2 * samples + 1)]
    assert errors == pytest.approx(expected, abs=1e-9)
    if samples > 1:
        assert errors[samples - 1] == pytest.approx(initial * ratio**samples, rel=1e-6)
        assert errors[-1] > 0.1 * initial  # it lags: (1 - 1/n)^(2n) > e^-2.5


def test_outputs_stay_unit_dual_quaternions_over_noisy_updates() -> None:
    rng = np.random.default_rng(7)
    truth = random_pose(rng)
    pose_filter = PoseFilter(samples=8)
    for _ in range(1000):
        noise = dq.pose(
            dq.rotation_quaternion(rng.normal(scale=0.05), rng.normal(size=3)),
            rng.normal(scale=0.01, size=3),
        )
        measured = dq.mul(truth, noise) * rng.choice([-1.0, 1.0])
        out = pose_filter.update(measured)
        assert dq.is_unit(out, tol=1e-12)
    assert distance(out, truth) < 0.02


def test_a_measurement_given_as_its_negative_does_not_flip_the_estimate() -> None:
    rng = np.random.default_rng(11)
    first, second = random_pose(rng), random_pose(rng)
    plain, negated = PoseFilter(samples=3), PoseFilter(samples=3)
    plain.update(first)
    negated.update(first)
    expected = plain.update(second)
    out = negated.update(-second)
    assert np.allclose(out, expected, atol=1e-12)
    assert float(np.dot(out, first)) == pytest.approx(float(np.dot(expected, first)))


@pytest.mark.parametrize("samples", [0, -3])
def test_fewer_than_one_sample_is_refused(samples: int) -> None:
    with pytest.raises(ValueError, match=f"samples must be >= 1, got {samples}"):
        PoseFilter(samples)


def test_reset_forgets_every_sample() -> None:
    pose_filter = PoseFilter(samples=10)
    for x in (0.0, 1.0, 2.0):
        pose_filter.update(translated(x))
    pose_filter.reset()
    assert pose_filter.count == 0 and pose_filter.pose is None
    assert np.allclose(pose_filter.update(translated(5.0)), translated(5.0), atol=1e-12)
    out = pose_filter.update(translated(7.0))
    assert dq.translation(out)[1] == pytest.approx(6.0, abs=1e-12)
    assert same_pose(pose_filter.pose, out)
