"""The package against the command line on the same files: reports, histories and
error messages. The figure of merit is the largest difference of any number in the
report (J, σ, principal moments and axes, condition, …), required below 1e-12."""

import math

import numpy as np
import pytest

import inertia
from conftest import cli_estimate, run_cli

TOL = 1e-12

CASES = [
    ("slew", [], {}),
    ("slew", ["--estimator", "variational"], dict(estimator="variational")),
    ("slew", ["--batch"], dict(batch=True)),
    ("slew", ["--estimator", "variational", "--gyro-noise", "1e-5", "--batch"],
     dict(estimator="variational", gyro_noise=1e-5, batch=True)),
    ("slew", ["--estimator", "momentum"], dict(estimator="momentum")),
    ("slew", ["--memory", "60", "--rho-model", "plain", "--no-torque-bias"],
     dict(memory=60.0, rho_model="plain", torque_bias=False)),
    ("spin", ["--bound", "J33=2.7:3.3", "--constraints", "paper"],
     dict(bounds={"J33": (2.7, 3.3)}, constraints="paper")),
    ("spin", ["--estimator", "finite-difference", "--every", "5"],
     dict(estimator="finite-difference", every=5)),
    ("smallsat", [], {}),
    ("spin", ["--diagonal"], dict(diagonal=True)),
    ("slew", ["--bound", "J12=0.0368:0.0368"], dict(bounds={"J12": (0.0368, 0.0368)})),
    ("smallsat", ["--rotation-source", "gyro", "--chain", "0"],
     dict(rotation_source="gyro", chain=0.0)),
    ("spin", ["--gyro-noise", "1e-5", "--attitude-drift", "6e-4", "--every", "10"],
     dict(gyro_noise=1e-5, attitude_drift=6e-4, every=10)),
]


def differences(a, b, path=""):
    """Largest difference between two reports' numbers; structure and strings equal."""
    if isinstance(a, dict):
        assert isinstance(b, dict) and set(a) == set(b), path
        return max([differences(a[k], b[k], f"{path}.{k}") for k in a], default=0.0)
    if isinstance(a, list):
        assert isinstance(b, list) and len(a) == len(b), path
        return max([differences(x, y, f"{path}[{i}]") for i, (x, y) in enumerate(zip(a, b))], default=0.0)
    if isinstance(a, (int, float)) and not isinstance(a, bool):
        assert isinstance(b, (int, float)), path
        return abs(a - b) / max(1.0, abs(a))
    assert a == b, f"{path}: {a!r} != {b!r}"
    return 0.0


def load(path):
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    extra = dict(tau=data[:, 8:11], w=data[:, 11:14]) if data.shape[1] >= 14 else dict(tau=data[:, 8:11])
    return (data[:, 0], data[:, 1:5], data[:, 5:8]), extra


@pytest.mark.parametrize("name, options, kwargs", CASES, ids=[" ".join([c[0], *c[1]]) for c in CASES])
def test_report_matches_cli(cli, files, name, options, kwargs):
    path = files[name]
    expected = cli_estimate(cli, path, *options)
    # The file, read as the CLI reads it.
    got = inertia.estimate(str(path), **kwargs)
    assert differences(expected, got.to_dict()) <= TOL
    assert got.status == expected["status"]
    # The readable report is the CLI's, line for line.
    assert got.text == run_cli(cli, "estimate", path, *options).stdout
    if expected["inertia"] is not None:
        assert np.abs(got.inertia - np.array(expected["inertia"])).max() <= TOL * np.abs(got.inertia).max()
    # The same numbers as arrays (the input summary names `<arrays>` instead of the file).
    pos, extra = load(path)
    arrays = inertia.estimate(*pos, **extra, **kwargs).to_dict()
    assert arrays.pop("file") == "<arrays>"
    expected.pop("file")
    assert differences(expected, arrays) <= TOL


def test_history_matches_cli(cli, files, tmp_path):
    out = tmp_path / "h.csv"
    run_cli(cli, "estimate", files["spin"], "--estimator", "variational", "-o", out)
    pd = pytest.importorskip("pandas")
    expected = pd.read_csv(out, keep_default_na=False, na_values=[""])
    got = inertia.estimate(inertia.read_csv(files["spin"]), estimator="variational", history=True).history
    assert list(got.columns) == list(expected.columns) == list(inertia.HISTORY_COLUMNS)
    assert len(got) == len(expected) > 1000
    for c in got.columns:
        if c in ("status",):
            assert list(got[c]) == list(expected[c])
        elif c == "reason":
            assert [r if isinstance(r, str) else "" for r in got[c]] == [r if isinstance(r, str) else "" for r in expected[c]]
        else:
            a, b = got[c].to_numpy(float), expected[c].to_numpy(float)
            assert np.array_equal(np.isnan(a), np.isnan(b)), c
            ok = ~np.isnan(a)
            assert np.all(np.abs(a[ok] - b[ok]) <= TOL * np.maximum(1.0, np.abs(b[ok]))), c


def test_truth_matches_cli(cli, files):
    expected = cli_estimate(cli, files["spin"], "--truth", str(files["spin"]).replace(".csv", ".truth.json"))
    sim = inertia.simulate("spin")
    got = inertia.estimate(files["spin"], truth=sim.inertia)
    assert math.isclose(got.relative_error, expected["relative_error"], rel_tol=TOL)


def test_simulate_matches_cli_file(files):
    """`inertia.simulate` gives the samples of `inertia simulate`'s file, bit for bit."""
    for name, kw in [("slew", dict(scenario="slew")), ("smallsat", dict(preset="small-sat", duration=200))]:
        sim = inertia.simulate(**kw)
        tel = inertia.read_csv(files[name])
        for a in ("t", "q", "rho", "tau", "w"):
            assert np.array_equal(getattr(sim.telemetry, a), getattr(tel, a)), (name, a)
        assert tel.stats == sim.telemetry.stats


def rewrite(src, dst, edit):
    lines = src.read_text().splitlines()
    dst.write_text("\n".join(edit(lines)) + "\n")
    return dst


def cli_error(cli, path, *options):
    p = run_cli(cli, "estimate", path, *options, check=False)
    assert p.returncode == 2, p
    assert p.stderr.startswith("inertia: ")
    return p.stderr[len("inertia: "):].strip()


def set_fields(line, values):
    f = line.split(",")
    for k, v in values.items():
        f[k] = v
    return ",".join(f)


@pytest.mark.parametrize(
    "what, edit, line",
    [
        ("non-unit quaternion", lambda L: L[:8] + [set_fields(L[8], {1: "0.5"})] + L[9:], 9),
        ("comment line", lambda L: L[:20] + ["# note"] + L[20:], 21),
        ("unparsable number", lambda L: L[:30] + [set_fields(L[30], {6: "1.2.3"})] + L[31:], 31),
        ("time going back", lambda L: L[:40] + [set_fields(L[40], {0: "0.1"})] + L[41:], 41),
        ("out of range", lambda L: L[:50] + [set_fields(L[50], {7: "1e15"})] + L[51:], 51),
        ("missing column", lambda L: [L[0].replace("rho_y", "rho_q")] + L[1:], 1),
        ("duplicated column", lambda L: [L[0].replace("tau_x", "rho_x")] + L[1:], 1),
        ("short row", lambda L: L[:60] + [",".join(L[60].split(",")[:5])] + L[61:], 61),
    ],
)
def test_file_errors_match_cli(cli, files, tmp_path, what, edit, line):
    bad = rewrite(files["slew"], tmp_path / "bad.csv", edit)
    expected = cli_error(cli, bad)
    with pytest.raises(inertia.DataError) as e:
        inertia.read_csv(bad)
    assert str(e.value) == expected
    assert e.value.line == line
    assert expected.startswith(f"{bad}:{line}:")


def glitch(lines, k=1502):
    """Turn the attitude of line k by 90° about body x."""
    f = lines[k - 1].split(",")
    x, y, z, w = map(float, f[1:5])
    c = s = math.sqrt(0.5)
    # q ⊗ [s, 0, 0, c] (Hamilton, scalar last)
    q = (w * s + x * c, y * c + z * s, z * c - y * s, w * c - x * s)
    f[1:5] = [repr(v) for v in q]
    return lines[: k - 1] + [",".join(f)] + lines[k:]


def test_estimator_errors_match_cli(cli, files, tmp_path):
    bad = rewrite(files["slew"], tmp_path / "glitch.csv", glitch)
    for options, kwargs in [([], {}), (["--batch"], dict(batch=True)), (["--estimator", "variational"], dict(estimator="variational"))]:
        expected = cli_error(cli, bad, *options)
        assert f"{bad}:1502:" in expected
        with pytest.raises(inertia.DataError) as e:
            inertia.estimate(bad, **kwargs)
        assert expected.endswith(" (option: --glitches keep)")
        assert str(e.value) == expected.replace("(option: --glitches keep)", '(keyword: glitches="keep")')
        assert e.value.line == 1502
    # Kept, as with --glitches keep: the same report.
    expected = cli_estimate(cli, bad, "--glitches", "keep")
    assert differences(expected, inertia.estimate(bad, glitches="keep").to_dict()) <= TOL


def permute(order):
    def edit(lines):
        out = [lines[0]]
        for line in lines[1:]:
            f = line.split(",")
            q = f[1:5]
            f[1:5] = [q[i] for i in order]
            out.append(",".join(f))
        return out

    return edit


def test_quaternion_conventions_match_cli(cli, files, tmp_path):
    reference = inertia.estimate(files["slew"])
    # Scalar first: the columns q_x..q_w hold [w, x, y, z].
    sf = rewrite(files["slew"], tmp_path / "sf.csv", permute([3, 0, 1, 2]))
    expected = cli_estimate(cli, sf, "--scalar-first")
    got = inertia.estimate(sf, scalar_first=True)
    assert differences(expected, got.to_dict()) <= TOL
    assert np.array_equal(got.inertia, reference.inertia)
    # Arrays in that convention, with the same option.
    pos, extra = load(sf)
    assert np.array_equal(inertia.estimate(*pos, **extra, scalar_first=True).inertia, reference.inertia)
    # Read without the option: the check against the gyro names it, as the CLI does.
    expected = cli_error(cli, sf)
    assert "read them scalar first (option: --scalar-first)" in expected
    with pytest.raises(inertia.DataError) as e:
        inertia.estimate(sf)
    assert str(e.value) == expected.replace("(option: --scalar-first)", "(keyword: scalar_first=True)")
    with pytest.raises(inertia.DataError) as e:
        inertia.estimate(*pos, **extra)
    assert "read them scalar first (keyword: scalar_first=True)" in str(e.value)
    # JPL (inertial → body): the CLI's --jpl.
    expected = cli_estimate(cli, files["slew"], "--jpl")
    assert differences(expected, inertia.estimate(files["slew"], jpl=True).to_dict()) <= TOL


def test_renamed_columns_match_cli(cli, files, tmp_path):
    renamed = rewrite(files["spin"], tmp_path / "renamed.csv",
                      lambda L: [L[0].replace("t,", "time,", 1).replace("rho_x", "hw_x")] + L[1:])
    expected = cli_estimate(cli, renamed, "--column", "t=time", "--column", "rho_x=hw_x")
    got = inertia.estimate(renamed, columns={"t": "time", "rho_x": "hw_x"})
    assert differences(expected, got.to_dict()) <= TOL


@pytest.mark.parametrize("products", ["tensor", "cad"])
def test_prior_matches_cli(cli, files, tmp_path, products):
    """A CAD prior (issue 13) through the file and option of the CLI and the arguments
    here, in either products-of-inertia convention."""
    import json
    path = files["spin"]
    truth = np.array(json.loads(path.with_suffix(".truth.json").read_text())["inertia_kg_m2"])
    prior = truth * np.where(np.eye(3) == 1, 1.02, 1.0)
    if products == "cad":
        prior = np.where(np.eye(3) == 1, prior, -prior)
    f = tmp_path / "prior.json"
    f.write_text(json.dumps({"inertia_kg_m2": prior.tolist()}))
    options = ["--prior", str(f), "--prior-sigma", "5%", "--products", products]
    expected = cli_estimate(cli, path, *options)
    got = inertia.estimate(str(path), prior=prior, prior_sigma="5%", products=products)
    assert differences(expected, got.to_dict()) <= TOL
    assert got.to_dict()["prior"]["rows"] == 6
    # σ per element as a matrix gives the same as the relative one it equals.
    sigma = np.abs(truth * 1.02) * 0.05
    d = np.sqrt(np.outer(np.diag(truth) * 1.02, np.diag(truth) * 1.02)) * 0.05
    sigma = np.where(np.eye(3) == 1, sigma, d)
    by_matrix = inertia.estimate(str(path), prior=prior, prior_sigma=sigma, products=products)
    assert differences(expected, by_matrix.to_dict()) <= 1e-9
    with pytest.raises(ValueError, match="prior_sigma"):
        inertia.estimate(str(path), prior=prior)
    # An absolute σ, as a number or as the CLI's text.
    absolute = cli_estimate(cli, path, "--prior", str(f), "--prior-sigma", "0.02", "--products", products)
    for sigma in (0.02, "0.02"):
        got = inertia.estimate(str(path), prior=prior, prior_sigma=sigma, products=products)
        assert differences(absolute, got.to_dict()) <= TOL


def test_the_keywords_are_a_run_files_keys(cli, files, tmp_path):
    """Python's keywords and ``inertia estimate --settings`` read the same description:
    the keywords written as a JSON run file give the CLI the report Python gives."""
    import json

    kwargs = dict(memory=60.0, rho_model="plain", torque_bias=False, every=2,
                  bounds=["J33=2.7:3.3"], inertial_torque="on", chain=20.0)
    run = tmp_path / "run.json"
    run.write_text(json.dumps(kwargs))
    expected = cli_estimate(cli, files["slew"], "--settings", str(run))
    got = inertia.estimate(str(files["slew"]), **kwargs).to_dict()
    assert differences(expected, got) <= TOL
    assert expected["j"] != cli_estimate(cli, files["slew"])["j"]
