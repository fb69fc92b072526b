"""The speed of the simulated loop's camera stages per frame, in this process.

Run as ``python -m studies.bench.sim_experiments [--json]``: on the scene of ``deploy/sim.yaml``,
render, JPEG encode and decode, marker detection and pose fits, median and p99 over FRAMES
frames. The chapter 6 experiments over many seeds on the whole simulated loop (the share that
converged, contacts, estimator errors, real-time factors, each stage's handler times, the
recorder's cost) are a study: ``parsimony study studies/files/sim-experiments.yaml``, whose
progress says the experiments per minute.
"""

from __future__ import annotations

import argparse
import sys
import time

import numpy as np

from launch.query import QueryError
from outputs.stdout import emit, json_text, result_only_stdout
from profiles.profile import ProfileError, load_profile
from sim2d.camera import ImageNoise, PlacedMarker, Renderer
from sim2d.pinhole import ceiling_camera
from sim2d.scenarios import scenario
from studies.experiment import PROFILES, Options, run_experiment
from vision.images import grey, jpeg
from vision.markers import Intrinsics, MarkerDetector, plane_of, plane_pose, square_pose
from wbc.planar import planar_pose
from wbc.robot import MobileManipulator

FRAMES = 200


def percentile(values: list[float], q: float) -> float:
    return round(float(np.percentile(values, q)), 1)


def experiment_or_none(options: Options, label: str) -> dict | None:
    """``run_experiment(options)``'s report, or None when it could not run (said on stderr,
    with why, under ``label``)."""
    try:
        return run_experiment(options)
    except (OSError, RuntimeError, QueryError, ProfileError) as error:
        print(f"[bench] {label}: did not run: {error}", file=sys.stderr, flush=True)
        return None


def vision_speed() -> dict:
    """Render, JPEG encode and decode, detection and fit times per frame, on the simulation
    profile's scene, as the simulator and the tracker run them."""
    profile = load_profile(PROFILES["lp"])
    scene, c = profile.scene, profile.scene.camera
    robot = MobileManipulator.from_yaml(profile.robot)
    setup = scenario("obstacle", robot)
    camera = ceiling_camera(c)
    below = [
        PlacedMarker(
            scene.reference.id, scene.reference.size_m, planar_pose(*scene.reference_pose)
        ),
        PlacedMarker(scene.goal.id, scene.goal.size_m, planar_pose(*setup.bin)),
    ]
    above = [
        PlacedMarker(i, scene.obstacles.size_m, planar_pose(o.x, o.y, 0.0, 0.3))
        for i, o in zip(scene.obstacles.ids, setup.obstacles, strict=False)
    ]
    rng = np.random.default_rng(0)
    renderer = Renderer(camera, scene.dictionary_id, ImageNoise(), rng, below, above)
    detector = MarkerDetector(scene.dictionary_id)
    intrinsics = Intrinsics(c.fx, c.fy, c.cx, c.cy)
    stages = ("render_us", "encode_us", "decode_us", "detect_us", "fit_us")
    times: dict[str, list[float]] = {name: [] for name in stages}
    for index in range(FRAMES):
        base = PlacedMarker(
            scene.base.id, scene.base.size_m, planar_pose(0.002 * index, 0.0, 0.2, 0.092)
        )
        marks = [time.perf_counter()]
        image = renderer.frame([base])
        marks.append(time.perf_counter())
        data = jpeg(image, 90)
        marks.append(time.perf_counter())
        image = grey(data, "jpeg", c.width, c.height)
        marks.append(time.perf_counter())
        found = detector.detect(image)
        marks.append(time.perf_counter())
        reference = next(d for d in found if d.id == scene.reference.id)
        pose, _ = square_pose(reference, scene.reference.size_m, intrinsics)
        normal, offset = plane_of(pose, 0.0)
        for detection in found:
            plane_pose(detection, 0.15, intrinsics, normal, offset)
        marks.append(time.perf_counter())
        for name, start, end in zip(stages, marks[:-1], marks[1:], strict=True):
            times[name].append((end - start) * 1e6)
    return {
        name: {"median": percentile(v, 50), "p99": percentile(v, 99)} for name, v in times.items()
    }


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--json", action="store_true", help="print JSON instead of a line")
    args = parser.parse_args(argv)
    speed = vision_speed()
    if args.json:
        emit(json_text({"bench": "sim_experiments", "vision": speed}))
    else:
        emit(
            "per camera frame: "
            + "  ".join(f"{k} median {v['median']} p99 {v['p99']}" for k, v in speed.items())
        )
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
