"""The base's planar pose from wheel odometry and camera fixes that arrive late.

The estimate is the odometry's dead-reckoned pose o seen through a correction frame C,
x = C ⊕ o (``wbc.planar.compose``), so that it moves as the wheels say. A camera fix z of the
frame taken at t pulls the estimate of that instant towards it by a gain g (eq. 6.1 on the
plane, the estimate standing for the previous average):

    x_t = C ⊕ o_t,    x_t' = x_t + g (z - x_t)   (the angle difference wrapped),
    C' = x_t' ⊕ o_t^-1

and every estimate after t follows, as x_s' = C' ⊕ o_s = x_t' ⊕ (o_t^-1 ⊕ o_s): the fix enters
at the time it was taken, however late it arrives, and the odometry since is laid on it again.
o_t is interpolated between the odometry poses around t (kept for ``horizon_s``); a fix newer
than the last odometry takes the last. The first fix sets x_t' = z.
"""

from __future__ import annotations

import bisect
from collections import deque

from wbc.planar import compose, inverse, wrap

Pose = tuple[float, float, float]


def blend(estimate: Pose, measured: Pose, gain: float) -> Pose:
    """x + g (z - x), the heading's difference wrapped to [-pi, pi)."""
    x, y, phi = estimate
    return (
        x + gain * (measured[0] - x),
        y + gain * (measured[1] - y),
        phi + gain * wrap(measured[2] - phi),
    )


class BaseEstimate:
    """x = C ⊕ o, odometry poses o by stamp, camera fixes at their own stamps (module doc)."""

    def __init__(self, horizon_s: float = 2.0) -> None:
        self.horizon_ns = round(horizon_s * 1e9)
        self.correction: Pose | None = None
        self._stamps: deque[int] = deque()
        self._odometry: deque[Pose] = deque()

    @property
    def pose(self) -> Pose | None:
        """The estimate at the last odometry: None before a fix, or before any odometry."""
        if self.correction is None or not self._odometry:
            return None
        return compose(self.correction, self._odometry[-1])

    def move(self, stamp_ns: int, odometry: Pose) -> None:
        """The odometry's pose at ``stamp_ns`` (stamps increase); poses older than the
        horizon are forgotten."""
        self._stamps.append(stamp_ns)
        self._odometry.append(odometry)
        while self._stamps[0] < stamp_ns - self.horizon_ns:
            self._stamps.popleft()
            self._odometry.popleft()

    def fix(self, stamp_ns: int, measured: Pose, gain: float) -> bool:
        """Correct by a camera fix taken at ``stamp_ns``; False (nothing done) when no
        odometry covers that time (none yet, or the fix is older than the horizon)."""
        at = self.odometry_at(stamp_ns)
        if at is None:
            return False
        estimate = measured if self.correction is None else compose(self.correction, at)
        corrected = blend(estimate, measured, gain)
        self.correction = compose(corrected, inverse(at))
        return True

    def reset(self) -> None:
        """Forget the correction: the next fix places the base again."""
        self.correction = None

    def odometry_at(self, stamp_ns: int) -> Pose | None:
        """o at ``stamp_ns``: linear between the poses around it (the heading's shorter way),
        the last one after the last, None before the first or with none."""
        if not self._stamps or stamp_ns < self._stamps[0]:
            return None
        i = bisect.bisect_right(self._stamps, stamp_ns)
        if i == len(self._stamps):
            return self._odometry[-1]
        before, after = self._odometry[i - 1], self._odometry[i]
        t0, t1 = self._stamps[i - 1], self._stamps[i]
        if t0 == stamp_ns:
            return before
        return blend(before, after, (stamp_ns - t0) / (t1 - t0))
