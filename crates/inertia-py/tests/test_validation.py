"""Shapes, types, values and settings: errors name the argument (or file, line and
column) as the command line does."""

import numpy as np
import pytest

import inertia


@pytest.fixture(scope="module")
def tel():
    return inertia.simulate("slew", duration=60).telemetry


def arrays(tel):
    return [tel.t.copy(), tel.q.copy(), tel.rho.copy()], dict(tau=tel.tau.copy(), w=tel.w.copy())


@pytest.mark.parametrize(
    "name, bad, message",
    [
        ("t", lambda a: a.reshape(-1, 1), "t: expected a 1-D array"),
        ("q", lambda a: a[:, :3], "q: expected shape (N, 4)"),
        ("q", lambda a: a[:-1], "q: expected shape (N, 4) = ("),
        ("rho", lambda a: a[:, :2], "rho: expected shape (N, 3)"),
        ("tau", lambda a: a.T, "tau: expected shape (N, 3)"),
        ("w", lambda a: a[:, :1], "w: expected shape (N, 3)"),
    ],
)
def test_shapes_name_the_argument(tel, name, bad, message):
    pos, kw = arrays(tel)
    names = ["t", "q", "rho"]
    if name in names:
        pos[names.index(name)] = bad(pos[names.index(name)])
    else:
        kw[name] = bad(kw[name])
    with pytest.raises(ValueError) as e:
        inertia.estimate(*pos, **kw)
    assert message in str(e.value)


def test_types_name_the_argument(tel):
    pos, kw = arrays(tel)
    with pytest.raises(TypeError, match="^q: expected an array of numbers"):
        inertia.estimate(pos[0], np.full((len(pos[0]), 4), "a"), pos[2])
    with pytest.raises(TypeError, match="^rho: expected an array of numbers"):
        inertia.estimate(pos[0], pos[1], object())
    with pytest.raises(TypeError, match="rho is required with an array t"):
        inertia.estimate(pos[0])
    with pytest.raises(TypeError, match="and q unless w is given"):
        inertia.estimate(pos[0], None, pos[2])
    with pytest.raises(TypeError, match="memory: expected a number"):
        inertia.estimate(*pos, **kw, memory="long")
    with pytest.raises(TypeError, match="every: expected an integer"):
        inertia.estimate(*pos, **kw, every=1.5)


@pytest.mark.parametrize(
    "mutate, message",
    [
        (lambda p, k: p[1].__setitem__((5, 2), np.nan), r"^q\[5, 2\]: value NaN is not finite$"),
        (lambda p, k: p[1].__setitem__((3, 0), 0.5), r"^q\[3\]: quaternion norm 1\.1\d+ differs from 1 by more than 1e-3$"),
        (lambda p, k: p[0].__setitem__(4, p[0][3]), r"^t\[4\]: time 0\.3 s does not increase \(previous row: 0\.3 s\)$"),
        (lambda p, k: p[2].__setitem__((2, 1), 1e15), r"^rho\[2, 1\]: value 1e15 is outside the supported range \(magnitude at most 1000000 N m s\)$"),
        (lambda p, k: k["w"].__setitem__((7, 0), 1e3), r"^w\[7, 0\]: value 1000 is outside the supported range \(magnitude at most 100 rad/s\)$"),
        (lambda p, k: k["tau"].__setitem__((9, 2), np.inf), r"^tau\[9, 2\]: value inf is not finite$"),
    ],
)
def test_bad_values_are_data_errors(tel, mutate, message):
    pos, kw = arrays(tel)
    mutate(pos, kw)
    with pytest.raises(inertia.DataError, match=message) as e:
        inertia.estimate(*pos, **kw)
    assert isinstance(e.value, ValueError)
    assert e.value.line is None


@pytest.mark.parametrize(
    "settings, exc, message",
    [
        (dict(estimator="nope"), ValueError, "estimator: unknown estimator `nope` (known: "),
        (dict(solver="nope"), ValueError, "solver: unknown solver `nope`"),
        (dict(memory=-1.0), ValueError, "memory=-1: expected a finite memory > 0 s"),
        (dict(memory=0.01), ValueError, "the memory 0.01 s is shorter than the sample period 0.1 s; the memory must span several samples (sample 1) (keyword: memory)"),
        (dict(resample=0.0001), ValueError, "resampling to 0.0001 s would make 1000 samples of the step of 0.1 s (at most 100) (keyword: resample)"),
        (dict(every=0), ValueError, "every=0: expected at least 1"),
        (dict(constraints="loose"), ValueError, 'constraints="loose": expected one of physical, paper, positive-definite'),
        (dict(rho_model="cubic"), ValueError, 'rho_model="cubic": expected one of'),
        (dict(rotation_source="star"), ValueError, 'rotation_source="star"'),
        (dict(glitches="ignore"), ValueError, 'glitches="ignore"'),
        (dict(bounds="J44=1:2"), ValueError, 'bounds "J44=1:2": unknown element'),
        (dict(bounds={"J33": (None, None)}), ValueError, 'bounds["J33"]: no bound given'),
        (dict(bounds={"J33": (3.3, 2.7)}), ValueError, "constraints"),
        (dict(bounds=3), TypeError, "bounds: expected a dict"),
        (dict(nominal=np.eye(3)), ValueError, "nominal: needs tolerance"),
        (dict(nominal=np.eye(3) + np.triu(np.ones((3, 3)), 1), tolerance=0.1), ValueError, "nominal: is not symmetric"),
        (dict(tolerance="ten"), ValueError, 'tolerance="ten"'),
        (dict(estimator="momentum", gyro_noise=1e-5), ValueError, "gyro_noise does not apply to the momentum estimator"),
        (dict(estimator="variational", chain=10.0), ValueError, "chain does not apply to the variational estimator"),
        (dict(attitude_drift=6e-4), ValueError, "attitude_drift needs gyro_noise > 0"),
        (dict(attitude_drift=6e-4, gyro_noise=1e-5, uncertainty=False), ValueError, "attitude_drift needs uncertainty on"),
        (dict(attitude_drift=6e-4, gyro_noise=1e-5, batch=True), ValueError, "batch=True: setting `attitude_drift_deg_rth` does not apply to the discrete-momentum batch estimator"),
        (dict(scalar_first=True, jpl=True), ValueError, "scalar_first, jpl and conjugate: choose one"),
        (dict(unit_tolerance=0.0), ValueError, "unit_tolerance=0: must be finite and > 0"),
        (dict(batch=True, memory=30.0), ValueError, "batch=True: setting `memory_s` does not apply to the batch estimator"),
        (dict(truth=np.eye(2)), ValueError, "truth: expected a 3×3 matrix"),
    ],
)
def test_bad_settings_name_the_argument(tel, settings, exc, message):
    pos, kw = arrays(tel)
    with pytest.raises(exc) as e:
        inertia.estimate(*pos, **kw, **settings)
    assert message in str(e.value), str(e.value)


def test_unknown_keyword_is_a_type_error(tel):
    with pytest.raises(TypeError):
        inertia.estimate(tel, memroy=30)
    with pytest.raises(TypeError, match="simulate\\(\\) got an unexpected keyword argument 'seeed'"):
        inertia.simulate("slew", seeed=3)


def test_estimators_that_need_rates(tel):
    pos, _ = arrays(tel)
    with pytest.raises(ValueError, match="^w: the momentum estimator needs gyro rates"):
        inertia.estimate(*pos, estimator="momentum")


def test_too_few_samples(tel):
    pos, kw = arrays(tel)
    with pytest.raises(inertia.DataError, match="too few samples for an estimate: the discrete-momentum estimator needs at least 4, got 3"):
        inertia.estimate(*(a[:3] for a in pos), tau=kw["tau"][:3], w=kw["w"][:3])


def test_simulate_arguments():
    with pytest.raises(ValueError, match="scenario or preset: one is required"):
        inertia.simulate()
    with pytest.raises(ValueError, match='scenario="tumble": expected one of slew, spin'):
        inertia.simulate("tumble")
    with pytest.raises(ValueError, match="duration=-1: must be finite and > 0"):
        inertia.simulate("slew", duration=-1)
    with pytest.raises(ValueError, match="telemetry_dt=0.15: must be a whole multiple"):
        inertia.simulate("slew", telemetry_dt=0.15)
    with pytest.raises(ValueError, match="constant_torque_nm: expected 3 numbers, got 2"):
        inertia.simulate("slew", constant_torque_nm=(1e-5, 0))


def test_the_native_mapping_is_the_librarys_description(tel):
    """The keywords are the library's run description's keys (every one is a keyword of
    :func:`inertia.estimate`), and the native side maps a dict onto it generically: an
    unknown keyword is a TypeError naming it, a value of the wrong type a TypeError, a bad
    value a ValueError, each naming the keyword."""
    import inspect

    names = set(inspect.signature(inertia.estimate).parameters)
    assert set(inertia._inertia.SETTINGS_KEYS) | set(inertia._inertia.INPUT_KEYS) <= names
    with pytest.raises(TypeError, match=r"^Estimator\(\) got an unexpected keyword argument 'memroy'$"):
        inertia._inertia.Stream(kwargs={"memroy": 30.0})
    with pytest.raises(TypeError, match=r"^read_csv\(\) got an unexpected keyword argument 'memory'$"):
        inertia._inertia.read_csv("x.csv", kwargs={"memory": 30.0})
    with pytest.raises(TypeError, match=r"^chain: expected a number, got str$"):
        inertia._inertia.Stream(kwargs={"chain": "long"})
    with pytest.raises(ValueError, match=r'^glitches="ignore": expected one of stop, keep$'):
        inertia._inertia.Stream(kwargs={"glitches": "ignore"})
    # None is the default, as for a keyword not given.
    assert inertia._inertia.Stream(kwargs={"memory": None, "rho_model": None}) is not None
