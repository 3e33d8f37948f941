"""The native module (internal: use the ``inertia`` package's functions)."""

from typing import Any, Dict, List, Optional, Tuple

import numpy as np

DEFAULT_ESTIMATOR: str
SETTINGS_KEYS: List[str]
INPUT_KEYS: List[str]

class DataError(ValueError):
    line: Optional[int]

_Result = Tuple[str, str, Optional[Dict[str, Any]]]

class Telemetry:
    t: np.ndarray
    q: np.ndarray
    rho: np.ndarray
    tau: np.ndarray
    w: Optional[np.ndarray]
    r: Optional[np.ndarray]
    b: Optional[np.ndarray]
    f: Optional[np.ndarray]
    file: Optional[str]
    lines: Optional[np.ndarray]
    stats: Dict[str, Any]
    q_columns: str
    label: str
    def rotors_state(self) -> Optional[Tuple[str, str, np.ndarray]]: ...
    def __len__(self) -> int: ...
    def estimate(self, kwargs: Optional[Dict[str, Any]] = ...) -> _Result: ...

class Stream:
    def __init__(self, kwargs: Optional[Dict[str, Any]] = ...) -> None: ...
    def push(
        self, t: float, q: Any, rho: Any, tau: Any = ..., w: Any = ...,
        r: Any = ..., b: Any = ..., f: Any = ..., dipole: Any = ...,
    ) -> bool: ...
    def push_many(
        self, t: Any, q: Any, rho: Any, tau: Any = ..., w: Any = ...,
        r: Any = ..., b: Any = ..., f: Any = ..., dipole: Any = ...,
    ) -> int: ...
    def finish(self) -> bool: ...
    def report(self) -> Optional[Tuple[str, str]]: ...
    samples: int
    estimator: str

def read_csv(path: str, kwargs: Optional[Dict[str, Any]] = ...) -> Telemetry: ...
def estimate_records(records: List[Telemetry], kwargs: Optional[Dict[str, Any]] = ...) -> _Result: ...
def estimate_arrays(
    t: np.ndarray,
    q: Optional[np.ndarray],
    rho: np.ndarray,
    tau: Optional[np.ndarray] = ...,
    w: Optional[np.ndarray] = ...,
    r: Optional[np.ndarray] = ...,
    b: Optional[np.ndarray] = ...,
    f: Optional[np.ndarray] = ...,
    dipole: Optional[np.ndarray] = ...,
    kwargs: Optional[Dict[str, Any]] = ...,
    frame_columns: Optional[List[str]] = ...,
    label: Optional[str] = ...,
) -> _Result: ...
def samples_from_arrays(
    t: np.ndarray,
    q: Optional[np.ndarray],
    rho: np.ndarray,
    tau: Optional[np.ndarray] = ...,
    w: Optional[np.ndarray] = ...,
    r: Optional[np.ndarray] = ...,
    b: Optional[np.ndarray] = ...,
    f: Optional[np.ndarray] = ...,
    dipole: Optional[np.ndarray] = ...,
    kwargs: Optional[Dict[str, Any]] = ...,
) -> Telemetry: ...
def restore(*state: Any) -> Telemetry: ...
def estimators() -> List[Tuple[str, str]]: ...
def simulate(
    kwargs: Optional[Dict[str, Any]] = ...,
) -> Tuple[Telemetry, np.ndarray, np.ndarray, str, Optional[np.ndarray]]: ...
def plan(
    spacecraft: str,
    target: float,
    duration: Optional[float],
    max_duration: float,
    chain: Optional[float],
    choose_chain: bool,
    rehearsals: int,
    disturbance: float,
) -> Dict[str, Any]: ...
