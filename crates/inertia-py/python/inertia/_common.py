"""Constants and argument conversions shared by the package's modules."""

from __future__ import annotations

import re
from typing import Any, Dict, List, Mapping, Optional, Sequence, Tuple

import numpy as np

from . import _inertia
from ._inertia import DataError


#: The estimator ``inertia estimate`` runs by default (the discrete momentum estimator).
DEFAULT_ESTIMATOR: str = _inertia.DEFAULT_ESTIMATOR

#: Columns of an estimate history (the CLI's ``-o`` CSV, schema version 1).
HISTORY_COLUMNS: Tuple[str, ...] = (
    "t", "J11", "J22", "J33", "J12", "J13", "J23", "status", "condition", "iterations",
    "sJ11", "sJ22", "sJ33", "sJ12", "sJ13", "sJ23", "reason",
)

#: The CSV column names, in the order t, q (4), rho (3), tau (3), w (3).
CSV_COLUMNS: Tuple[str, ...] = (
    "t", "q_x", "q_y", "q_z", "q_w", "rho_x", "rho_y", "rho_z",
    "tau_x", "tau_y", "tau_z", "w_x", "w_y", "w_z",
)

#: The optional columns of outside measurements, in the order r (inertial position, m),
#: b (magnetic field, T, body axes), f (external force, N, body axes), dipole (commanded
#: magnetic dipole, A m², body axes): the arguments ``r``, ``b``, ``f``, ``dipole``.
OUTSIDE_COLUMNS: Tuple[str, ...] = (
    "r_x", "r_y", "r_z", "b_x", "b_y", "b_z", "f_x", "f_y", "f_z",
    "dipole_x", "dipole_y", "dipole_z",
)


def _pandas(what: str):
    try:
        import pandas
    except ImportError as e:  # pragma: no cover - exercised without pandas only
        raise ImportError(
            f"{what} needs pandas, which is not installed: pip install pandas"
        ) from e
    return pandas


def _array(v: Any) -> Optional[np.ndarray]:
    return None if v is None else np.array(v, dtype=np.float64)


def _float_array(name: str, x: Any, shape: str) -> np.ndarray:
    try:
        a = np.asarray(x)
    except Exception as e:  # noqa: BLE001 - anything numpy cannot take
        raise TypeError(f"{name}: expected an array of numbers {shape}, got {type(x).__name__}") from e
    if a.dtype.kind not in "iuf":
        raise TypeError(
            f"{name}: expected an array of numbers {shape}, got an array of dtype {a.dtype}"
        )
    return np.ascontiguousarray(a, dtype=np.float64)


def _arrays(t, q, rho, tau, w, r=None, b=None, f=None, dipole=None):
    def optional(name: str, x: Any) -> Optional[np.ndarray]:
        return None if x is None else _float_array(name, x, "(N, 3)")

    return (
        _float_array("t", t, "(N,)"),
        None if q is None else _float_array("q", q, "(N, 4)"),
        _float_array("rho", rho, "(N, 3)"),
        optional("tau", tau),
        optional("w", w),
        optional("r", r),
        optional("b", b),
        optional("f", f),
        optional("dipole", dipole),
    )


def _is_frame(x: Any) -> bool:
    return hasattr(x, "columns") and hasattr(x, "iloc")


def _frame_arrays(df: Any, columns: Optional[Mapping[str, str]]):
    known = CSV_COLUMNS + OUTSIDE_COLUMNS
    names = list(known)
    for k, v in (columns or {}).items():
        if k not in known:
            raise ValueError(
                f"columns: unknown column {k!r} (known: t, q_x, q_y, q_z, q_w, rho_*, tau_*, "
                "w_*, r_*, b_*, f_*, dipole_*)"
            )
        names[known.index(k)] = v
    present = [str(c) for c in df.columns]
    if len(set(present)) != len(present):
        dup = next(c for c in present if present.count(c) > 1)
        raise DataError(f"<DataFrame>: column `{dup}` appears twice")

    def need(n: str) -> np.ndarray:
        if n not in present:
            raise DataError(f"<DataFrame>: missing column `{n}` (columns present: {','.join(present)})")
        return df[n].to_numpy()

    def optional(block: List[str]) -> Optional[np.ndarray]:
        if not any(n in present for n in block):
            return None
        return np.column_stack([_float_array(n, need(n), "(N,)") for n in block])

    need(names[0])
    t = df[names[0]]
    if str(t.dtype).startswith("datetime64"):
        # Elapsed seconds since the first row (pandas' datetimes have no leap seconds).
        t = (t - t.iloc[0]).dt.total_seconds()
    t = _float_array(names[0], t.to_numpy(), "(N,)")
    # No quaternion column at all (none renamed, none that looks like one) and every gyro
    # column: the attitude is integrated from the gyro rates, as for such a CSV file.
    looks_like_q = any(re.fullmatch(r"(q|quat|quaternion)[_ ]?([0-3]|[xyzws]|scalar)", c.lower()) for c in present)
    gyro_only = (
        not any(n in present for n in names[1:5])
        and names[1:5] == list(CSV_COLUMNS[1:5])
        and all(n in present for n in names[11:14])
        and not looks_like_q
    )
    q = None if gyro_only else np.column_stack([_float_array(n, need(n), "(N,)") for n in names[1:5]])
    rho = np.column_stack([_float_array(n, need(n), "(N,)") for n in names[5:8]])
    blocks = [optional(names[k:k + 3]) for k in range(8, len(names), 3)]
    return names, (t, q, rho, *blocks)


#: The estimation settings and the input conventions, as :func:`estimate` and
#: :class:`Estimator` name them: the library's run description's keys (the command line's
#: options, in snake case; ``inertia estimate --settings`` reads the same keys from a
#: file). The native side maps them onto the description generically.
_SETTINGS = tuple(_inertia.SETTINGS_KEYS)
#: How the data are read (``columns`` and ``spacecraft`` go to :func:`read_csv` apart).
_CONVENTIONS = tuple(k for k in _inertia.INPUT_KEYS if k not in ("columns", "spacecraft"))


def _settings(arguments: Mapping[str, Any], names: Sequence[str] = _SETTINGS) -> Dict[str, Any]:
    """The named arguments a function has, with matrices as nested lists for the native
    side."""
    kw = {k: arguments[k] for k in names if k in arguments}
    for key in ("nominal", "truth", "prior"):
        if kw.get(key) is not None:
            kw[key] = _float_array(key, kw[key], "(3, 3)").tolist()
    sigma = kw.get("prior_sigma")
    if sigma is not None and not isinstance(sigma, (str, int, float)):
        kw["prior_sigma"] = _float_array("prior_sigma", sigma, "(3, 3)").tolist()
    return kw
