"""Type stubs of the ``inertia`` package (units: SI; see the module docstring)."""

import os
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

__version__: str
DEFAULT_ESTIMATOR: str
HISTORY_COLUMNS: Tuple[str, ...]
CSV_COLUMNS: Tuple[str, ...]
OUTSIDE_COLUMNS: Tuple[str, ...]

ArrayLike = npt.ArrayLike
Bounds = Union[None, str, Sequence[str], Mapping[str, Tuple[Optional[float], Optional[float]]]]

class DataError(ValueError):
    """Bad input data; the message is the command line's."""

    line: Optional[int]

def estimators() -> List[Tuple[str, str]]: ...

class Estimate:
    inertia: Optional[np.ndarray]  # (3, 3) kg m²
    j: Optional[np.ndarray]  # (6,) kg m²: J11, J22, J33, J12, J13, J23
    sigma: Optional[np.ndarray]  # (6,) kg m²
    status: str
    reason: Optional[str]
    condition: Optional[float]
    principal_moments: Optional[np.ndarray]  # (3,) kg m², ascending
    principal_moments_sigma: Optional[np.ndarray]  # (3,) kg m²
    principal_axes: Optional[np.ndarray]  # (3, 3), columns, body axes
    t: float  # s
    samples: int
    estimator: str
    relative_error: Optional[float]
    torque_bias_nm: Optional[np.ndarray]  # (3,) N m
    warnings: List[str]
    report: Dict[str, Any]
    text: str
    history_columns: Optional[Dict[str, Any]]
    @property
    def determined(self) -> bool: ...
    @property
    def history(self) -> Any: ...  # pandas.DataFrame
    def to_dict(self) -> Dict[str, Any]: ...

class Telemetry:
    @classmethod
    def from_arrays(
        cls,
        t: ArrayLike,
        q: ArrayLike,
        rho: ArrayLike,
        tau: Optional[ArrayLike] = ...,
        w: Optional[ArrayLike] = ...,
        r: Optional[ArrayLike] = ...,
        b: Optional[ArrayLike] = ...,
        f: Optional[ArrayLike] = ...,
        dipole: Optional[ArrayLike] = ...,
        *,
        scalar_first: bool = ...,
        jpl: bool = ...,
        conjugate: bool = ...,
        gyro_unit: Optional[str] = ...,
        negate_rho: bool = ...,
        unit_tolerance: Optional[float] = ...,
        period_tolerance: Optional[float] = ...,
    ) -> Telemetry: ...
    @property
    def t(self) -> np.ndarray: ...  # (N,) s
    @property
    def q(self) -> np.ndarray: ...  # (N, 4) [x, y, z, w], Hamilton, body → inertial
    @property
    def rho(self) -> np.ndarray: ...  # (N, 3) N m s
    @property
    def tau(self) -> np.ndarray: ...  # (N, 3) N m
    @property
    def w(self) -> Optional[np.ndarray]: ...  # (N, 3) rad/s
    @property
    def r(self) -> Optional[np.ndarray]: ...  # (N, 3) m, inertial position
    @property
    def b(self) -> Optional[np.ndarray]: ...  # (N, 3) T, magnetic field
    @property
    def f(self) -> Optional[np.ndarray]: ...  # (N, 3) N, external force
    @property
    def file(self) -> Optional[str]: ...
    @property
    def lines(self) -> Optional[np.ndarray]: ...
    @property
    def stats(self) -> Dict[str, Any]: ...
    def __len__(self) -> int: ...
    def to_dataframe(self) -> Any: ...  # pandas.DataFrame

def read_csv(
    path: Union[str, os.PathLike[str]],
    *,
    scalar_first: bool = ...,
    jpl: bool = ...,
    conjugate: bool = ...,
    gyro_unit: Optional[str] = ...,
    negate_rho: bool = ...,
    columns: Optional[Mapping[str, str]] = ...,
    unit_tolerance: Optional[float] = ...,
    period_tolerance: Optional[float] = ...,
    spacecraft: Union[None, str, os.PathLike[str]] = ...,
) -> Telemetry: ...

def estimate(
    t: Any,
    q: Optional[ArrayLike] = ...,
    rho: Optional[ArrayLike] = ...,
    *,
    tau: Optional[ArrayLike] = ...,
    w: Optional[ArrayLike] = ...,
    r: Optional[ArrayLike] = ...,
    b: Optional[ArrayLike] = ...,
    f: Optional[ArrayLike] = ...,
    dipole: Optional[ArrayLike] = ...,
    estimator: str = ...,
    constraints: str = ...,
    bounds: Bounds = ...,
    nominal: Optional[ArrayLike] = ...,
    tolerance: Union[None, float, str] = ...,
    diagonal: bool = ...,
    prior: Optional[ArrayLike] = ...,
    prior_sigma: Union[None, float, str, ArrayLike] = ...,
    products: str = ...,
    gyro_noise: Optional[float] = ...,
    attitude_drift: Optional[float] = ...,
    memory: Optional[float] = ...,
    resample: Optional[float] = ...,
    every: int = ...,
    rotation_source: Optional[str] = ...,
    rho_model: str = ...,
    torque_bias: bool = ...,
    inertial_torque: str = ...,
    damping: bool = ...,
    calibrate_rotors: bool = ...,
    outside: Optional[Mapping[str, Any]] = ...,
    rotor_scale_sigma: Optional[float] = ...,
    torque_scale_sigma: Optional[float] = ...,
    filter_cutoff_hz: Optional[float] = ...,
    chain: float = ...,
    wheel_delay: Union[None, str, float] = ...,
    glitches: str = ...,
    solver: str = ...,
    uncertainty: bool = ...,
    batch: bool = ...,
    history: bool = ...,
    truth: Optional[ArrayLike] = ...,
    scalar_first: bool = ...,
    jpl: bool = ...,
    conjugate: bool = ...,
    gyro_unit: Optional[str] = ...,
    negate_rho: bool = ...,
    columns: Optional[Mapping[str, str]] = ...,
    unit_tolerance: Optional[float] = ...,
    period_tolerance: Optional[float] = ...,
    spacecraft: Union[None, str, os.PathLike[str]] = ...,
) -> Estimate: ...

class Estimator:
    def __init__(
        self,
        *,
        estimator: str = ...,
        constraints: str = ...,
        bounds: Bounds = ...,
        nominal: Optional[ArrayLike] = ...,
        tolerance: Union[None, float, str] = ...,
        diagonal: bool = ...,
        prior: Optional[ArrayLike] = ...,
        prior_sigma: Union[None, float, str, ArrayLike] = ...,
        products: str = ...,
        gyro_noise: Optional[float] = ...,
        attitude_drift: Optional[float] = ...,
        memory: Optional[float] = ...,
        resample: Optional[float] = ...,
        every: int = ...,
        rotation_source: Optional[str] = ...,
        rho_model: str = ...,
        torque_bias: bool = ...,
        inertial_torque: str = ...,
        damping: bool = ...,
        outside: Optional[Mapping[str, Any]] = ...,
        rotor_scale_sigma: Optional[float] = ...,
        torque_scale_sigma: Optional[float] = ...,
        filter_cutoff_hz: Optional[float] = ...,
        chain: float = ...,
        glitches: str = ...,
        solver: str = ...,
        uncertainty: bool = ...,
        scalar_first: bool = ...,
        jpl: bool = ...,
        conjugate: bool = ...,
        gyro_unit: Optional[str] = ...,
        negate_rho: bool = ...,
        unit_tolerance: Optional[float] = ...,
        period_tolerance: Optional[float] = ...,
    ) -> None: ...
    def push(
        self,
        t: float,
        q: ArrayLike,
        rho: ArrayLike,
        tau: Optional[ArrayLike] = ...,
        w: Optional[ArrayLike] = ...,
        r: Optional[ArrayLike] = ...,
        b: Optional[ArrayLike] = ...,
        f: Optional[ArrayLike] = ...,
        dipole: Optional[ArrayLike] = ...,
    ) -> Optional[Estimate]: ...
    def push_many(
        self,
        t: ArrayLike,
        q: ArrayLike,
        rho: ArrayLike,
        tau: Optional[ArrayLike] = ...,
        w: Optional[ArrayLike] = ...,
        r: Optional[ArrayLike] = ...,
        b: Optional[ArrayLike] = ...,
        f: Optional[ArrayLike] = ...,
        dipole: Optional[ArrayLike] = ...,
    ) -> Optional[Estimate]: ...
    def finish(self) -> Optional[Estimate]: ...
    @property
    def estimate(self) -> Optional[Estimate]: ...
    @property
    def samples(self) -> int: ...

class Simulation:
    telemetry: Telemetry
    inertia: np.ndarray  # (3, 3) kg m², at the end of the run
    inertia_initial: np.ndarray
    scenario: str
    positions: Optional[np.ndarray]  # (N, 3) m
    def __iter__(self) -> Iterator[Any]: ...

def simulate(scenario: Optional[str] = ..., **options: Any) -> Simulation: ...

def plan(
    spacecraft: Union[str, "os.PathLike[str]"],
    target: float = ...,
    duration: Optional[float] = ...,
    max_duration: float = ...,
    chain: Union[float, str, None] = ...,
    rehearsals: int = ...,
    disturbance: float = ...,
) -> Dict[str, Any]: ...
