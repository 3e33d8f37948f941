"""The damping unknown through Python: ``damping=True`` gives the CLI's ``--damping``
answer, with ``D`` and its σ in the report; an estimator without a row model refuses it
by name."""

import pytest

import inertia
from conftest import cli_estimate
from test_cli_agreement import TOL, differences


def test_damping_matches_cli(cli, files):
    got = inertia.estimate(files["slew"], damping=True).to_dict()
    expected = cli_estimate(cli, files["slew"], "--damping")
    assert differences(expected, got) <= TOL
    assert got["row_model"]["damping"] is True
    assert got["damping_sigma_nms"] > 0.0
    assert abs(got["damping_nms"]) < 1.0


def test_damping_refused_without_row_model(files):
    with pytest.raises(ValueError, match="damping"):
        inertia.estimate(files["slew"], estimator="variational", damping=True)
