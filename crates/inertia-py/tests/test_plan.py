"""inertia.plan: the library's plan through the thin layer, every limit kept."""

import pathlib

import numpy as np
import pytest

import inertia

ROOT = pathlib.Path(__file__).resolve().parents[3]
SAT1 = ROOT / "examples" / "plan" / "sat1.toml"


def test_plan_keeps_the_limits_and_meets_its_target():
    p = inertia.plan(SAT1, rehearsals=0)
    cmds = p["rho_dot_nm"]
    assert cmds.shape[1] == 3 and len(p["t"]) == len(cmds)
    torques = np.array(p["wheel_torque_nm"])
    # Three orthogonal wheels: each wheel's torque is its axis's command, within 0.01 N m
    # times the margin; its momentum, the running sum, within 0.046 N m s.
    assert np.allclose(torques, cmds)
    assert np.abs(torques).max() <= 0.01 * p["margin"] + 1e-12
    momentum = np.cumsum(cmds * p["period_s"], axis=0)
    assert np.abs(momentum).max() <= 0.046 * p["margin"] + 1e-12
    assert p["limit_use"]["momentum"] <= p["margin"] + 1e-12
    # The target is met within the plan, by the prediction it returns.
    t_met = p["target_met_s"]
    assert t_met is not None and t_met <= p["t"][-1] + p["period_s"]
    k = np.searchsorted(p["prediction_t"], t_met)
    assert 3 * p["relative_sigma"][k] <= 0.01
    assert p["sigma_kg_m2"].shape == (len(p["prediction_t"]), 6)


def test_a_file_without_sensors_is_refused_by_key(tmp_path):
    bad = tmp_path / "sc.toml"
    bad.write_text(SAT1.read_text().split("[sensors]")[0])
    with pytest.raises(ValueError, match="sensors"):
        inertia.plan(bad)


def test_the_chain_is_chosen_by_rehearsal_and_returned():
    """``chain="auto"`` rehearses 30, 60 and 120 s chains and returns the one kept, as the
    CLI prints it; without rehearsals it is the estimator's default; a fixed chain is kept
    as given; anything else is refused."""
    p = inertia.plan(SAT1)
    trials = p["chain_trials"]
    assert [c for c, _ in trials] == [30.0, 60.0, 120.0]
    best = min(t for _, t in trials if t is not None)
    assert p["reported_target_met_s"] == best
    assert p["chain_s"] == next(c for c, t in trials if t == best)
    assert inertia.plan(SAT1, rehearsals=0)["chain_s"] == 30.0
    fixed = inertia.plan(SAT1, chain=45.0)
    assert fixed["chain_s"] == 45.0 and fixed["chain_trials"] == []
    with pytest.raises(ValueError, match="chain"):
        inertia.plan(SAT1, chain="fast")
