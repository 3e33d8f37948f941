"""Shared fixtures: the command-line tool (to compare against) and simulated files."""

import json
import os
import pathlib
import subprocess

import pytest

REPO = pathlib.Path(__file__).resolve().parents[3]


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
