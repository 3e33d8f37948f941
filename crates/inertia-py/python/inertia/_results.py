"""The result of an estimation run (:class:`Estimate`)."""

from __future__ import annotations

import dataclasses
import json
from typing import Any, Dict, List, Optional, Tuple

import numpy as np

from ._common import HISTORY_COLUMNS, _array, _pandas


@dataclasses.dataclass(frozen=True, eq=False)
class Estimate:
    """The result of an estimation run: the command line's report.

    Attributes:
        inertia: J, kg m², 3×3 (``None`` when the data cannot determine J).
        j: ``[J11, J22, J33, J12, J13, J23]``, kg m² (products are tensor entries,
            ``J12 = −Σ m x y``).
        sigma: one standard deviation of each element of ``j``, kg m² (noise,
            discretisation bias and, when ``rotor_scale_sigma`` or ``torque_scale_sigma``
            was given, the wheels' or the known torque's scale:
            ``report["rotor_scale_sigma_kg_m2"]``, ``report["torque_scale_sigma_kg_m2"]``),
            or ``None`` for estimators without an uncertainty model.
        status: ``"determined"``, ``"from_prior"``, ``"not_observable"``,
            ``"unchecked"`` (no observability test, or no σ) or ``"model_check_failed"``
            (an answer with its σ that breaks J1 > 0 or J1 + J2 ≥ J3 beyond 3σ).
        reason: why the data fall short, when they do (else ``None``).
        condition: σ₁/σ₆ of the information factor R when determined.
        principal_moments: ascending, kg m² (3,).
        principal_moments_sigma: their standard deviations, kg m² (3,).
        principal_axes: the principal axes as columns, body axes (3×3).
        t: time of the estimate, s.
        samples: samples the estimator saw (after resampling).
        estimator: the estimator's name.
        relative_error: ‖J − J_true‖_F/‖J_true‖_F when ``truth=`` was given.
        torque_bias_nm: estimated constant body-frame disturbance torque, N m (3,);
            ``None`` where it is not estimated or the data gave no evidence of one and it
            was held at zero (``report["torque_test"]``: ``chi2``, ``held_at_zero``).
            The torques of outside measurements (``r``, ``b``, ``f``) are reported in
            ``report["outside"]``: ``gravity_gradient`` (whether modelled),
            ``residual_dipole_am2`` (A m²) and ``centre_of_mass_m`` (m), each
            ``{"value": [3], "sigma": [3] or None}`` or ``None``; the report has no
            ``outside`` key where none of them is modelled.
        warnings: every ``warning:`` line of the text report (the JSON's ``warnings``
            messages), none of which contradicts ``status``.
        report: the whole report as a dict (the ``inertia estimate --json`` schema).
        text: the readable report (``inertia estimate`` without ``--json``).

    With ``history=True`` the estimate history is ``.history`` (a pandas DataFrame with
    :data:`HISTORY_COLUMNS`; pandas is needed only then). Estimates pickle.
    """

    inertia: Optional[np.ndarray]
    j: Optional[np.ndarray]
    sigma: Optional[np.ndarray]
    status: str
    reason: Optional[str]
    condition: Optional[float]
    principal_moments: Optional[np.ndarray]
    principal_moments_sigma: Optional[np.ndarray]
    principal_axes: Optional[np.ndarray]
    t: float
    samples: int
    estimator: str
    relative_error: Optional[float]
    torque_bias_nm: Optional[np.ndarray]
    warnings: List[str]
    report: Dict[str, Any] = dataclasses.field(repr=False)
    text: str = dataclasses.field(repr=False)
    history_columns: Optional[Dict[str, Any]] = dataclasses.field(default=None, repr=False)

    @classmethod
    def _from_native(cls, native: Tuple[str, str, Optional[Dict[str, Any]]]) -> "Estimate":
        report_json, text, history = native
        r = json.loads(report_json)
        return cls(
            inertia=_array(r["inertia"]),
            j=_array(r["j"]),
            sigma=_array(r["sigma"]),
            status=r["status"],
            reason=r["reason"],
            condition=r["condition"],
            principal_moments=_array(r["principal_moments"]),
            principal_moments_sigma=_array(r["principal_moments_sigma"]),
            principal_axes=_array(r["principal_axes"]),
            t=r["t"],
            samples=r["samples"],
            estimator=r["estimator"],
            relative_error=r["relative_error"],
            torque_bias_nm=_array(r["torque_bias_nm"]),
            warnings=[w["message"] for w in r["warnings"]],
            report=r,
            text=text,
            history_columns=history,
        )

    @property
    def determined(self) -> bool:
        """``True`` when the data determine J (status ``"determined"``)."""
        return self.status == "determined"

    @property
    def history(self):
        """The estimate history as a pandas DataFrame (``history=True`` runs only).

        Columns :data:`HISTORY_COLUMNS`: ``t`` s; ``J..`` and ``sJ..`` kg m² (NaN where
        not available); ``status``; ``condition``; ``iterations``; ``reason``.
        """
        if self.history_columns is None:
            raise ValueError("no history: estimate with history=True")
        pd = _pandas("Estimate.history")
        return pd.DataFrame({c: self.history_columns[c] for c in HISTORY_COLUMNS})

    def to_dict(self) -> Dict[str, Any]:
        """The report as a JSON-compatible dict: the ``inertia estimate --json`` object."""
        return json.loads(json.dumps(self.report))

    def __str__(self) -> str:
        return self.text
