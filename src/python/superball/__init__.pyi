# Type stubs of the superball package (src/python/superball/__init__.py documents each function).
import enum
import os
from typing import Any, Literal, NamedTuple, Optional, Sequence, Union, overload

import numpy as np
import numpy.typing as npt
import xarray

__version__: str
SOURCE: str
BUILD: str
KERNELS: str
OUTCOMES: tuple[str, str, str, str]

_Real = Union[float, int, np.floating, np.integer]
_Coordinate = Union[_Real, npt.ArrayLike]
_Path = Union[str, os.PathLike[str]]
_Kernel = Optional[Literal["simd", "scalar", "baseline", "avx2", "avx512", "native"]]
_Parameter = Literal["e", "alpha", "e_wall", "alpha_wall", "e_floor", "alpha_floor"]

class Outcome(enum.IntEnum):
    invalid = 0
    left = 1
    missed = 2
    capped = 3

class Counts(NamedTuple):
    wall_bounces: Any  # npt.NDArray[np.uint32], or int for a single launch
    outcome: Any  # npt.NDArray[np.uint8], or Outcome for a single launch
    def outcome_names(self) -> npt.NDArray[np.str_]: ...

class Trajectory(dict[str, npt.NDArray[Any]]):
    wall_bounces: int
    outcome: Outcome
    truncated: bool
    units: str
    g: float
    radius: float
    start: tuple[float, float, float]

def count(
    xi: Optional[_Coordinate] = None,
    U: Optional[_Coordinate] = None,
    W: Optional[_Coordinate] = None,
    *,
    x: Optional[_Coordinate] = None,
    u: Optional[_Coordinate] = None,
    v: Optional[_Coordinate] = None,
    omega: Optional[_Coordinate] = None,
    g: Optional[_Real] = None,
    radius: Optional[_Real] = None,
    e: Optional[_Real] = None,
    alpha: Optional[_Real] = None,
    e_wall: Optional[_Real] = None,
    alpha_wall: Optional[_Real] = None,
    e_floor: Optional[_Real] = None,
    alpha_floor: Optional[_Real] = None,
    mu: Optional[_Real] = None,
    mu_wall: Optional[_Real] = None,
    mu_floor: Optional[_Real] = None,
    inertia: Optional[_Real] = None,
    max_bounces: int = 1000,
    threads: Optional[int] = None,
    kernel: _Kernel = None,
) -> Counts: ...
def trajectory(
    xi: Optional[_Real] = None,
    U: Optional[_Real] = None,
    W: Optional[_Real] = None,
    *,
    x: Optional[_Real] = None,
    u: Optional[_Real] = None,
    v: Optional[_Real] = None,
    omega: Optional[_Real] = None,
    g: Optional[_Real] = None,
    radius: Optional[_Real] = None,
    e: Optional[_Real] = None,
    alpha: Optional[_Real] = None,
    e_wall: Optional[_Real] = None,
    alpha_wall: Optional[_Real] = None,
    e_floor: Optional[_Real] = None,
    alpha_floor: Optional[_Real] = None,
    mu: Optional[_Real] = None,
    mu_wall: Optional[_Real] = None,
    mu_floor: Optional[_Real] = None,
    inertia: Optional[_Real] = None,
    max_bounces: int = 1000,
    samples: int = 0,
) -> Trajectory: ...
def fixed_points(
    *,
    e: Optional[_Real] = None,
    alpha: Optional[_Real] = None,
    e_wall: Optional[_Real] = None,
    alpha_wall: Optional[_Real] = None,
    e_floor: Optional[_Real] = None,
    alpha_floor: Optional[_Real] = None,
    mu: Optional[_Real] = None,
    mu_wall: Optional[_Real] = None,
    mu_floor: Optional[_Real] = None,
    inertia: Optional[_Real] = None,
    period: int = 1,
    starts: int = 2000,
    seed: int = 1,
    corner: bool = False,
) -> dict[str, Any]: ...
def continue_branch(
    *,
    param: _Parameter,
    min: _Real,
    max: _Real,
    e: Optional[_Real] = None,
    alpha: Optional[_Real] = None,
    e_wall: Optional[_Real] = None,
    alpha_wall: Optional[_Real] = None,
    e_floor: Optional[_Real] = None,
    alpha_floor: Optional[_Real] = None,
    mu: Optional[_Real] = None,
    mu_wall: Optional[_Real] = None,
    mu_floor: Optional[_Real] = None,
    inertia: Optional[_Real] = None,
    start: Optional[Sequence[_Real]] = None,
    period: int = 1,
    starts: int = 2000,
    seed: int = 1,
    corner: bool = False,
    step: Optional[_Real] = None,
    max_step: _Real = 0.05,
    min_step: _Real = 1e-7,
    max_points: int = 2000,
    curve: Optional[_Parameter] = None,
    curve_min: Optional[_Real] = None,
    curve_max: Optional[_Real] = None,
    curve_step: _Real = 0.005,
    curve_max_step: _Real = 0.02,
    curve_max_points: int = 400,
) -> dict[str, Any]: ...
@overload
def explore(
    job: Union[_Path, dict[str, dict[str, Any]]],
    output: Optional[_Path] = None,
    *,
    overwrite: bool = False,
    resume: bool = False,
    threads: Optional[int] = None,
    kernel: _Kernel = None,
    progress: bool = False,
    dataset: Literal[True] = True,
) -> xarray.Dataset: ...
@overload
def explore(
    job: Union[_Path, dict[str, dict[str, Any]]],
    output: Optional[_Path] = None,
    *,
    overwrite: bool = False,
    resume: bool = False,
    threads: Optional[int] = None,
    kernel: _Kernel = None,
    progress: bool = False,
    dataset: Literal[False],
) -> dict[str, Any]: ...
def open(path: _Path) -> xarray.Dataset: ...
