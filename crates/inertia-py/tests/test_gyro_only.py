"""Gyro-only telemetry through Python: a file without quaternion columns is read with its
attitude integrated from the gyro, as the CLI reads it, and pickles with that flag."""

import pickle

import inertia
from conftest import cli_estimate, run_cli
from test_cli_agreement import TOL, differences


def test_gyro_only_file_matches_cli(cli, files, tmp_path):
    rows = files["slew"].read_text().splitlines()
    f = tmp_path / "gyro.csv"
    f.write_text("\n".join(",".join(r.split(",")[:1] + r.split(",")[5:]) for r in rows) + "\n")
    t = inertia.read_csv(f)
    assert t.stats["attitude_from_gyro"] is True
    got = inertia.estimate(f)
    expected = cli_estimate(cli, f)
    assert expected["attitude_from_gyro"] is True
    assert differences(expected, got.to_dict()) <= TOL
    assert got.text == run_cli(cli, "estimate", f).stdout
    assert "attitude: integrated from the gyro rates" in got.text
    back = pickle.loads(pickle.dumps(t))
    assert back.stats["attitude_from_gyro"] is True
    assert differences(inertia.estimate(back).to_dict(), inertia.estimate(t).to_dict()) == 0.0


def test_arrays_without_quaternions_match_the_file(files, tmp_path):
    """``q=None`` with ``w=``: the same answer as the gyro-only file, bit for bit, and a
    quaternion convention given without quaternions is refused by name."""
    rows = files["slew"].read_text().splitlines()
    f = tmp_path / "gyro.csv"
    f.write_text("\n".join(",".join(r.split(",")[:1] + r.split(",")[5:]) for r in rows) + "\n")
    t = inertia.read_csv(files["slew"])
    from_file = inertia.estimate(f).to_dict()
    from_arrays = inertia.estimate(t.t, None, t.rho, tau=t.tau, w=t.w).to_dict()
    assert from_arrays.pop("file") == "<arrays>"
    from_file.pop("file")
    assert differences(from_file, from_arrays) == 0.0
    assert from_arrays["attitude_from_gyro"] is True
    import pytest

    with pytest.raises(ValueError, match="q=None"):
        inertia.estimate(t.t, None, t.rho, w=t.w, jpl=True)


def test_dataframe_without_quaternions_matches_the_file(files, tmp_path):
    """A DataFrame with gyro columns and no quaternion column: the attitude integrated
    from the gyro, bit for bit as the gyro-only file; a column that looks like a
    quaternion keeps the missing ``q_*`` an error instead."""
    import pytest

    pd = pytest.importorskip("pandas")
    rows = files["slew"].read_text().splitlines()
    f = tmp_path / "gyro.csv"
    f.write_text("\n".join(",".join(r.split(",")[:1] + r.split(",")[5:]) for r in rows) + "\n")
    frame = inertia.read_csv(files["slew"]).to_dataframe().drop(columns=["q_x", "q_y", "q_z", "q_w"])
    got = inertia.estimate(frame).to_dict()
    expected = inertia.estimate(f).to_dict()
    assert got.pop("file") == "<DataFrame>"
    expected.pop("file")
    assert differences(expected, got) == 0.0
    assert got["attitude_from_gyro"] is True
    with pytest.raises(inertia.DataError, match="q_x"):
        inertia.estimate(frame.assign(qx=0.0))
