# Type stubs of superball._core, the compiled half of the package (src/python/module.cpp):
# use the package's functions, which check and convert the arguments first.
from typing import Any, Optional, Sequence

import numpy as np
import numpy.typing as npt

# The model's coefficients (e, alpha, e_wall, alpha_wall, e_floor, alpha_floor, mu, mu_wall,
# mu_floor, inertia): each a float, or None where not given; no other key.
_Model = dict[str, Optional[float]]

version: str
source: str
build: str
kernel_report: str
outcomes: tuple[str, ...]
usable_cores: int

def resolve_one_start(given: Sequence[str], g: Optional[float], radius: Optional[float], max_bounces: str,
                      model: _Model) -> tuple[bool, float, float, int]: ...
def count(coordinates: Sequence[tuple[str, npt.NDArray[Any]]], physical: bool, g: float, radius: float,
          model: _Model, max_bounces: int, threads: int,
          kernel: str) -> tuple[npt.NDArray[np.uint32], npt.NDArray[np.uint8]]: ...
def trajectory(xi: Optional[float], U: Optional[float], W: Optional[float], x: Optional[float], u: Optional[float],
               v: Optional[float], omega: Optional[float], g: Optional[float], radius: Optional[float],
               model: _Model, max_bounces: int, samples: int) -> tuple[dict[str, Any], dict[str, Any]]: ...
def fixed_points(model: _Model, period: int, starts: int, seed: int, corner: bool) -> list[dict[str, Any]]: ...
def continue_branch(model: _Model, param: str, min: Optional[float],
                    max: Optional[float], start: Optional[tuple[float, float, float]], period: int, starts: int,
                    seed: int, corner: bool, step: Optional[float], max_step: float, min_step: float,
                    max_points: int, curve: str, curve_min: Optional[float], curve_max: Optional[float],
                    curve_step: float, curve_max_step: float, curve_max_points: int) -> dict[str, Any]: ...
def parse_job(text: str, source: str) -> dict[str, Any]: ...
def load_job(path: str) -> dict[str, Any]: ...
# run: output (str), overwrite, resume (bool), threads (int), kernel, command (str), progress (bool).
def explore(text: str, source: str, run: dict[str, Any]) -> dict[str, Any]: ...
def validate(path: str) -> dict[str, Any]: ...
