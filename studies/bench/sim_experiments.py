"""The chapter 6 experiments on the whole simulated loop, over many seeds, and the loop's speed.

Run as ``python -m studies.bench.sim_experiments [--seeds N] [--workers W] [--json]``. For each
experiment and law it runs ``parsimony experiment`` in lockstep, recorder on, for seeds
0..N-1, W at a time (each system in its own process, namespace and router port), and prints the
share that converged, contacts, the worst estimator error in steady state, the real-time factor
(simulated over wall seconds, on this machine, with the other workers running), the cost of
each stage (the handlers' median times, the simulator's frame answer and state-to-command
times), the recorder's CPU per simulated second (its share of one core in real time) and the
recording's bytes per simulated second; then experiments per minute over the whole study.
Last, the speed of the camera's parts per frame in this process, on the scene of
``deploy/sim.yaml``: render, JPEG encode and decode, marker detection and pose fits.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from launch.query import QueryError
from outputs.stdout import emit, json_text, result_only_stdout, table
from profiles.profile import ProfileError, load_profile
from sim2d.camera import ImageNoise, PlacedMarker, Renderer, ceiling_camera
from sim2d.scenarios import NAMES, scenario
from studies.experiment import PROFILES, SUPERVISED, Options, run_experiment
from vision.images import grey, jpeg
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


def run_one(name: str, controller: str, seed: int, directory: Path) -> dict | None:
    """One lockstep run (in a worker process: its pid names the system's namespace); None
    when it could not run (said, with why)."""
    options = Options(
        name=name, controller=controller, seed=seed, out=directory / f"{name}-{controller}-{seed}"
    )
    report = experiment_or_none(options, f"{name} {controller} seed {seed}")
    if report is not None:
        print(
            f"[bench] {name} {controller} seed {seed}: converged={report['converged']} "
            f"rtf={report['real_time_factor']}",
            file=sys.stderr,
            flush=True,
        )
    return report


def experiment_or_none(options: Options, label: str) -> dict | None:
    """``run_experiment(options)``'s report, or None when it could not run (said on stderr,
    with why, under ``label``)."""
    try:
        return run_experiment(options)
    except (OSError, RuntimeError, QueryError, ProfileError) as error:
        print(f"[bench] {label}: did not run: {error}", file=sys.stderr, flush=True)
        return None


def median_of(reports: list[dict], component: str, counter: str) -> int:
    return round(
        statistics.median(r["durations_us"].get(component, {}).get(counter, 0) for r in reports)
    )


def summary(name: str, controller: str, found: list[dict | None]) -> dict:
    """Every seed of one experiment and law, summarised (those that could not run counted)."""
    reports = [r for r in found if r is not None]
    estimator = [r["estimator_error"] for r in reports if r["estimator_error"]["samples"]]
    # The recorder's CPU per simulated second: its share of one core in real time (30 Hz).
    recorder = [r["cpu_s"].get("recorder", 0.0) / r["sim_time_s"] for r in reports]
    return {
        "experiment": name,
        "law": controller,
        "runs": len(reports),
        "did_not_run": len(found) - len(reports),
        "converged": sum(r["converged"] for r in reports),
        "with_contact": sum(r["contacts"] > 0 for r in reports),
        "at_joint_stops": sum(r["joint_limit_violations"] > 0 for r in reports),
        "estimator_position_mm": round(max(e["position_m"] for e in estimator) * 1e3, 2),
        "estimator_angle_deg": round(float(np.degrees(max(e["angle_rad"] for e in estimator))), 2),
        "real_time_factor": round(statistics.median(r["real_time_factor"] for r in reports), 2),
        "rtf_min": round(min(r["real_time_factor"] for r in reports), 2),
        "tracker_frame_us": median_of(reports, "vision_tracker", "handler.camera/image_us_median"),
        "estimator_odometry_us": median_of(
            reports, "state_estimator", "handler.base/odometry_us_median"
        ),
        "controller_state_us": median_of(reports, "controller", "handler.robot/state_us_median"),
        "frame_answer_us": median_of(reports, "simulator", "frame_us_median"),
        "loop_us": median_of(reports, "simulator", "loop_us_median"),
        "recorder_cpu_pct_rt": round(100 * statistics.median(recorder), 1),
        "bytes_per_sim_s": round(
            statistics.median(r["recording"]["bytes_per_sim_s"] for r in reports)
        ),
        "recordings_whole": sum(r["recording"]["whole"] for r in reports),
    }


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
    parser.add_argument("--seeds", type=int, default=20, help="seeds per experiment and law")
    parser.add_argument(
        "--workers",
        type=int,
        default=max(1, (os.cpu_count() or 2) // 2),
        help="experiments run at once (default: one per two cores)",
    )
    parser.add_argument("--only", help="comma-separated experiments to run (default: all)")
    parser.add_argument("--laws", default="lp,cascade", help="comma-separated laws to run")
    parser.add_argument("--json", action="store_true", help="print JSON instead of tables")
    args = parser.parse_args(argv)
    runs = [
        (n, law)
        for n, law in RUNS
        if (not args.only or n in args.only.split(",")) and law in args.laws.split(",")
    ]
    started = time.monotonic()
    with tempfile.TemporaryDirectory() as directory, ProcessPoolExecutor(args.workers) as pool:
        jobs = {
            (n, law): [
                pool.submit(run_one, n, law, seed, Path(directory)) for seed in range(args.seeds)
            ]
            for n, law in runs
        }
        rows = [
            summary(n, law, [job.result() for job in found]) for (n, law), found in jobs.items()
        ]
    minutes = (time.monotonic() - started) / 60.0
    study = {
        "experiments": len(runs) * args.seeds,
        "workers": args.workers,
        "experiments_per_minute": round(len(runs) * args.seeds / minutes, 1),
    }
    speed = vision_speed()
    if args.json:
        emit(
            json_text(
                {"bench": "sim_experiments", "study": study, "experiments": rows, "vision": speed}
            )
        )
    else:
        emit(table(rows))
        emit(" ".join(f"{k}={v}" for k, v in study.items()))
        emit(
            "per camera frame: "
            + "  ".join(f"{k} median {v['median']} p99 {v['p99']}" for k, v in speed.items())
        )
    return 0


if __name__ == "__main__":
    with result_only_stdout():
        code = main()
    sys.exit(code)
