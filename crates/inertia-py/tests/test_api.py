"""The package's own behaviour: recovery of the true J, streaming against one-shot and
batch runs, DataFrames, pickling, the GIL, optional pandas."""

import pickle
import sys
import threading
import time

import numpy as np
import pytest

import inertia
from conftest import run_cli


@pytest.fixture(scope="module")
def slew():
    return inertia.simulate("slew", seed=3)


def rel(a, b):
    return np.linalg.norm(a - b) / np.linalg.norm(b)


@pytest.mark.parametrize(
    "scenario, kwargs, limit",
    [
        ("slew", {}, 1e-4),
        ("spin", dict(bounds={"J33": (2.7, 3.3)}), 1e-4),
        ("slew", dict(estimator="variational"), 1e-3),
        ("spin", dict(estimator="variational", bounds=["J33=2.7:3.3"], constraints="paper"), 1e-3),
    ],
)
def test_recovers_the_true_inertia(scenario, kwargs, limit):
    sim = inertia.simulate(scenario, seed=7)
    tel, truth = sim
    e = inertia.estimate(tel, truth=truth, **kwargs)
    assert e.inertia.shape == (3, 3) and e.sigma.shape == (6,)
    assert rel(e.inertia, truth) < limit
    assert e.relative_error == pytest.approx(rel(e.inertia, truth), rel=1e-9)
    # Principal moments and axes reconstruct J.
    A, m = e.principal_axes, e.principal_moments
    assert np.all(np.diff(m) >= 0)
    assert np.allclose(A @ np.diag(m) @ A.T, e.inertia, atol=1e-9)
    assert np.allclose(A.T @ A, np.eye(3), atol=1e-9)


def test_inertia_change_in_simulation():
    sim = inertia.simulate("slew", duration=400, inertia_step=(300, 1.1), seed=2)
    np.testing.assert_allclose(sim.inertia, 1.1 * sim.inertia_initial, rtol=1e-15)
    before = inertia.estimate(sim.telemetry.t[:2900], sim.telemetry.q[:2900], sim.telemetry.rho[:2900],
                              tau=sim.telemetry.tau[:2900], w=sim.telemetry.w[:2900])
    assert rel(before.inertia, sim.inertia_initial) < 1e-3


def test_streaming_equals_one_shot(slew):
    tel, _ = slew
    one_shot = inertia.estimate(tel)
    s = inertia.Estimator()
    assert s.estimate is None
    produced = []
    for k in range(200):
        e = s.push(tel.t[k], tel.q[k], tel.rho[k], tel.tau[k], tel.w[k])
        if e is not None:
            produced.append(e.t)
    assert produced and produced[-1] == pytest.approx(tel.t[199])
    last = s.push_many(tel.t[200:], tel.q[200:], tel.rho[200:], tau=tel.tau[200:], w=tel.w[200:])
    assert s.samples == len(tel)
    assert last.t == one_shot.t
    np.testing.assert_allclose(last.inertia, one_shot.inertia, rtol=0, atol=1e-12)
    np.testing.assert_allclose(last.sigma, one_shot.sigma, rtol=0, atol=1e-12)
    assert last.status == one_shot.status


def test_streaming_then_finish_equals_one_shot_on_held_wheel_speeds(cli, tmp_path):
    # The lab throw holds its wheel speeds at 100 Hz: estimate() gives the final answer
    # with the held lag's term in σ; the streaming estimator's answers carry none until
    # finish() gives the same final answer.
    path = tmp_path / "throw.csv"
    run_cli(cli, "simulate", "--preset", "throw", "--seed", "2", "-o", path)
    tel = inertia.read_csv(path)
    one_shot = inertia.estimate(tel)
    s = inertia.Estimator()
    last = s.push_many(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w)
    final = s.finish()
    assert final.t == last.t == one_shot.t
    np.testing.assert_array_equal(final.inertia, last.inertia)
    assert np.all(final.sigma >= last.sigma) and np.any(final.sigma > 1.01 * last.sigma)
    np.testing.assert_allclose(final.sigma, one_shot.sigma, rtol=0, atol=1e-15)
    assert final.status == one_shot.status
    assert "σ carries" in " ".join(w["message"] for w in final.report["warnings"])


def test_streaming_agrees_with_batch(slew):
    tel, truth = slew
    stream = inertia.Estimator(estimator="variational")
    stream.push_many(tel.t, tel.q, tel.rho, tel.tau, tel.w)
    batch = inertia.estimate(tel, estimator="variational", batch=True)
    assert batch.report["batch"] and not stream.estimate.report["batch"]
    # Two solutions of the same least-squares problem, each within 1e-3 of the truth,
    # closer still to each other.
    assert rel(batch.inertia, truth) < 1e-3 and rel(stream.estimate.inertia, truth) < 1e-3
    assert rel(stream.estimate.inertia, batch.inertia) < 1e-4


def test_streaming_errors():
    s = inertia.Estimator()
    with pytest.raises(ValueError, match=r"^q: expected 4 numbers"):
        s.push(0.0, [0, 0, 1], [0, 0, 0])
    s.push(0.0, [0, 0, 0, 1], [0, 0, 0], w=[0, 0, 0])
    with pytest.raises(inertia.DataError, match=r"^t\[1\]: time 0 s does not increase"):
        s.push(0.0, [0, 0, 0, 1], [0, 0, 0], w=[0, 0, 0])
    with pytest.raises(inertia.DataError, match=r"^w\[1\]: gyro rates missing here but given"):
        s.push(0.1, [0, 0, 0, 1], [0, 0, 0])
    assert s.samples == 1  # rejected samples leave the estimator as it was
    with pytest.raises(ValueError, match=r"the memory 0.01 s is shorter than the sample period 0.1 s.*\(keyword: memory\)"):
        m = inertia.Estimator(memory=0.01)
        m.push(0.0, [0, 0, 0, 1], [0, 0, 0])
        m.push(0.1, [0, 0, 0, 1], [0, 0, 0])


def test_dataframe_input(slew):
    pd = pytest.importorskip("pandas")
    tel, _ = slew
    df = tel.to_dataframe()
    assert list(df.columns) == list(inertia.CSV_COLUMNS)
    ref = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w)
    np.testing.assert_array_equal(inertia.estimate(df).inertia, ref.inertia)
    # Renamed columns, extra columns, datetime time stamps.
    renamed = df.rename(columns={"t": "time", "rho_x": "hw_x"}).assign(extra=1.0)
    renamed["time"] = pd.Timestamp("2026-11-21T09:06:00Z") + pd.to_timedelta(renamed["time"], unit="s")
    got = inertia.estimate(renamed, columns={"t": "time", "rho_x": "hw_x"})
    np.testing.assert_allclose(got.inertia, ref.inertia, rtol=0, atol=1e-9)
    with pytest.raises(inertia.DataError, match=r"missing column `rho_y` \(columns present: t,q_x"):
        inertia.estimate(df.drop(columns=["rho_y"]))
    with pytest.raises(inertia.DataError, match="missing column `w_z`"):
        inertia.estimate(df.drop(columns=["w_z"]))
    bad = df.copy()
    bad.loc[12, "q_w"] = 2.0
    with pytest.raises(inertia.DataError, match=r"^row 12: columns `q_x,q_y,q_z,q_w`: quaternion norm"):
        inertia.estimate(bad)
    with pytest.raises(TypeError, match="only with arrays"):
        inertia.estimate(df, tel.q)


def test_history_dataframe(slew):
    tel, _ = slew
    e = inertia.estimate(tel, history=True, estimator="variational")
    h = e.history
    assert list(h.columns) == list(inertia.HISTORY_COLUMNS)
    assert len(h) > 0.9 * len(tel)
    last = h.iloc[-1]
    assert last["t"] == e.t and last["status"] == e.status
    np.testing.assert_array_equal(last[["J11", "J22", "J33", "J12", "J13", "J23"]].to_numpy(float), e.j)
    with pytest.raises(ValueError, match="history=True"):
        inertia.estimate(tel).history


def test_without_pandas_only_dataframes_fail(slew, monkeypatch):
    tel, _ = slew
    monkeypatch.setitem(sys.modules, "pandas", None)  # import pandas now fails
    e = inertia.estimate(tel, history=True)  # arrays work without pandas
    assert e.history_columns["t"].shape[0] > 0
    with pytest.raises(ImportError, match="needs pandas, which is not installed: pip install pandas"):
        e.history
    with pytest.raises(ImportError, match="pip install pandas"):
        tel.to_dataframe()


def test_results_pickle(slew):
    tel, truth = slew
    e = inertia.estimate(tel, truth=truth, history=True)
    back = pickle.loads(pickle.dumps(e))
    assert type(back) is inertia.Estimate
    np.testing.assert_array_equal(back.inertia, e.inertia)
    np.testing.assert_array_equal(back.sigma, e.sigma)
    assert back.to_dict() == e.to_dict() and back.text == e.text
    assert back.history.equals(e.history)
    # Telemetry and simulations pickle too (rebuilt from their arrays).
    t2 = pickle.loads(pickle.dumps(tel))
    for a in ("t", "q", "rho", "tau", "w"):
        np.testing.assert_array_equal(getattr(t2, a), getattr(tel, a))
    assert t2.stats == tel.stats
    assert inertia.estimate(t2).to_dict() == inertia.estimate(tel).to_dict()
    arrays = inertia.Telemetry.from_arrays(tel.t, tel.q, tel.rho, tel.tau, tel.w)
    assert inertia.estimate(arrays).report["file"] == "<arrays>"
    np.testing.assert_array_equal(inertia.estimate(t2).inertia, inertia.estimate(tel).inertia)
    sim = pickle.loads(pickle.dumps(slew))
    np.testing.assert_array_equal(sim.inertia, truth)


def test_to_dict_is_the_json_report(slew):
    import json

    e = inertia.estimate(slew.telemetry)
    d = e.to_dict()
    assert json.loads(json.dumps(d)) == d
    assert d["schema_version"] == 1 and d["estimator"] == inertia.DEFAULT_ESTIMATOR == "discrete-momentum"
    assert str(e).startswith("<simulated>: 3001 samples, h = 0.1 s")


def test_gil_is_released_during_estimation():
    """While another thread estimates, this thread keeps running Python code."""
    tel = inertia.simulate("slew", duration=3000).telemetry
    t0 = time.perf_counter()
    inertia.estimate(tel)
    alone = time.perf_counter() - t0
    assert alone > 0.1, "too short to tell"
    done = threading.Event()

    def work():
        inertia.estimate(tel)
        done.set()

    th = threading.Thread(target=work)
    ticks = []
    th.start()
    while not done.is_set():
        ticks.append(time.perf_counter())
        time.sleep(0.001)
    th.join()
    gaps = np.diff(ticks)
    # With the GIL held the whole estimate (`alone` seconds) would be one gap.
    assert len(ticks) > 10 and gaps.max() < alone / 3, (gaps.max(), alone)


def test_conventions_on_arrays(slew):
    tel, _ = slew
    ref = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w)
    wxyz = tel.q[:, [3, 0, 1, 2]]
    got = inertia.estimate(tel.t, wxyz, tel.rho, tau=tel.tau, w=tel.w, scalar_first=True)
    np.testing.assert_array_equal(got.inertia, ref.inertia)
    got = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w, jpl=True)
    np.testing.assert_array_equal(got.inertia, ref.inertia)
    # The inertial → body reading (conjugate) is caught against the gyro.
    conj = tel.q * [-1, -1, -1, 1]
    with pytest.raises(inertia.DataError, match="look conjugated"):
        inertia.estimate(tel.t, conj, tel.rho, tau=tel.tau, w=tel.w)
    # A wheel momentum of the opposite sign stops the run, naming the keyword that fixes
    # it; with that keyword the answer is the same.
    with pytest.raises(inertia.DataError, match=r"negate_rho=True"):
        inertia.estimate(tel.t, tel.q, -tel.rho, tau=tel.tau, w=tel.w)
    got = inertia.estimate(tel.t, tel.q, -tel.rho, tau=tel.tau, w=tel.w, negate_rho=True)
    np.testing.assert_array_equal(got.inertia, ref.inertia)
    # Conventions belong to reading: telemetry already read refuses them.
    with pytest.raises(ValueError, match="^scalar_first: these samples were already read"):
        inertia.estimate(tel, scalar_first=True)
    with pytest.raises(ValueError, match="^negate_rho: these samples were already read"):
        inertia.estimate(tel, negate_rho=True)


def test_read_csv_stats_and_lines(tmp_path, slew):
    tel, _ = slew
    p = tmp_path / "x.csv"
    rows = ["t,q_x,q_y,q_z,q_w,rho_x,rho_y,rho_z"]
    for k in range(50):
        q = tel.q[k] * (1 + 5e-4) * (-1 if k % 10 == 5 else 1)
        rows.append(",".join(repr(float(v)) for v in [tel.t[k], *q, *tel.rho[k]]))
    p.write_text("\n".join(rows) + "\n")
    r = inertia.read_csv(p)
    assert len(r) == 50 and r.w is None and r.file == str(p)
    assert r.stats["renormalised"] == 50 and r.stats["sign_flips"] == 10
    assert [int(x) for x in r.lines] == list(range(2, 52))
    np.testing.assert_allclose(np.linalg.norm(r.q, axis=1), 1.0, atol=1e-15)
    r2 = pickle.loads(pickle.dumps(r))
    assert r2.file == r.file and list(r2.lines) == list(r.lines) and r2.stats == r.stats
    with pytest.raises(OSError, match="cannot read"):
        inertia.read_csv(tmp_path / "absent.csv")


def test_conjugated_quaternions_and_gyro_degrees_are_named_and_read(slew):
    tel, _ = slew
    ref = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w)
    # Hamilton inertial → body quaternions: the error names the keyword that reads
    # them (not jpl, which has this library's numbers), and with it the answer is the
    # unconjugated data's, bit for bit.
    conj = tel.q * [-1, -1, -1, 1]
    with pytest.raises(inertia.DataError, match=r"conjugate=True") as err:
        inertia.estimate(tel.t, conj, tel.rho, tau=tel.tau, w=tel.w)
    assert "jpl" not in str(err.value)
    got = inertia.estimate(tel.t, conj, tel.rho, tau=tel.tau, w=tel.w, conjugate=True)
    np.testing.assert_array_equal(got.inertia, ref.inertia)
    assert got.status == ref.status
    # Gyro rates in deg/s: named, and read as deg/s they give the rad/s answer.
    deg = tel.w * (180.0 / np.pi)
    with pytest.raises(inertia.DataError, match=r'gyro_unit="deg/s"'):
        inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=deg)
    got = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=deg, gyro_unit="deg/s")
    np.testing.assert_allclose(got.inertia, ref.inertia, rtol=1e-9, atol=1e-12)
    with pytest.raises(ValueError, match="choose one"):
        inertia.estimate(tel.t, conj, tel.rho, jpl=True, conjugate=True)
    with pytest.raises(ValueError, match="gyro_unit"):
        inertia.estimate(tel.t, tel.q, tel.rho, w=deg, gyro_unit="rpm")


def test_warnings_are_the_reports_and_never_contradict_the_status():
    # The paper's J breaks J1 + J2 ≥ J3 by 4.9e-5 kg m²: beyond the discrete momentum
    # estimator's 3σ (a model check failed: the answer and σ shown, not determined, said
    # on the status line), within the variational estimator's (determined, with a
    # warning that says so).
    sim = inertia.simulate("slew", paper_inertia=True)
    np.testing.assert_array_equal(
        sim.inertia, inertia.simulate("slew", paper_inertia=True, seed=2).inertia
    )
    assert not np.array_equal(sim.inertia, inertia.simulate("slew").inertia)
    dm = inertia.estimate(sim.telemetry, constraints="positive-definite")
    assert dm.status == "model_check_failed"
    assert dm.inertia is not None and dm.sigma is not None
    assert dm.reason.startswith("not a physical inertia")
    assert not any("J1 + J2" in w for w in dm.warnings)
    v = inertia.estimate(sim.telemetry, estimator="variational", constraints="positive-definite")
    assert v.status == "determined"
    assert any("within 3 σ of a physical inertia" in w for w in v.warnings), v.warnings
    for e in (dm, v):
        assert e.warnings == [w["message"] for w in e.report["warnings"]]
        lines = [l.strip()[len("warning: "):] for l in e.text.splitlines() if l.strip().startswith("warning: ")]
        assert lines == e.warnings


def test_rotor_scale_sigma_widens_sigma_and_inertial_torque_is_a_setting(slew):
    """The wheels' stated scale uncertainty is a consider parameter: the same J, each
    element's σ √(σ² + (r ĵ)²); the inertial torque's modes are the library's names."""
    tel, _ = slew
    base = inertia.estimate(tel)
    r = 0.02
    wide = inertia.estimate(tel, rotor_scale_sigma=r)
    assert np.array_equal(wide.j, base.j)
    assert np.allclose(wide.sigma, np.sqrt(base.sigma**2 + (r * base.j) ** 2), rtol=1e-12)
    assert inertia.estimate(tel, inertial_torque="on").status == "determined"
    with pytest.raises(ValueError, match="inertial_torque"):
        inertia.estimate(tel, inertial_torque="sometimes")
    with pytest.raises(ValueError, match="rotor_scale_sigma"):
        inertia.estimate(tel, rotor_scale_sigma=1.5)


def test_wheel_delay_shifts_the_speeds_and_is_reported(slew):
    """The wheel speeds' time tag: off by default; given, the report says so; estimated
    on on-time data, it is near zero (within 3σ) and its σ widens each element's."""
    tel, _ = slew
    base = inertia.estimate(tel)
    assert base.report["wheel_delay"] is None
    given = inertia.estimate(tel, wheel_delay=0.01)
    assert given.report["wheel_delay"]["delay_s"] == 0.01
    assert not given.report["wheel_delay"]["estimated"]
    assert not np.array_equal(given.j, base.j)
    est = inertia.estimate(tel, wheel_delay="estimate")
    d = est.report["wheel_delay"]
    assert d["estimated"] and abs(d["delay_s"]) <= 3 * d["sigma_s"]
    assert np.all(est.sigma >= base.sigma * (1 - 1e-9))
    with pytest.raises(ValueError, match="wheel_delay"):
        inertia.estimate(tel, wheel_delay="late")
    with pytest.raises(TypeError, match="wheel_delay"):
        inertia.Estimator(wheel_delay=0.01)
    with pytest.raises(ValueError, match="whole record"):
        inertia._inertia.Stream(kwargs={"wheel_delay": 0.01})


def test_torque_scale_sigma_widens_the_final_answer_as_the_cli(tmp_path, cli):
    """A spacecraft whose wheels never move, excited by its thrusters: the known torque's
    stated σ is that share of J in the final answer, as the CLI's."""
    import json
    import subprocess

    (tmp_path / "zero.csv").write_text(
        "t_s,rho_dot_x_nm,rho_dot_y_nm,rho_dot_z_nm\n0,0,0,0\n300,0,0,0\n"
    )
    subprocess.run(
        [cli, "simulate", "--commands", tmp_path / "zero.csv", "--thrusters", "0.02",
         "-o", tmp_path / "f.csv"], check=True, capture_output=True,
    )
    est = inertia.estimate(tmp_path / "f.csv", torque_scale_sigma=0.05)
    term = np.array(est.report["torque_scale_sigma_kg_m2"])
    assert np.allclose(term, 0.05 * np.abs(est.j), rtol=0.02)
    out = subprocess.run(
        [cli, "estimate", tmp_path / "f.csv", "--json", "--torque-scale-sigma", "5%"],
        check=True, capture_output=True, text=True,
    )
    assert np.allclose(json.loads(out.stdout)["sigma"], est.sigma, rtol=1e-12)
    with pytest.raises(ValueError, match="torque_scale_sigma"):
        inertia.estimate(tmp_path / "f.csv", torque_scale_sigma=1.5)
