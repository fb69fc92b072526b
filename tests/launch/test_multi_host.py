"""Two computers of a lab, as two network namespaces made by the test: the robot's router
listens over TLS on one, the station's router links to it from the other (deploy/lab/).

The addresses (10.213.0.0/24) exist only inside the namespaces the test creates and removes;
the certificates are made for the test by openssl. Needs root, iproute2 and openssl.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
import yaml

from profiles.deploy_files import DEPLOY, ROBOT_FILE
from tests.launch.conftest import LAUNCH

ROBOT_ADDRESS, STATION_ADDRESS = "10.213.0.1", "10.213.0.2"

pytestmark = pytest.mark.skipif(
    os.geteuid() != 0 or not shutil.which("ip") or not shutil.which("openssl"),
    reason="needs root, iproute2 and openssl to make network namespaces and certificates",
)


def run(*command: str) -> None:
    subprocess.run(command, check=True, capture_output=True, timeout=30)


@pytest.fixture
def hosts() -> Iterator[tuple[str, str]]:
    """Two namespaces joined by a veth pair: the robot at .1, the station at .2."""
    robot, station = f"parsimony-robot-{os.getpid()}", f"parsimony-station-{os.getpid()}"
    try:
        run("ip", "netns", "add", robot)
        run("ip", "netns", "add", station)
        run(
            "ip",
            "link",
            "add",
            "pz-robot",
            "netns",
            robot,
            "type",
            "veth",
            "peer",
            "name",
            "pz-station",
            "netns",
            station,
        )
        for namespace, device, address in (
            (robot, "pz-robot", ROBOT_ADDRESS),
            (station, "pz-station", STATION_ADDRESS),
        ):
            run("ip", "-n", namespace, "addr", "add", f"{address}/24", "dev", device)
            run("ip", "-n", namespace, "link", "set", device, "up")
            run("ip", "-n", namespace, "link", "set", "lo", "up")
        yield robot, station
    finally:
        for namespace in (robot, station):
            subprocess.run(["ip", "netns", "del", namespace], capture_output=True, timeout=30)


def make_certificates(directory: Path) -> None:
    """A CA, and a certificate for the robot's router at ROBOT_ADDRESS signed by it."""
    run(
        "openssl",
        "req",
        "-x509",
        "-newkey",
        "rsa:2048",
        "-nodes",
        "-days",
        "1",
        "-keyout",
        str(directory / "ca-key.pem"),
        "-out",
        str(directory / "ca.pem"),
        "-subj",
        "/CN=parsimony test CA",
    )
    run(
        "openssl",
        "req",
        "-newkey",
        "rsa:2048",
        "-nodes",
        "-keyout",
        str(directory / "robot-key.pem"),
        "-out",
        str(directory / "robot.csr"),
        "-subj",
        f"/CN={ROBOT_ADDRESS}",
    )
    (directory / "ext.cnf").write_text(
        f"subjectAltName=IP:{ROBOT_ADDRESS}\nextendedKeyUsage=serverAuth\n"
    )
    run(
        "openssl",
        "x509",
        "-req",
        "-days",
        "1",
        "-in",
        str(directory / "robot.csr"),
        "-CA",
        str(directory / "ca.pem"),
        "-CAkey",
        str(directory / "ca-key.pem"),
        "-CAcreateserial",
        "-out",
        str(directory / "robot.pem"),
        "-extfile",
        str(directory / "ext.cnf"),
    )


def lab_profile(name: str, directory: Path) -> Path:
    """deploy/lab/NAME.yaml with its certificates taken from ``directory``."""
    data = yaml.safe_load((DEPLOY / "lab" / f"{name}.yaml").read_text())
    if "robot" in data:
        data["robot"] = str(ROBOT_FILE)
    data["zenoh"]["tls"] = {
        key: str(directory / Path(value).name) for key, value in data["zenoh"]["tls"].items()
    }
    path = directory / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def in_namespace(namespace: str, *command: str) -> list[str]:
    return ["ip", "netns", "exec", namespace, *command]


def test_a_station_reaches_the_robot_over_tls_between_two_hosts(
    hosts: tuple[str, str], tmp_path: Path
) -> None:
    robot_host, station_host = hosts
    make_certificates(tmp_path)
    robot, station = lab_profile("robot", tmp_path), lab_profile("station", tmp_path)
    launchers = [
        subprocess.Popen(
            in_namespace(host, sys.executable, "-c", LAUNCH, str(profile), "--duration", "30"),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
            text=True,
        )
        for host, profile in ((robot_host, robot), (station_host, station))
    ]
    try:
        deadline = time.monotonic() + 20.0
        received = 0
        while received == 0:
            assert time.monotonic() < deadline, "no robot/state crossed from the station"
            status = subprocess.run(
                in_namespace(
                    robot_host,
                    sys.executable,
                    "-m",
                    "parsimony.cli",
                    "status",
                    str(robot),
                    "--json",
                    "--timeout",
                    "1",
                ),
                capture_output=True,
                text=True,
                timeout=30,
            )
            rows = json.loads(status.stdout) if status.returncode == 0 else []
            for row in rows:
                if row["name"] == "controller" and row["status"]:
                    received = row["status"]["counters"]["received.robot/state"]
        assert received > 0
    finally:
        for launcher in launchers:
            launcher.terminate()
        outputs = [launcher.communicate(timeout=30)[0] for launcher in launchers]
    assert "[launch] all 1 components alive" in outputs[0], outputs[0]
    assert "[launch] all 1 components alive" in outputs[1], outputs[1]
