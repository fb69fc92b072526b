"""The chapter 6 experiments on the whole simulated loop, over many seeds, and the loop's speed.

Run as ``python -m bench.sim_experiments [--seeds N] [--json]``. For each experiment and law it
runs ``parsimony experiment`` in lockstep for seeds 0..N-1 and prints the share that converged,
contacts, the worst estimator error in steady state, and the real-time factor (simulated over
wall seconds, on this machine). Then the speed of the parts: camera render, marker detection
and pose fits per frame (in this process, on the scene of ``deploy/sim.yaml``), the camera-frame
answer time (tracker and estimator) and the state-to-command time inside the running loop (the
simulator's counters), and the controller's step time.
"""

from __future__ import annotations

import argparse
import json
import statistics
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from parsimony.experiment import PROFILES, SUPERVISED, Options, run_experiment
from parsimony.output import emit, result_only_stdout
from profiles.profile import load_profile
from sim2d.camera import (
    ImageNoise,
    PlacedMarker,
    ceiling_camera,
    render,
)
from sim2d.scenarios import NAMES, scenario
from vision.markers import Intrinsics, MarkerDetector, plane_of, plane_pose, square_pose
from wbc.planar import planar_pose
from wbc.robot import MobileManipulator

RUNS = [(name, "lp") for name in NAMES] + [
    (name, "cascade") for name in NAMES if name not in SUPERVISED
]
"""Every experiment with each law; the cascade cannot follow the supervisor's drive tasks."""
FRAMES = 200


def percentile(values: list[float], q: float) -> float:
    return round(float(np.percentile(values, q)), 1)


def run_seeds(name: str, controller: str, seeds: int, directory: Path) -> dict:
    """Every seed of one experiment and law, summarised."""
    reports = []
    for seed in range(seeds):
        options = Options(name=name, controller=controller, seed=seed,
                          out=directory / f"{name}-{controller}-{seed}")  # fmt: skip
        reports.append(run_experiment(options))
        print(f"[bench] {name} {controller} seed {seed}: converged={reports[-1]['converged']}",
              file=sys.stderr, flush=True)  # fmt: skip
    estimator = [r["estimator_error"] for r in reports if r["estimator_error"]["samples"]]
    answer = [r["durations_us"].get("simulator", {}) for r in reports]
    handlers = [r["durations_us"].get("state_estimator", {}) for r in reports]
    return {
        "experiment": name,
        "law": controller,
        "runs": len(reports),
        "converged": sum(r["converged"] for r in reports),
        "with_contact": sum(r["contacts"] > 0 for r in reports),
        "at_joint_stops": sum(r["joint_limit_violations"] > 0 for r in reports),
        "estimator_position_mm": round(max(e["position_m"] for e in estimator) * 1e3, 2),
        "estimator_angle_deg": round(float(np.degrees(max(e["angle_rad"] for e in estimator))), 2),
        "real_time_factor": round(statistics.median(r["real_time_factor"] for r in reports), 2),
        "tracker_frame_us": round(statistics.median(
            r["durations_us"].get("vision_tracker", {}).get("handler.camera/image_us_median", 0)
            for r in reports)),
        "step_us_median": round(statistics.median(r["step_time_us"]["median"] for r in reports)),
        "loop_us_median": round(statistics.median(a.get("loop_us_median", 0) for a in answer)),
        "frame_us_median": round(statistics.median(a.get("frame_us_median", 0) for a in answer)),
        "estimator_odometry_us": round(statistics.median(
            e.get("handler.base/odometry_us_median", 0) for e in handlers)),
        "estimator_markers_us": round(statistics.median(
            e.get("handler.vision/markers_us_median", 0) for e in handlers)),
    }


def vision_speed() -> dict:
    """Render, detect and fit times per frame on the simulation profile's scene."""
    profile = load_profile(PROFILES["lp"])
    scene, c = profile.scene, profile.scene.camera
    robot = MobileManipulator.from_yaml(profile.robot)
    setup = scenario("obstacle", robot)
    camera = ceiling_camera(c)
    reference = planar_pose(*scene.reference_pose)
    markers = [
        PlacedMarker(scene.reference.id, scene.reference.size_m, reference),
        PlacedMarker(scene.base.id, scene.base.size_m, planar_pose(0.0, 0.0, 0.2, 0.092)),
        PlacedMarker(scene.goal.id, scene.goal.size_m, planar_pose(*setup.bin)),
        *(PlacedMarker(i, scene.obstacles.size_m, planar_pose(o.x, o.y, 0.0, 0.3))
          for i, o in zip(scene.obstacles.ids, setup.obstacles, strict=False)),
    ]  # fmt: skip
    detector = MarkerDetector(scene.dictionary_id)
    intrinsics = Intrinsics(c.fx, c.fy, c.cx, c.cy)
    rng = np.random.default_rng(0)
    times: dict[str, list[float]] = {"render_us": [], "detect_us": [], "fit_us": []}
    for _ in range(FRAMES):
        start = time.perf_counter()
        image = render(camera, markers, scene.dictionary_id, ImageNoise(), rng)
        rendered = time.perf_counter()
        found = detector.detect(image)
        detected = time.perf_counter()
        reference = next(d for d in found if d.id == scene.reference.id)
        pose, _ = square_pose(reference, scene.reference.size_m, intrinsics)
        normal, offset = plane_of(pose, 0.0)
        for detection in found:
            plane_pose(detection, 0.15, intrinsics, normal, offset)
        fitted = time.perf_counter()
        times["render_us"].append((rendered - start) * 1e6)
        times["detect_us"].append((detected - rendered) * 1e6)
        times["fit_us"].append((fitted - detected) * 1e6)
    return {name: {"median": percentile(v, 50), "p99": percentile(v, 99)}
            for name, v in times.items()}  # fmt: skip


def format_table(rows: list[dict]) -> str:
    header = list(rows[0])
    table = [header] + [[str(row[k]) for k in header] for row in rows]
    widths = [max(len(line[i]) for line in table) for i in range(len(header))]
    return "\n".join("  ".join(cell.rjust(w) for cell, w in zip(line, widths, strict=True))
                     for line in table)  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=20, help="seeds per experiment and law")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    with tempfile.TemporaryDirectory() as directory:
        rows = [run_seeds(name, law, args.seeds, Path(directory)) for name, law in RUNS]
    speed = vision_speed()
    if args.json:
        emit(json.dumps({"bench": "sim_experiments", "experiments": rows, "vision": speed}))
    else:
        emit(format_table(rows))
        emit("per camera frame: " + "  ".join(
            f"{k} median {v['median']} p99 {v['p99']}" for k, v in speed.items()))  # fmt: skip
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
