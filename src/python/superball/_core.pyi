# Type stubs of superball._core, the compiled half of the package (src/python/module.cpp):
# use the package's functions, which check and convert the arguments first.
from typing import Any, Optional, Sequence

import numpy as np
import numpy.typing as npt

version: str
source: str
build: str
kernel_report: str
outcomes: tuple[str, ...]
usable_cores: int

def resolve_one_start(given: Sequence[str], g: Optional[float], radius: Optional[float], max_bounces: str,
                      e: Optional[float], alpha: Optional[float], e_wall: Optional[float], alpha_wall: Optional[float],
                      e_floor: Optional[float], alpha_floor: Optional[float]) -> tuple[bool, float, float, int]: ...
def count(coordinates: Sequence[tuple[str, npt.NDArray[Any]]], physical: bool, g: float, radius: float,
          e: Optional[float], alpha: Optional[float], e_wall: Optional[float], alpha_wall: Optional[float],
          e_floor: Optional[float], alpha_floor: Optional[float], max_bounces: int, threads: int,
          kernel: str) -> tuple[npt.NDArray[np.uint32], npt.NDArray[np.uint8]]: ...
def trajectory(xi: Optional[float], U: Optional[float], W: Optional[float], x: Optional[float], u: Optional[float],
               v: Optional[float], omega: Optional[float], g: Optional[float], radius: Optional[float],
               e: Optional[float], alpha: Optional[float], e_wall: Optional[float], alpha_wall: Optional[float],
               e_floor: Optional[float], alpha_floor: Optional[float], max_bounces: int,
               samples: int) -> tuple[dict[str, Any], dict[str, Any]]: ...
def fixed_points(e: Optional[float], alpha: Optional[float], e_wall: Optional[float], alpha_wall: Optional[float],
                 e_floor: Optional[float], alpha_floor: Optional[float], period: int, starts: int, seed: int,
                 corner: bool) -> list[dict[str, Any]]: ...
def continue_branch(e: Optional[float], alpha: Optional[float], e_wall: Optional[float], alpha_wall: Optional[float],
                    e_floor: Optional[float], alpha_floor: Optional[float], param: str, min: Optional[float],
                    max: Optional[float], start: Optional[tuple[float, float, float]], period: int, starts: int,
                    seed: int, corner: bool, step: Optional[float], max_step: float, min_step: float,
                    max_points: int, curve: str, curve_min: Optional[float], curve_max: Optional[float],
                    curve_step: float, curve_max_step: float, curve_max_points: int) -> dict[str, Any]: ...
def parse_job(text: str, source: str) -> dict[str, Any]: ...
def load_job(path: str) -> dict[str, Any]: ...
def explore(text: str, source: str, output: str, overwrite: bool, resume: bool, threads: int, kernel: str,
            command: str, progress: bool) -> dict[str, Any]: ...
def validate(path: str) -> dict[str, Any]: ...
