"""The bad-input table (tests/data/bad_inputs.json) through Python's arrays: the error's
``.kind`` and ``.sample`` are the table's, as the CLI's JSON error and C's
``inertia_last_error_kind`` give them (crates/inertia-cli/tests/cli/bad_inputs.rs,
crates/inertia-c/tests/c_api/bad_inputs.rs)."""

import json
import math
import pathlib

import numpy as np
import pytest

import inertia

TABLE = json.loads(
    (pathlib.Path(__file__).resolve().parents[3] / "tests" / "data" / "bad_inputs.json").read_text()
)


def number(v):
    return {"nan": math.nan, "inf": math.inf, "-inf": -math.inf}[v] if isinstance(v, str) else float(v)


def rows(case):
    base = TABLE["base"]
    n = case.get("n", base["n"])
    dt, rate = base["dt_s"], base["rate_rad_s"]
    k = np.arange(n, dtype=float)
    t = k * dt
    half = rate * t / 2.0
    q = np.stack([np.zeros(n), np.zeros(n), np.sin(half), np.cos(half)], axis=1)
    rho = np.stack([0.1 + 0.001 * k, np.full(n, 0.2), np.full(n, 0.3)], axis=1)
    tau = np.zeros((n, 3))
    w = np.tile([0.0, 0.0, rate], (n, 1))
    arrays = {"t": t, "q": q, "rho": rho, "tau": tau, "w": w}
    for s in case.get("set", []):
        a = arrays[s["field"]]
        if a.ndim == 1:
            a[s["sample"]] = number(s["value"])
        else:
            a[s["sample"], s.get("component", 0)] = number(s["value"])
    return arrays


@pytest.mark.parametrize("case", TABLE["cases"], ids=[c["name"] for c in TABLE["cases"]])
def test_python_refuses_the_tables_inputs_with_its_kinds(case):
    a = rows(case)
    kwargs = {} if "memory_s" not in case else {"memory": case["memory_s"]}
    with pytest.raises(ValueError) as info:
        if "w_absent_from" in case:
            # Gyro rates per sample: the streaming estimator.
            est = inertia.Estimator(**kwargs)
            for i in range(len(a["t"])):
                w = a["w"][i] if i < case["w_absent_from"] else None
                est.push(a["t"][i], a["q"][i], a["rho"][i], tau=a["tau"][i], w=w)
        else:
            inertia.estimate(a["t"], a["q"], a["rho"], tau=a["tau"], w=a["w"], **kwargs)
    e = info.value
    assert e.kind == case["kind"], (case["name"], str(e))
    assert e.sample == case["sample"], (case["name"], str(e))
