"""The ceiling camera's pinhole model (sim2d.pinhole): a point projected by hand."""

from __future__ import annotations

import numpy as np

from sim2d.pinhole import PinholeCamera, ceiling_pose


def test_camera_above_a_point_maps_it_to_the_principal_point() -> None:
    x, y, h = 0.6, 0.1, 2.5
    camera = PinholeCamera(ceiling_pose(x, y, h))
    pixels = camera.project(np.array([[x, y, 0.0], [x + 0.5, y + 0.25, 0.0], [x, y, 1.0]]))
    np.testing.assert_allclose(pixels[0], [camera.cx, camera.cy], atol=1e-9)
    # camera x = world x, camera y = -world y: u = cx + fx dx / h, v = cy - fy dy / h
    np.testing.assert_allclose(pixels[1], [319.5 + 600 * 0.5 / h, 239.5 - 600 * 0.25 / h])
    np.testing.assert_allclose(pixels[2], [camera.cx, camera.cy], atol=1e-9)
    np.testing.assert_allclose(camera.matrix(), [[600, 0, 319.5], [0, 600, 239.5], [0, 0, 1]])
