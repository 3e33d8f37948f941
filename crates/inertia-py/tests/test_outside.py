"""Outside measurements through Python: the arrays ``r``, ``b``, ``f``, ``dipole`` and the
DataFrame columns ``r_x`` … ``dipole_z`` give the CLI's report on the same file (the
gravity gradient modelled, a residual dipole and the centre of mass estimated with σ,
within 3σ of the simulated truth); ``outside={...}`` is ``--no-gravity-gradient`` & co.;
bad values are data errors naming the argument or column and the row."""

import pickle

import numpy as np
import pytest

import inertia
from conftest import cli_estimate, run_cli
from test_cli_agreement import TOL, differences

#: The simulated truths (`inertia simulate` options and their Python keywords).
FIELD_T = (2e-5, -1e-5, 2.5e-5)
DIPOLE_AM2 = (0.05, -0.03, 0.02)
CENTRE_OF_MASS_M = (0.02, -0.01, 0.015)


def colon(v):
    return ":".join(map(str, v))


#: name: (`inertia simulate` options, `inertia.simulate` keywords, the report's entry).
CASES = {
    "gravity": (["--gravity-gradient-altitude-km", "500"],
                dict(gravity_gradient_altitude_km=500.0), "gravity_gradient"),
    "magnetic": (["--magnetic-field-t", colon(FIELD_T), "--residual-dipole-am2", colon(DIPOLE_AM2)],
                 dict(magnetic_field_t=FIELD_T, residual_dipole_am2=DIPOLE_AM2), "residual_dipole_am2"),
    "thrusters": (["--thrusters", "0.02", "--centre-of-mass-m", colon(CENTRE_OF_MASS_M)],
                  dict(thrusters=0.02, centre_of_mass_m=CENTRE_OF_MASS_M), "centre_of_mass_m"),
}


@pytest.fixture(scope="module")
def outside_files(cli, tmp_path_factory):
    """`inertia simulate --scenario slew` with each outside effect: files with `r_*`,
    `b_*`, `f_*` columns."""
    d = tmp_path_factory.mktemp("outside")
    out = {}
    for name, (options, _, _) in CASES.items():
        f = d / f"{name}.csv"
        run_cli(cli, "simulate", "--scenario", "slew", *options, "-o", f)
        out[name] = f
    return out


def load(path):
    """A CSV file's columns by name, every number exactly as written."""
    with open(path) as fh:
        names = fh.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1)
    return {n: data[:, i] for i, n in enumerate(names)}


def block(c, prefix, axes="xyz"):
    names = [f"{prefix}_{a}" for a in axes]
    return np.column_stack([c[n] for n in names]) if names[0] in c else None


def arrays(c):
    """`estimate`'s positional and keyword arrays from a file's columns."""
    pos = (c["t"], block(c, "q", "xyzw"), block(c, "rho"))
    kw = {k: block(c, p) for k, p in
          (("tau", "tau"), ("w", "w"), ("r", "r"), ("b", "b"), ("f", "f"), ("dipole", "dipole"))}
    return pos, {k: v for k, v in kw.items() if v is not None}


def without_file(report):
    r = dict(report)
    r.pop("file")
    return r


def agree(expected, got):
    """The reports equal to TOL in every number, besides the input's name."""
    assert differences(without_file(expected), without_file(got)) <= TOL


@pytest.mark.parametrize("name", CASES)
def test_arrays_and_frame_give_the_files_report(cli, outside_files, name):
    """The file, its columns as arrays and as a DataFrame: the CLI's report, the same J
    and outside estimates, to 1e-12 relative."""
    pd = pytest.importorskip("pandas")
    path = outside_files[name]
    expected = cli_estimate(cli, path)
    by_file = inertia.estimate(str(path)).to_dict()
    assert differences(expected, by_file) <= TOL
    assert by_file["outside"] == expected["outside"]
    c = load(path)
    pos, kw = arrays(c)
    assert set(kw) == {"tau", "w", {"gravity": "r", "magnetic": "b", "thrusters": "f"}[name]}
    by_arrays = inertia.estimate(*pos, **kw)
    agree(expected, by_arrays.to_dict())
    by_frame = inertia.estimate(pd.DataFrame(c))
    agree(expected, by_frame.to_dict())
    for got in (by_arrays, by_frame):
        np.testing.assert_allclose(got.inertia, by_file["inertia"], rtol=TOL, atol=0)
    # The outside entry is there, and only the measured effect's.
    entry = CASES[name][2]
    out = by_arrays.report["outside"]
    assert (out["gravity_gradient"] is True) == (entry == "gravity_gradient")
    for key in ("residual_dipole_am2", "centre_of_mass_m"):
        assert (out[key] is not None) == (key == entry), (key, out)


@pytest.mark.parametrize(
    "name, key, truth",
    [("magnetic", "residual_dipole_am2", DIPOLE_AM2), ("thrusters", "centre_of_mass_m", CENTRE_OF_MASS_M)],
)
def test_outside_unknowns_within_three_sigma_of_the_truth(outside_files, name, key, truth):
    c = load(outside_files[name])
    pos, kw = arrays(c)
    got = inertia.estimate(*pos, **kw).report["outside"][key]
    value, sigma = np.array(got["value"]), np.array(got["sigma"])
    assert sigma.shape == (3,) and np.all(sigma > 0)
    assert np.all(np.abs(value - np.array(truth)) <= 3 * sigma), (value, sigma, truth)


@pytest.mark.parametrize(
    "name, flags, outside, dropped",
    [
        ("gravity", ["--no-gravity-gradient"], {"gravity_gradient": False}, "gravity_gradient"),
        ("gravity", ["--gravity-mu", "3.9e14"], {"gravity_mu_m3_s2": 3.9e14}, None),
        ("magnetic", ["--no-residual-dipole"], {"residual_dipole": False}, "residual_dipole_am2"),
        ("thrusters", ["--no-centre-of-mass"], {"centre_of_mass": False}, "centre_of_mass_m"),
    ],
    ids=["no-gravity-gradient", "gravity-mu", "no-residual-dipole", "no-centre-of-mass"],
)
def test_outside_setting_is_the_clis_flag(cli, outside_files, name, flags, outside, dropped):
    path = outside_files[name]
    expected = cli_estimate(cli, path, *flags)
    got = inertia.estimate(str(path), outside=outside).to_dict()
    assert differences(expected, got) <= TOL
    pos, kw = arrays(load(path))
    agree(expected, inertia.estimate(*pos, **kw, outside=outside).to_dict())
    if dropped is None:
        assert got["outside"]["gravity_gradient"] is True
    else:
        # Each file measures one effect: with its torque off, the report has no
        # `outside` entry at all.
        assert "outside" not in got, got["outside"]
    # The streaming estimator takes it too.
    s = inertia.Estimator(outside=outside)
    s.push_many(*pos, **kw)
    agree(got, s.estimate.to_dict())


def test_commanded_dipole(cli, outside_files, tmp_path):
    """A commanded dipole's torque m × B added to tau: the file with `dipole_*` columns,
    its arrays and its DataFrame give the CLI's report; the answer is the one with that
    torque in `tau_*` already, to rounding."""
    pd = pytest.importorskip("pandas")
    c = load(outside_files["magnetic"])
    t = c["t"]
    m = np.column_stack([0.5 * np.sin(2 * np.pi * t / p) for p in (50.0, 70.0, 90.0)])
    b = block(c, "b")
    tau = block(c, "tau") - np.cross(m, b)
    cols = dict(c)
    for k, a in enumerate("xyz"):
        cols[f"tau_{a}"] = tau[:, k]
        cols[f"dipole_{a}"] = m[:, k]
    path = tmp_path / "dipole.csv"
    names = list(cols)
    np.savetxt(path, np.column_stack([cols[n] for n in names]), delimiter=",", fmt="%.17g",
               header=",".join(names), comments="")
    expected = cli_estimate(cli, path)
    pos, kw = arrays(load(path))
    assert "dipole" in kw
    agree(expected, inertia.estimate(*pos, **kw).to_dict())
    agree(expected, inertia.estimate(pd.DataFrame(cols)).to_dict())
    # The commanded torque is in Telemetry.tau (the dipole itself is not kept).
    tel = inertia.Telemetry.from_arrays(*pos, **kw)
    np.testing.assert_allclose(tel.tau, block(c, "tau"), rtol=0, atol=1e-15)
    reference = cli_estimate(cli, outside_files["magnetic"])
    np.testing.assert_allclose(expected["inertia"], reference["inertia"], rtol=TOL)
    np.testing.assert_allclose(expected["outside"]["residual_dipole_am2"]["value"],
                               reference["outside"]["residual_dipole_am2"]["value"], rtol=TOL)


@pytest.mark.parametrize("name", CASES)
def test_python_simulation_has_the_files_columns(cli, outside_files, name):
    """`inertia.simulate` with the outside options: the CLI's samples and columns, and
    so its report."""
    sim = inertia.simulate("slew", **CASES[name][1])
    c = load(outside_files[name])
    tel = sim.telemetry
    for arg in ("r", "b", "f"):
        got, want = getattr(tel, arg), block(c, arg)
        if want is None:
            assert got is None, arg
        else:
            np.testing.assert_array_equal(got, want)
    if name == "gravity":
        np.testing.assert_array_equal(tel.r, sim.positions)
    agree(cli_estimate(cli, outside_files[name]), inertia.estimate(tel).to_dict())


def test_telemetry_keeps_the_measurements(outside_files):
    pd = pytest.importorskip("pandas")
    tel = inertia.read_csv(outside_files["thrusters"])
    assert tel.r is None and tel.b is None and tel.f.shape == (len(tel), 3)
    df = tel.to_dataframe()
    assert list(df.columns)[-3:] == ["f_x", "f_y", "f_z"]
    back = pickle.loads(pickle.dumps(tel))
    np.testing.assert_array_equal(back.f, tel.f)
    a, b = inertia.estimate(tel), inertia.estimate(back)
    np.testing.assert_array_equal(a.inertia, b.inertia)
    assert a.report["outside"] == b.report["outside"]
    # The frame holds the Telemetry's arrays (the quaternions renormalised once): the
    # same answer as those arrays.
    ref = inertia.estimate(tel.t, tel.q, tel.rho, tau=tel.tau, w=tel.w, f=tel.f)
    np.testing.assert_array_equal(inertia.estimate(df).inertia, ref.inertia)
    np.testing.assert_allclose(ref.inertia, a.inertia, rtol=1e-12, atol=0)


def test_streaming_equals_one_shot_with_outside(outside_files):
    pos, kw = arrays(load(outside_files["magnetic"]))
    one_shot = inertia.estimate(*pos, **kw)
    s = inertia.Estimator()
    for k in range(100):
        s.push(*(a[k] for a in pos), **{n: a[k] for n, a in kw.items()})
    s.push_many(*(a[100:] for a in pos), **{n: a[100:] for n, a in kw.items()})
    agree(one_shot.to_dict(), s.estimate.to_dict())


# ------------------------------------------------------------------------ bad input


@pytest.fixture(scope="module")
def magnetic(outside_files):
    return load(outside_files["magnetic"])


def test_nan_in_b_names_the_element_and_the_column(magnetic):
    pd = pytest.importorskip("pandas")
    pos, kw = arrays(magnetic)
    kw["b"][12, 1] = np.nan
    with pytest.raises(inertia.DataError, match=r"^b\[12, 1\]: value NaN is not finite$") as e:
        inertia.estimate(*pos, **kw)
    assert (e.value.kind, e.value.sample) == ("not_finite", 12)
    cols = dict(magnetic)
    cols["b_y"] = cols["b_y"].copy()
    cols["b_y"][12] = np.nan
    with pytest.raises(inertia.DataError, match=r"^row 12: column `b_y`: value NaN is not finite$"):
        inertia.estimate(pd.DataFrame(cols))
    # Out of range (|B| ≤ 1e-2 T), renamed column.
    cols = dict(magnetic)
    cols["mag_z"] = cols.pop("b_z") * 1e4
    with pytest.raises(inertia.DataError, match=r"^row 0: column `mag_z`: value 0\.2494.* is outside the supported range \(magnitude at most 0\.01 T\)$"):
        inertia.estimate(pd.DataFrame(cols), columns={"b_z": "mag_z"})


def test_dipole_without_b(magnetic):
    pd = pytest.importorskip("pandas")
    pos, kw = arrays(magnetic)
    kw["dipole"] = kw.pop("b")
    with pytest.raises(inertia.DataError, match=r"^dipole\[0\]: commanded dipoles \(dipole_x,dipole_y,dipole_z\) need the magnetic field") as e:
        inertia.estimate(*pos, **kw)
    assert (e.value.kind, e.value.sample) == ("columns", 0)
    cols = {k.replace("b_", "dipole_"): v for k, v in magnetic.items()}
    with pytest.raises(inertia.DataError, match=r"^row 0: column `dipole_x`: commanded dipoles"):
        inertia.estimate(pd.DataFrame(cols))


def test_positions_without_quaternions(outside_files):
    pd = pytest.importorskip("pandas")
    pos, kw = arrays(load(outside_files["gravity"]))
    message = r"positions \(r_x,r_y,r_z\) need the attitude in their inertial frame"
    with pytest.raises(inertia.DataError, match=rf"^r\[0\]: {message}") as e:
        inertia.estimate(pos[0], None, pos[2], **kw)
    assert (e.value.kind, e.value.sample) == ("columns", 0)
    cols = {k: v for k, v in load(outside_files["gravity"]).items() if not k.startswith("q_")}
    with pytest.raises(inertia.DataError, match=rf"^row 0: column `r_x`: {message}"):
        inertia.estimate(pd.DataFrame(cols))


def test_measurement_given_for_some_samples_only(magnetic):
    pos, kw = arrays(magnetic)
    s = inertia.Estimator()
    s.push(*(a[0] for a in pos), **{n: a[0] for n, a in kw.items()})
    kw.pop("b")
    with pytest.raises(inertia.DataError, match=r"^b\[1\]: magnetic fields \(b_x,b_y,b_z\) missing here but given for the earlier samples") as e:
        s.push(*(a[1] for a in pos), **{n: a[1] for n, a in kw.items()})
    assert (e.value.kind, e.value.sample) == ("columns", 1)
    assert s.samples == 1


def test_shapes_and_frame_columns(magnetic):
    pd = pytest.importorskip("pandas")
    pos, kw = arrays(magnetic)
    for name, bad in (("r", kw["b"][:, :2]), ("b", kw["b"][:-1]), ("f", kw["b"].T), ("dipole", kw["b"][:, :1])):
        with pytest.raises(ValueError, match=rf"^{name}: expected shape \(N, 3\)"):
            inertia.estimate(*pos, **{**kw, name: bad})
    with pytest.raises(TypeError, match=r"^f: expected an array of numbers"):
        inertia.estimate(*pos, **kw, f=np.full((len(pos[0]), 3), "a"))
    with pytest.raises(inertia.DataError, match=r"missing column `b_z`"):
        inertia.estimate(pd.DataFrame(magnetic).drop(columns=["b_z"]))
    with pytest.raises(TypeError, match="only with arrays"):
        inertia.estimate(pd.DataFrame(magnetic), b=kw["b"])


@pytest.mark.parametrize(
    "outside, exc, message",
    [
        ({"gravity": False}, ValueError, 'outside: unknown key "gravity" (known: gravity_gradient, gravity_mu_m3_s2, residual_dipole, centre_of_mass)'),
        ({"residual_dipole": "no"}, TypeError, 'outside["residual_dipole"]: expected True or False, got str'),
        ({"gravity_mu_m3_s2": -1.0}, ValueError, 'outside["gravity_mu_m3_s2"]=-1: expected'),
        (True, TypeError, "outside: expected a dict, got bool"),
    ],
)
def test_bad_outside_settings_name_the_key(magnetic, outside, exc, message):
    pos, kw = arrays(magnetic)
    with pytest.raises(exc) as e:
        inertia.estimate(*pos, **kw, outside=outside)
    assert message in str(e.value), str(e.value)


def test_simulate_outside_options_are_checked():
    with pytest.raises(ValueError, match=r"^the magnetic options need a field: gravity_gradient_altitude_km"):
        inertia.simulate("slew", residual_dipole_am2=DIPOLE_AM2)
    with pytest.raises(ValueError, match=r"^centre_of_mass_m: needs thrusters$"):
        inertia.simulate("slew", centre_of_mass_m=CENTRE_OF_MASS_M)
    with pytest.raises(ValueError, match=r"^magnetic_field_t: simulation setting `environment\.magnetic\.field`"):
        inertia.simulate("slew", magnetic_field_t=(1.0, 0.0, 0.0))
    with pytest.raises(ValueError, match=r"^thrusters: simulation setting"):
        inertia.simulate("slew", thrusters=-1.0)


#: Three unit thrusters at the origin along the body axes: their throttles are the force's
#: components and their torque about the origin is zero.
UNIT_THRUSTERS = "".join(
    f'[[thruster]]\nname = "t{a}"\nposition_m = [0.0, 0.0, 0.0]\ndirection = {d}\n'
    f'thrust_n = 1.0\ncolumn = "t_{a}"\n\n'
    for a, d in (("x", "[1.0, 0.0, 0.0]"), ("y", "[0.0, 1.0, 0.0]"), ("z", "[0.0, 0.0, 1.0]"))
)


def with_throttles(src, tmp_path):
    """The thrusters file `src` with its force columns as the throttles of
    `UNIT_THRUSTERS` (written beside it): the file, the spacecraft file, the columns."""
    c = load(src)
    names = [n for n in c if not n.startswith("f_")]
    data = np.column_stack([c[n] for n in names] + [c[f"f_{a}"] for a in "xyz"])
    path = tmp_path / "throttles.csv"
    np.savetxt(path, data, delimiter=",", header=",".join(names + ["t_x", "t_y", "t_z"]),
               comments="", fmt="%.17g")
    sc = tmp_path / "thrusters.toml"
    sc.write_text(UNIT_THRUSTERS)
    return path, sc, c


def test_spacecraft_thrusters_give_the_files_force(cli, outside_files, tmp_path):
    """A spacecraft file's thrusters with throttle columns (`read_csv(spacecraft=…)`):
    the same report as the force columns they replace, by Python and by the CLI, and the
    Telemetry's force is the file's."""
    src = outside_files["thrusters"]
    path, sc, c = with_throttles(src, tmp_path)
    expected = inertia.estimate(str(src)).to_dict()
    got = inertia.estimate(str(path), spacecraft=str(sc)).to_dict()
    agree(expected, got)
    assert got["outside"]["centre_of_mass_m"] == expected["outside"]["centre_of_mass_m"]
    agree(expected, cli_estimate(cli, path, "--spacecraft", sc))
    t = inertia.read_csv(str(path), spacecraft=str(sc))
    np.testing.assert_array_equal(t.f, block(c, "f"))


def test_a_thruster_telemetry_survives_pickling(outside_files, tmp_path):
    """`read_csv(spacecraft=…)` with thrusters, pickled and restored: the same estimate."""
    src = outside_files["thrusters"]
    path, sc, c = with_throttles(src, tmp_path)
    t = inertia.read_csv(str(path), spacecraft=str(sc))
    back = pickle.loads(pickle.dumps(t))
    np.testing.assert_array_equal(back.f, t.f)
    agree(inertia.estimate(t).to_dict(), inertia.estimate(back).to_dict())
