"""Type stubs of termid's native module (the Rust library through PyO3). Use the friendly
API in `termid` (`termid.Model`, `termid.fit`, `termid.Moments`) rather than this module."""

from typing import Any, Dict, List, Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

Columns = Dict[str, npt.NDArray[np.float64]]
Run = Tuple[str, Columns]
NamedArrays = List[Tuple[str, npt.NDArray[np.float64]]]

class TermidError(Exception):
    """termid refused the input; the message locates it (file, row, column, or a caret)."""

class Model:
    @staticmethod
    def load(path: str) -> Model: ...
    @staticmethod
    def parse(text: str, name: str = "<text>") -> Model: ...
    @staticmethod
    def builtin(name: str) -> Model: ...
    @staticmethod
    def builtin_names() -> List[str]: ...
    @staticmethod
    def from_states(
        states: Sequence[str], inputs: Sequence[str], candidates: Sequence[str], degree: Optional[int], time: str, name: str
    ) -> Model: ...
    @staticmethod
    def from_particulars(text: str, json: bool = False, name: str = "<particulars>") -> Tuple[Model, str, List[str]]: ...
    @staticmethod
    def default_model() -> Model: ...
    def to_toml(self) -> str: ...
    def save(self, path: str) -> None: ...
    @property
    def name(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def time(self) -> str: ...
    @property
    def states(self) -> List[str]: ...
    @property
    def initial(self) -> Dict[str, float]: ...
    @property
    def inputs(self) -> List[str]: ...
    @property
    def equations(self) -> List[str]: ...
    @property
    def identifiable(self) -> List[str]: ...
    @property
    def parameters(self) -> Dict[str, float]: ...
    @property
    def free_parameters(self) -> List[str]: ...
    def coefficients(self, equation: str) -> List[Tuple[str, float, Optional[float]]]: ...
    def intercept(self, equation: str) -> Optional[float]: ...
    def set_coefficients(
        self, equation: str, coefficients: Sequence[Tuple[str, float, Optional[float]]], intercept: Optional[float] = None
    ) -> None: ...
    def set_parameter(self, name: str, value: float) -> None: ...
    def set_per_run(self, name: str, rule: Optional[str]) -> None: ...
    def identify(
        self,
        runs: Sequence[Run],
        derivative: Optional[str] = None,
        equations: Sequence[str] = ...,
        intercept: Optional[bool] = None,
        backend: Optional[str] = None,
    ) -> Tuple[Model, List[Tuple[str, str]]]: ...
    def starting_as(self, run: Run) -> Model: ...
    def moments(self, equations: Sequence[str], runs: Sequence[Run], derivative: Optional[str] = None) -> List[Moments]: ...
    def identify_from_moments(
        self, moments: Sequence[Moments], intercept: Optional[bool] = None
    ) -> Tuple[Model, List[Tuple[str, str]]]: ...
    def predict(self, run: Run, with_intercept: bool = False) -> NamedArrays: ...
    def simulate_free(
        self,
        duration: float,
        inputs: Dict[str, float],
        initial: Dict[str, float],
        dt: Optional[float] = None,
        sample: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
    ) -> NamedArrays: ...
    def simulate(
        self,
        scenario: str,
        dt: Optional[float] = None,
        duration: Optional[float] = None,
        sample: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
    ) -> Tuple[NamedArrays, str, str, List[str]]: ...
    def record(
        self, manoeuvre: str, speed: float = 1.0, duration: float = 100.0, seed: int = 0, tracked: bool = False
    ) -> Tuple[NamedArrays, NamedArrays]: ...
    def spread_from(self, predict: Any) -> str: ...
    def replay(
        self, runs: Sequence[Run], dt: Optional[float] = None, integrator: Optional[str] = None, with_intercept: bool = False
    ) -> List[NamedArrays]: ...
    def validate(
        self,
        runs: Sequence[Run],
        dt: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        over_ground: bool = False,
    ) -> str: ...
    def validate_monte_carlo(
        self,
        runs: Sequence[Run],
        n: int,
        seed: int = 1,
        dt: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        over_ground: bool = False,
    ) -> str: ...
    def diagnose(
        self,
        runs: Sequence[Run],
        dt: Optional[float] = None,
        integrator: Optional[str] = None,
        with_intercept: bool = False,
        over_ground: bool = False,
    ) -> Tuple[str, Optional[Model]]: ...
    def recipe(
        self,
        runs: Sequence[Run],
        derivatives: Sequence[str],
        smooth: bool = False,
        intercept: Optional[bool] = None,
        choose: Sequence[str] = ...,
        compare: Sequence[str] = ...,
        refine: Optional[Sequence[str]] = None,
        refine_iterations: int = 100,
        refine_prior: float = 1e-4,
        held_out: Sequence[Run] = ...,
        refine_step: Optional[float] = None,
        parameters: Optional[bool] = None,
        sources: Sequence[int] = ...,
        per_source: Sequence[str] = ...,
        per_run: Sequence[str] = ...,
    ) -> Tuple[str, str, Model]: ...
    def estimate(
        self,
        runs: Sequence[Run],
        coefficients: bool = False,
        states: Optional[Sequence[str]] = None,
        initial_values: str = "auto",
        dt: Optional[float] = None,
        iterations: int = 50,
        sources: Sequence[int] = ...,
        per_source: Sequence[str] = ...,
        per_run: Sequence[str] = ...,
        coarse: bool = False,
        segments: Optional[int] = None,
        free: Sequence[str] = ...,
        hold: Sequence[str] = ...,
        over_ground: bool = False,
    ) -> Tuple[str, Model]: ...
    def checks(self, runs: Sequence[Run] = ...) -> str: ...
    def steering_gear(self, runs: Sequence[Run]) -> Optional[str]: ...
    def sway_yaw(self, speed: Optional[float] = None) -> Optional[str]: ...
    def __reduce__(self) -> Tuple[Any, Tuple[str, str]]: ...

class Moments:
    @staticmethod
    def from_json(text: str, origin: str = "<moments>") -> Moments: ...
    @staticmethod
    def from_frame(
        data: Any, model: Any, equation: str, derivative: Optional[str] = None, target: Optional[str] = None
    ) -> Moments: ...
    def to_json(self) -> str: ...
    def to_bytes(self) -> bytes: ...
    def __add__(self, other: "Moments") -> "Moments": ...
    def __eq__(self, other: object) -> bool: ...
    @staticmethod
    def from_bytes(data: bytes, origin: str = "<moments>") -> Moments: ...
    def merge(self, other: Moments) -> Moments: ...
    @property
    def equation(self) -> str: ...
    @property
    def target(self) -> str: ...
    @property
    def candidates(self) -> List[str]: ...
    @property
    def runs(self) -> List[str]: ...
    @property
    def rows(self) -> int: ...
    def __reduce__(self) -> Tuple[Any, Tuple[bytes]]: ...

class Fit:
    def to_json(self) -> str: ...
    def report_json(self) -> str: ...
    def predict(self, columns: Columns) -> npt.NDArray[np.float64]: ...

def fit(
    target: str,
    columns: Columns,
    terms: Sequence[str],
    backend: str = ...,
    intercept: bool = True,
    forced: Sequence[str] = ...,
    excluded: Sequence[str] = ...,
    parameters: Dict[str, float] = ...,
    weights: Optional[str] = None,
    time: Optional[str] = None,
    derivative: Optional[str] = None,
    keep_spikes: bool = False,
    intersample: str = "auto",
    delays: Dict[str, float] = ...,
    runs: Sequence[Tuple[str, Columns]] = ...,
) -> Fit: ...
def methods() -> Tuple[List[str], List[str]]: ...
def version() -> str: ...
def default_settings(name: str) -> str: ...
def time_like(names: List[str]) -> Optional[str]: ...
def interleaved(labels: List[int], columns: List[Any]) -> Optional[Tuple[int, int]]: ...
