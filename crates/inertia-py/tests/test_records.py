"""Several records of one spacecraft through Python: ``estimate([a, b, …], batch=True)``
gives the CLI's ``estimate --batch a b …`` answer; the pooled σ is below each record's;
records are refused by name where the run cannot take them, and a bad row is named in
its own file."""

import pytest

import inertia
from conftest import run_cli
from test_cli_agreement import TOL, differences
import json


@pytest.fixture(scope="module")
def records(cli, tmp_path_factory):
    d = tmp_path_factory.mktemp("records")
    out = []
    for k in range(3):
        f = d / f"r{k}.csv"
        run_cli(
            cli, "simulate", "--scenario", "slew", "--duration", "60", "--seed", str(k + 1),
            "--momentum-bias", f"0.0{k}:0:0.02", "--constant-torque-nm", f"0:1e-6:-{k}e-6",
            "-o", f,
        )
        out.append(f)
    return out


def test_records_match_cli(cli, records):
    got = inertia.estimate(records, batch=True).to_dict()
    expected = json.loads(run_cli(cli, "estimate", "--batch", "--json", *records).stdout)
    assert differences(expected, got) <= TOL
    assert got["records"] == 3
    assert got["file"] == ", ".join(str(r) for r in records)


def test_pooled_sigma_is_below_each_records(records):
    pooled = inertia.estimate(records, batch=True)
    for r in records:
        one = inertia.estimate(r, batch=True)
        assert "records" not in one.to_dict()
        assert all(pooled.sigma[:3] < one.sigma[:3])


def test_telemetry_records_equal_paths(records):
    read = [inertia.read_csv(r) for r in records]
    a = inertia.estimate(read, batch=True)
    b = inertia.estimate(records, batch=True)
    assert (a.j == b.j).all()


def test_records_refused_by_name(records):
    with pytest.raises(ValueError, match=r"batch=True"):
        inertia.estimate(records)
    with pytest.raises(ValueError, match="variational"):
        inertia.estimate(records, batch=True, estimator="variational")
    with pytest.raises(ValueError, match="empty"):
        inertia.estimate([], batch=True)
    with pytest.raises(TypeError, match=r"records\[1\]"):
        inertia.estimate([records[0], 3], batch=True)


def test_bad_row_named_in_its_own_file(records, tmp_path):
    bad = tmp_path / "bad.csv"
    lines = records[1].read_text().splitlines()
    lines[5] = lines[5].replace(",", ",nan,", 1).replace(",nan,", ",", 1)
    # Time going back on line 6 of the second file.
    fields = lines[5].split(",")
    fields[0] = "0.0"
    lines[5] = ",".join(fields)
    bad.write_text("\n".join(lines) + "\n")
    with pytest.raises(inertia.DataError, match=r"bad\.csv:6:"):
        inertia.estimate([records[0], bad], batch=True)


def test_a_list_of_times_is_still_an_array(records):
    t = inertia.read_csv(records[0])
    arrays = inertia.estimate(list(t.t), t.q, t.rho, w=t.w, batch=True)
    assert arrays.j is not None
