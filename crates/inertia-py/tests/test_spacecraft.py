"""A spacecraft file's rotors through Python: the same report as the CLI's on the same
files, the wheel speeds summed into ``rho`` as the run sums them, pickling that keeps the
rotors, and misuse refused by name."""

import pickle

import numpy as np
import pytest

import inertia
from conftest import cli_estimate, run_cli
from test_cli_agreement import TOL, differences

PYRAMID = """
rotor_errors = "independent"
{rotors}
"""

ROTOR = """
[[rotor]]
name = "rw{i}"
axis = [{x}, {y}, 0.577350269]
spin_inertia_kg_m2 = {j}
spin_inertia_sigma_kg_m2 = {s}
speed_column = "rw{i}_rpm"
speed_unit = "rpm"
"""


def pyramid(j, sigma):
    c = 0.816496581
    axes = [(c, 0.0), (0.0, c), (-c, 0.0), (0.0, -c)]
    return PYRAMID.format(rotors="".join(
        ROTOR.format(i=i + 1, x=x, y=y, j=j[i], s=sigma * j[i]) for i, (x, y) in enumerate(axes)
    ))


@pytest.fixture(scope="module")
def speed_file(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("sc")
    truth = d / "truth.toml"
    truth.write_text(pyramid([1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3], 0.0))
    stated = d / "stated.toml"
    stated.write_text(pyramid([1.52e-3, 1.58e-3, 1.73e-3, 1.8e-3], 0.02))
    f = d / "slew.csv"
    run_cli(cli, "simulate", "--scenario", "slew", "--duration", "120", "--spacecraft", truth, "-o", f)
    plain = d / "slew_rho.csv"
    run_cli(cli, "simulate", "--scenario", "slew", "--duration", "120", "-o", plain)
    return f, truth, stated, plain


def test_report_matches_cli(cli, speed_file):
    f, _, stated, _ = speed_file
    py = inertia.estimate(f, spacecraft=stated)
    c = cli_estimate(cli, f, "--spacecraft", stated)
    assert differences(c, py.to_dict()) <= TOL
    assert py.text == run_cli(cli, "estimate", f, "--spacecraft", stated).stdout
    assert py.report["rotor_inertia"]["rotors"] == ["rw1", "rw2", "rw3", "rw4"]
    assert all(s > 0 for s in py.report["rotor_inertia"]["sigma_kg_m2"])


def test_speeds_sum_into_rho_as_the_rows_need(speed_file):
    f, truth, _, plain = speed_file
    by_speed = inertia.read_csv(f, spacecraft=truth)
    by_rho = inertia.read_csv(plain)
    assert np.abs(by_speed.rho - by_rho.rho).max() < 1e-12 * np.abs(by_rho.rho).max()
    a = inertia.estimate(by_speed).inertia
    b = inertia.estimate(by_rho).inertia
    assert np.abs(a - b).max() < 1e-9


def test_pickling_keeps_the_rotors(speed_file):
    f, _, stated, _ = speed_file
    t = inertia.read_csv(f, spacecraft=stated)
    back = pickle.loads(pickle.dumps(t))
    a, b = inertia.estimate(t), inertia.estimate(back)
    assert differences(a.to_dict(), b.to_dict()) == 0.0
    assert b.report["rotor_inertia"] is not None
    with pytest.warns(UserWarning, match="do not travel with the frame"):
        t.to_dataframe()


def test_misuse_is_refused_by_name(speed_file, tmp_path):
    f, truth, _, plain = speed_file
    t = inertia.read_csv(plain)
    with pytest.raises(TypeError, match="spacecraft"):
        inertia.estimate(t, spacecraft=truth)
    # The rho columns and the rotors' speed columns: the momentum given twice.
    with pytest.raises(inertia.DataError, match="rho_x.*spacecraft file's rotor speeds"):
        both = tmp_path / "both.csv"
        text = plain.read_text().splitlines()
        speeds = f.read_text().splitlines()
        both.write_text("\n".join(a + "," + ",".join(b.split(",")[-4:]) for a, b in zip(text, speeds)) + "\n")
        inertia.read_csv(both, spacecraft=truth)
    bad = tmp_path / "bad.toml"
    bad.write_text(truth.read_text().replace('speed_unit = "rpm"', 'speed_unit = "RPM"', 1))
    with pytest.raises(ValueError, match=r"bad.toml:\d+: `rotor\[0\].speed_unit`"):
        inertia.read_csv(f, spacecraft=bad)


def test_calibration_matches_cli_and_is_refused_without_batch(cli, tmp_path):
    """``calibrate_rotors=True`` with ``batch=True`` on a momentum-biased slew: the CLI's
    report (``--batch --calibrate-rotors``), the four spin-inertia sources fixed but for
    their common scale; without ``batch`` a ValueError naming the keywords."""
    truth = tmp_path / "truth.toml"
    truth.write_text(pyramid([1.5e-3, 1.6e-3, 1.7e-3, 1.8e-3], 0.0))
    stated = tmp_path / "stated.toml"
    stated.write_text(pyramid([1.52e-3, 1.58e-3, 1.73e-3, 1.8e-3], 0.02))
    f = tmp_path / "biased.csv"
    run_cli(cli, "simulate", "--scenario", "slew", "--duration", "120", "--momentum-bias",
            "0.03:-0.02:0.1", "--spacecraft", truth, "-o", f)
    py = inertia.estimate(f, spacecraft=stated, batch=True, calibrate_rotors=True)
    c = cli_estimate(cli, f, "--spacecraft", stated, "--batch", "--calibrate-rotors")
    assert differences(c, py.to_dict()) <= TOL
    cal = py.report["rotor_calibration"]
    assert cal["sources"] == [f"rw{i} spin inertia" for i in range(1, 5)]
    assert cal["unit"] == ["relative"] * 4 and cal["data_fixed"] == 3
    with pytest.raises(ValueError, match="calibrate_rotors needs batch"):
        inertia.estimate(f, spacecraft=stated, calibrate_rotors=True)
