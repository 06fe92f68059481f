# Type stubs of the Rust extension ``fractalgeo_rs._core``.
# Each domain keeps its own section; the public, documented API is in the
# Python modules that wrap these functions.
from os import PathLike
from typing import Optional, Sequence, Tuple

import numpy as np
import numpy.typing as npt

__version__: str

# ---- dimension ----
def box_count_binary(
    data: npt.NDArray[np.uint8],
    box_sizes: Sequence[int],
    offsets: int,
    anchor_bbox: bool,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.uint64], int, list[int], list[int]]: ...
def box_count_points(
    points: npt.NDArray[np.float64],
    box_sizes: Sequence[float],
    offsets: int,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]: ...
def dbc_count(
    data: npt.NDArray[np.floating],
    box_sizes: Sequence[int],
    offsets: int,
    z0: float,
    z_unit: float,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.float64]]: ...
def column_ranges(
    data: npt.NDArray[np.float64],
    box_sizes: Sequence[int],
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]: ...

# ---- io ----
def read_image(path: str | PathLike[str]) -> np.ndarray: ...
def write_png(path: str | PathLike[str], image: np.ndarray) -> None: ...

# ---- synth / dem ----
def normal_noise(
    n: int, seed: int, stream: int, start: int = 0, n_threads: Optional[int] = None
) -> npt.NDArray[np.float64]: ...
def midpoint_refine_1d(
    coarse: npt.NDArray[np.float64],
    levels: int,
    hurst: float,
    sigma: float,
    coarse_spacing: float,
    additions: bool,
    seed: int,
    first_level: int = 0,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def midpoint_refine_2d(
    coarse: npt.NDArray[np.float64],
    levels: int,
    hurst: float,
    sigma: float,
    coarse_spacing: float,
    additions: bool,
    periodic: bool,
    seed: int,
    first_level: int = 0,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def hillshade_f64(
    dem: npt.NDArray[np.float64],
    dx: Sequence[float],
    dy: float,
    azimuth: float,
    altitude: float,
    z_factor: float,
    multidirectional: bool,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float32]: ...
def shade_to_byte(shade: npt.NDArray[np.float32], n_threads: Optional[int] = None) -> npt.NDArray[np.uint8]: ...
def read_exr(path: str | PathLike[str]) -> npt.NDArray[np.float32]: ...
def write_exr(path: str | PathLike[str], image: npt.NDArray[np.float32]) -> None: ...

# ---- lsystem ----
