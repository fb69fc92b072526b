"""The dual-quaternion low-pass filter of the vision system (eq. 6.1).

    x_bar_k = x_bar_{k-1} (x_bar_{k-1}^* x_k)^(1/n),    n = min(k, samples)

With n = k it is the running mean of the first k poses on the manifold of rigid motions; once
k passes ``samples`` the weight stays 1/samples, a first-order low-pass: a high ``samples``
for static markers (less noise), a low one for the moving base (less lag).
"""

from __future__ import annotations

import numpy as np

from wbc import dq


class PoseFilter:
    """Eq. 6.1 with ``samples`` samples (1: no filtering)."""

    def __init__(self, samples: int) -> None:
        if samples < 1:
            raise ValueError(f"samples must be >= 1, got {samples}")
        self.samples = samples
        self.count = 0
        self.pose: np.ndarray | None = None

    def update(self, measured: np.ndarray) -> np.ndarray:
        """Fold in one measured pose; return the filtered one."""
        self.count += 1
        if self.pose is None:
            self.pose = dq.normalize(np.array(measured, dtype=float))
            return self.pose
        nearest = dq.nearest_equivalent(np.asarray(measured, dtype=float), self.pose)
        step = dq.mul(dq.conj(self.pose), nearest)
        step = dq.power(step, 1.0 / min(self.count, self.samples))
        self.pose = dq.normalize(dq.mul(self.pose, step))
        return self.pose

    def reset(self) -> None:
        """Forget every sample (a marker seen again after it moved while hidden)."""
        self.count = 0
        self.pose = None
