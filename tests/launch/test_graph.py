"""The dataflow of a profile, from the components' declarations; nothing is started."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from launch.graph import dataflow
from profiles.deploy_files import DEPLOY
from profiles.profile import ProfileError, load_profile
from profiles.recorder import with_recorder
from tests.parsimony.in_process import completed


def test_the_controllers_profile_wires_the_publisher_to_the_controller() -> None:
    graph = dataflow(load_profile(DEPLOY / "controllers.yaml"))
    assert graph.writers("robot/state") == ["publisher"]
    assert graph.readers("robot/state") == ["controller"]
    assert graph.writers("control/goal") == ["publisher"]
    assert graph.writers("base/command") == ["controller"] and graph.readers("base/command") == []
    assert graph.read_never_written() == ["world/obstacles"]
    dot = graph.to_dot()
    assert '"publisher" -> "parsimony/robot/state";' in dot
    assert '"parsimony/robot/state" -> "controller";' in dot
    assert '"parsimony/world/obstacles" [shape=ellipse, style=dashed];' in dot


@pytest.mark.parametrize("name", ["sim.yaml", "sim_cascade.yaml"])
def test_the_sim_profiles_close_the_loop_of_the_design(name: str) -> None:
    """simulator -> tracker -> estimator -> controller -> simulator, every topic read is
    written, and the ground truth reaches no estimator or controller."""
    profile = load_profile(DEPLOY / name)
    graph = dataflow(profile)
    assert graph.writers("camera/image") == ["simulator"]
    assert graph.readers("camera/image") == ["vision_tracker"]
    assert graph.readers("vision/markers") == ["simulator", "state_estimator"]
    assert graph.writers("robot/state") == ["state_estimator"]
    assert graph.readers("robot/state") == ["controller"]
    assert graph.readers("arm/command") == ["simulator"]
    assert graph.read_never_written() == []
    roles = {spec.name: spec.role for spec in profile.components}
    assert all(roles[r] not in ("estimator", "controller") for r in graph.readers("sim/truth"))
    assert profile.component("controller").module == (
        "lp_controller" if name == "sim.yaml" else "cascade_controller"
    )


def test_a_sim_clock_profile_makes_every_component_read_sim_clock(tmp_path: Path) -> None:
    profile = load_profile(DEPLOY / "controllers.yaml").model_copy(update={"clock": "sim"})
    graph = dataflow(profile)
    assert graph.readers("sim/clock") == ["controller", "publisher"]


def test_parsimony_graph_prints_json_alone_and_writes_dot(tmp_path: Path) -> None:
    dot = tmp_path / "graph.dot"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "parsimony.cli",
            "graph",
            str(DEPLOY / "controllers.yaml"),
            "--json",
            "--dot",
            str(dot),
        ],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    assert report["topics"]["robot/state"] == {
        "key": "parsimony/robot/state",
        "writers": ["publisher"],
        "readers": ["controller"],
    }
    assert "parsimony/world/obstacles is read by controller" in result.stderr
    assert dot.read_text().startswith('digraph "parsimony" {')


def test_graph_png_without_graphviz_prints_only_how_to_install_it(tmp_path: Path) -> None:
    """Before, it printed the whole text graph, then the hint, and exited 1."""
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "parsimony.cli",
            "graph",
            str(DEPLOY / "controllers.yaml"),
            "--png",
            str(tmp_path / "graph.png"),
        ],
        capture_output=True,
        text=True,
        timeout=120,
        env={"PATH": str(tmp_path)},
    )
    assert result.returncode == 2
    assert result.stdout == ""
    assert result.stderr.splitlines() == [
        "graph: --png needs Graphviz's dot (install it: apt-get install graphviz, brew install "
        "graphviz); --dot FILE writes the graph without it"
    ]
    assert not (tmp_path / "graph.png").exists()


def test_a_module_without_one_component_class_is_refused(tmp_path: Path) -> None:
    path = tmp_path / "profile.yaml"
    path.write_text("namespace: t\ncomponents:\n  - {name: x, module: params, role: tool}\n")
    with pytest.raises(LookupError, match="expected one Component subclass"):
        dataflow(load_profile(path))


def test_the_supervised_profile_puts_the_supervisor_between_the_goal_and_the_controller() -> None:
    """The estimator's goal is remapped to goal/request; only the supervisor writes the
    controller's goal; the controller and the rest of the loop are as in sim.yaml."""
    graph = dataflow(load_profile(DEPLOY / "sim_supervised.yaml"))
    assert graph.writers("goal/request") == ["state_estimator"]
    assert graph.readers("goal/request") == ["supervisor"]
    assert graph.writers("control/goal") == ["supervisor"]
    assert graph.readers("control/goal") == ["controller"]
    assert graph.readers("robot/state") == ["controller", "supervisor"]
    assert graph.read_never_written() == []
    plain = dataflow(load_profile(DEPLOY / "sim.yaml"))
    assert plain.writers("control/goal") == ["state_estimator"]
    assert "goal/request" not in plain.topics()


def test_a_parameter_no_component_would_take_is_refused_before_anything_starts(
    tmp_path: Path,
) -> None:
    """`graph` and `launch` name the file and the field, exit 2; nothing is launched."""
    path = tmp_path / "profile.yaml"
    path.write_text(
        f"extends: {DEPLOY / 'sim.yaml'}\n"
        "components: [{name: simulator, params: {real_time_factor: -1}}]\n"
    )
    with pytest.raises(
        ProfileError,
        match=r"components\[0\] \(simulator\)\.params\."
        r"real_time_factor: expected a float in \[0.0",
    ):
        dataflow(load_profile(path), path)
    for command in ("graph", "launch"):
        done = completed(command, str(path))
        assert done.returncode == 2 and f"{path}: invalid profile" in done.stderr, done.stderr
        assert "[launch]" not in done.stderr  # refused before a component was started


def test_a_recorder_reading_every_topic_makes_no_topic_read_and_never_written(
    tmp_path: Path,
) -> None:
    """A recorder takes whatever comes: the topics only it reads are no warning (an experiment's
    or a recorded launch's profile warned of every topic nothing wrote)."""
    profile_file = tmp_path / "recorded.yaml"
    profile_file.write_text(with_recorder(DEPLOY / "sim.yaml", tmp_path / "session.mcap"))
    graph = dataflow(load_profile(profile_file))
    assert "recorder" in graph.readers("goal/request")
    assert graph.read_never_written() == [] and graph.warnings() == []
