"""Shared fixtures: the command-line tool (to compare against) and simulated files."""

import importlib.util
import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


def load_basilisk_converter():
    """``inertia/basilisk.py`` imported by path: it is pure numpy, so its tests need not
    build the package."""
    path = pathlib.Path(__file__).resolve().parents[1] / "python" / "inertia" / "basilisk.py"
    spec = importlib.util.spec_from_file_location("inertia_basilisk", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def basilisk_wheels(sim, sc, axes, spin_inertias):
    """Basilisk's balanced reaction wheels at B on spacecraft ``sc`` (one per axis and spin
    inertia, at rest), in task ``"task"`` after the hub, commanded through one
    ``ArrayMotorTorqueMsg``: returns the effector, the command payload and its message."""
    from Basilisk.architecture import messaging
    from Basilisk.simulation import reactionWheelStateEffector
    from Basilisk.utilities import simIncludeRW

    factory = simIncludeRW.rwFactory()
    for g, js in zip(axes, spin_inertias):
        factory.create("custom", [float(x) for x in g], Js=float(js), Omega=0.0,
                       RWModel=messaging.BalancedWheels, rWB_B=[0.0, 0.0, 0.0],
                       useMaxTorque=False)
    rw = reactionWheelStateEffector.ReactionWheelStateEffector()
    rw.ModelTag = "rw"
    factory.addToSpacecraft("rw", rw, sc)
    cmd = messaging.ArrayMotorTorqueMsgPayload()
    cmd.motorTorque = [0.0] * 36
    msg = messaging.ArrayMotorTorqueMsg().write(cmd)
    rw.rwMotorCmdInMsg.subscribeTo(msg)
    sim.AddModelToTask("task", rw, 2)
    sim.AddModelToTask("task", sc, 1)
    return rw, cmd, msg


@pytest.fixture(scope="session")
def cli() -> str:
    """The `inertia` binary: $INERTIA_CLI, or target/release/inertia built here."""
    path = os.environ.get("INERTIA_CLI")
    if path:
        return path
    subprocess.run(
        ["cargo", "build", "--release", "-q", "-p", "inertia-cli"], cwd=REPO, check=True
    )
    return str(REPO / "target" / "release" / "inertia")


def run_cli(cli: str, *args: str, check: bool = True) -> subprocess.CompletedProcess:
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"inertia {' '.join(map(str, args))}: exit {p.returncode}: {p.stderr}")
    return p


def cli_estimate(cli: str, path, *options: str) -> dict:
    return json.loads(run_cli(cli, "estimate", path, "--json", *options).stdout)


@pytest.fixture(scope="session")
def files(cli, tmp_path_factory):
    """Telemetry files written by `inertia simulate`: slew, spin, and a short small-sat."""
    d = tmp_path_factory.mktemp("sim")
    out = {}
    for name, args in {
        "slew": ["--scenario", "slew"],
        "spin": ["--scenario", "spin"],
        "smallsat": ["--preset", "small-sat", "--duration", "200"],
    }.items():
        f = d / f"{name}.csv"
        run_cli(cli, "simulate", *args, "-o", f)
        out[name] = f
    return out
