"""Type stubs of the extension module shpb._shpb (the Rust binding; use the package `shpb`)."""

from typing import Any, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

class InputError(ValueError):
    """Bad input (exit code 2 of `shpb`)."""

class InstabilityError(RuntimeError):
    """A numerically unstable run (exit code 3 of `shpb`)."""

class RunData:
    """The data of one run; `shpb.Run` wraps it."""

    @property
    def origin(self) -> str: ...
    def summary(self) -> List[Tuple[str, float, str]]: ...
    def bands(self) -> List[Tuple[str, float, str, float, float]]: ...
    def dataset_info(self) -> List[Tuple[str, List[int], str]]: ...
    def array(self, path: str) -> npt.NDArray[np.float64]: ...
    def verdict(self) -> Optional[Tuple[str, str]]: ...
    def warnings(self) -> List[str]: ...
    def scene(self) -> str: ...
    def provenance(
        self,
    ) -> Optional[Tuple[str, Optional[str], str, List[Tuple[str, str]]]]: ...
    def save(self, path: str, force: bool = False) -> None: ...

def run(
    scene: Union[str, dict],
    fidelity: Optional[str] = None,
    set: Optional[dict] = None,
    command_line: str = "",
    bands: bool = True,
) -> RunData: ...
def load(path: str) -> RunData: ...
def gun(pressure: str, bars: str = "authors") -> float: ...
def curve(
    pair: str = "ss440c",
    rate: float = 0.0,
    to: float = 250e-6,
    points: int = 101,
    law: str = "burgoyne-daraio",
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def reduce(
    record: str,
    bars: Optional[str] = None,
    dispersion: str = "bancroft",
    tyas_pope: bool = False,
    align: str = "geometric",
    smooth: float = 2e-6,
    specimen_length_m: Optional[float] = None,
    specimen_diameter_m: Optional[float] = None,
    layout: Optional[str] = None,
    balance_bound_s: float = 60e-6,
    specimen: Optional[str] = None,
    tension: bool = False,
) -> RunData: ...
Rows = List[Tuple[int, List[str], Tuple[float, float, float, float, float], List[str]]]

def sweep_runs(
    scene: str, set: Sequence[str], jobs: int = 1, shard: Tuple[int, int] = (1, 1)
) -> Tuple[List[str], Rows]: ...
def sweep_table(
    keys: List[str], rows: Rows, partial: bool = False
) -> Tuple[
    List[str],
    List[List[str]],
    List[Optional[Tuple[str, List[float]]]],
    List[Tuple[str, str, List[float]]],
    List[List[str]],
]: ...
def study_runs(
    scene: str,
    samples: int,
    seed: int = 1,
    jobs: int = 1,
    gun_scatter: bool = True,
    shard: Tuple[int, int] = (1, 1),
    fidelity: Optional[str] = None,
) -> Rows: ...
def study_table(
    scene: str,
    samples: int,
    seed: int,
    gun_scatter: bool,
    rows: Rows,
    fidelity: Optional[str] = None,
) -> Tuple[Any, List[Tuple[str, str, int, float, float, Tuple[float, float, float], List[float]]], List[str]]: ...
def version() -> str: ...
def is_hdf5(path: str) -> bool: ...

class FitData:
    """What `shpb fit` found; `shpb.Fit` wraps it."""

    @property
    def burn_in(self) -> int: ...
    def json(self) -> str: ...
    def keys(self) -> List[str]: ...
    def shape(self) -> Tuple[int, int, int]: ...
    def chain(self) -> npt.NDArray[np.float64]: ...
    def samples(self) -> npt.NDArray[np.float64]: ...
    def log_prob(self) -> npt.NDArray[np.float64]: ...
    def correlations(self) -> List[List[float]]: ...
    def records(self) -> List[dict]: ...
    def warnings(self) -> List[str]: ...
    def save(self, path: str, force: bool = False) -> None: ...

def fit(
    scene: str,
    free: Sequence[str],
    prior: Sequence[str] = ...,
    record: Sequence[str] = ...,
    residual: Optional[str] = None,
    walkers: int = 0,
    steps: int = 200,
    burn_in: Optional[int] = None,
    seed: int = 1,
    jobs: Optional[int] = None,
    output: Optional[str] = None,
    plot: Optional[str] = None,
    corner: Optional[str] = None,
    force: bool = False,
    command_line: str = "",
) -> FitData: ...
