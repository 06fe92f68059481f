# Type stubs of the Rust extension ``fractalgeo_rs._core``.
# Each domain keeps its own section; the public, documented API is in the
# Python modules that wrap these functions.
from os import PathLike
from typing import Any, Dict, List, Optional, Protocol, Sequence, Tuple, final

import numpy as np
import numpy.typing as npt

__version__: str
__all__ = [
    "LSystemCore",
    "ModuleString",
    "ProgressCounter",
    "RadiometryScene",
    "__version__",
    "additions_refine_2d",
    "blanket_areas_image",
    "blanket_transform_map",
    "box_count_binary",
    "box_count_point_levels",
    "box_count_points",
    "column_ranges",
    "davies_harte_fbm",
    "dbc_count",
    "dbc_transform_map",
    "exr_header",
    "fgn_sqrt_eigenvalues",
    "fractal_resample",
    "gls_transform_map",
    "higuchi_lengths",
    "hillshade_f64",
    "hillshade_gdal_byte",
    "ifs_chaos_game",
    "image_header",
    "ifs_check",
    "ifs_iterate",
    "ifs_preset",
    "ifs_rasterize",
    "lacunarity_transform_map",
    "lsystem_parse_text",
    "mass_curve_image",
    "mass_transform_map",
    "mesh_edges",
    "mesh_from_grid",
    "mesh_from_tin",
    "mesh_validate",
    "midpoint_refine_1d",
    "midpoint_refine_2d",
    "moran_dimension",
    "normal_noise",
    "plants_on_terrain",
    "read_exr",
    "read_image",
    "shade_to_byte",
    "spectral_filter_2d",
    "turtle_mesh",
    "turtle_polylines",
    "turtle_segments",
    "variation_transform_map",
    "write_exr",
    "write_mesh",
    "write_png",
    "resample_stencil",
    "resample_local_maps",
    "resample_node_variograms",
    "resample_interp_nodes",
    "resample_local_amplitude",
    "RESAMPLE_HALO",
    "tin_delaunay",
    "tin_greedy",
    "tin_grid",
    "tin_rasterize",
    "radar_geocode",
    "radar_geometry",
    "radar_project",
    "radar_scene",
    "radar_slant_extent",
    "speckle_f64",
    "radiometry_intersect",
    "radiometry_occluded",
]

# ---- geometry ----
class _MeshLike(Protocol):  # read by attribute (geometry.Mesh), exact dtypes, any strides
    @property
    def origin(self) -> Tuple[float, float, float]: ...
    @property
    def vertices(self) -> npt.NDArray[np.float32]: ...
    @property
    def normals(self) -> npt.NDArray[np.float32]: ...
    @property
    def uvs(self) -> npt.NDArray[np.float32]: ...
    @property
    def faces(self) -> npt.NDArray[np.uint32]: ...
    @property
    def part_ids(self) -> npt.NDArray[np.uint32]: ...
    @property
    def kinds(self) -> npt.NDArray[np.uint8]: ...
    @property
    def colors(self) -> npt.NDArray[np.uint32]: ...
    @property
    def instances(self) -> npt.NDArray[np.uint32]: ...

class _GeoGridLike(Protocol):  # read by attribute (geometry.GeoGrid)
    @property
    def origin(self) -> Tuple[float, float]: ...
    @property
    def cell_size(self) -> Tuple[float, float]: ...
    @property
    def rotation(self) -> float: ...
    @property
    def crs(self) -> Optional[str]: ...

def mesh_from_grid(
    dem: npt.NDArray[np.float64], grid: _GeoGridLike, split: str, n_threads: Optional[int] = None
) -> Dict[str, Any]: ...
def mesh_from_tin(vertices: npt.NDArray[np.float64], triangles: npt.NDArray[np.int64]) -> Dict[str, Any]: ...
def mesh_validate(mesh: _MeshLike) -> None: ...
def mesh_edges(mesh: _MeshLike) -> Tuple[int, int, int]: ...

# ---- dimension ----
def box_count_binary(
    data: npt.NDArray[np.uint8],
    box_sizes: Sequence[int],
    offsets: int,
    anchor_bbox: bool,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.uint64], npt.NDArray[np.uint64], int, list[int], list[int]]: ...
def box_count_point_levels(
    points: npt.NDArray[np.float64],
    base: int,
    k_first: int,
    min_occupancy: float,
    max_levels: int,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
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
def higuchi_lengths(
    data: npt.NDArray[np.float64],
    k_max: int,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def column_ranges(
    data: npt.NDArray[np.float64],
    box_sizes: Sequence[int],
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]: ...

# ---- io ----
def read_image(path: str | PathLike[str]) -> np.ndarray: ...
def image_header(path: str | PathLike[str]) -> Tuple[int, int, int, int]: ...
def exr_header(path: str | PathLike[str]) -> Tuple[int, int, int]: ...
def write_png(path: str | PathLike[str], image: np.ndarray) -> None: ...

# ---- synth / dem ----
@final
class ProgressCounter:
    def __new__(cls) -> ProgressCounter: ...
    @property
    def done(self) -> int: ...
    @property
    def total(self) -> int: ...

def normal_noise(
    n: int,
    seed: int,
    stream: int,
    start: int = 0,
    n_threads: Optional[int] = None,
    progress: Optional[ProgressCounter] = None,
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
    progress: Optional[ProgressCounter] = None,
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
    progress: Optional[ProgressCounter] = None,
) -> npt.NDArray[np.float64]: ...
def additions_refine_2d(
    coarse: npt.NDArray[np.float64],
    levels: int,
    hurst: float,
    sigma: float,
    coarse_spacing: float,
    tension: float,
    variances: Sequence[float],
    periodic: bool,
    seed: int,
    first_level: int = 0,
    n_threads: Optional[int] = None,
    shape: Optional[Tuple[int, int]] = None,
    progress: Optional[ProgressCounter] = None,
) -> npt.NDArray[np.float64]: ...
def fgn_sqrt_eigenvalues(m: int, hurst: float, n_threads: Optional[int] = None) -> npt.NDArray[np.float64]: ...
def davies_harte_fbm(
    sqrt_eig: npt.NDArray[np.float64],
    n: int,
    seed: int,
    stream: int,
    n_threads: Optional[int] = None,
    progress: Optional[ProgressCounter] = None,
) -> npt.NDArray[np.float64]: ...
def spectral_filter_2d(n0: int, n1: int, hurst: float, n_threads: Optional[int] = None) -> npt.NDArray[np.float64]: ...
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
def hillshade_gdal_byte(
    dem: npt.NDArray[np.float32],
    dx: float,
    dy: float,
    azimuth: float,
    altitude: float,
    z_factor: float,
    multidirectional: bool,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.uint8]: ...
def shade_to_byte(shade: npt.NDArray[np.float32], n_threads: Optional[int] = None) -> npt.NDArray[np.uint8]: ...
def read_exr(path: str | PathLike[str]) -> npt.NDArray[np.float32]: ...
def write_exr(path: str | PathLike[str], image: npt.NDArray[np.float32]) -> None: ...

# ---- lsystem ----
class _TurtleArgs(Protocol):  # read by attribute (lsystem.geometry.TurtleArgs)
    @property
    def angle(self) -> float: ...
    @property
    def step(self) -> float: ...
    @property
    def width(self) -> float: ...
    @property
    def width_factor(self) -> float: ...
    @property
    def tropism(self) -> Tuple[float, float, float]: ...
    @property
    def elasticity(self) -> float: ...
    @property
    def heading(self) -> Tuple[float, float, float]: ...
    @property
    def left(self) -> Tuple[float, float, float]: ...
    @property
    def draw(self) -> str: ...
    @property
    def moves(self) -> str: ...

# a mesh from Rust: {"origin", "vertices", "normals", "uvs", "faces", "part_ids", "kinds", "colors", "instances"}
_MeshDict = Dict[str, Any]

@final
class ModuleString:
    @staticmethod
    def parse(text: str) -> ModuleString: ...
    def __len__(self) -> int: ...
    def __eq__(self, other: object, /) -> bool: ...
    def count(self, symbol: str) -> int: ...
    def symbols(self) -> str: ...
    def parameters(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64]]: ...

@final
class LSystemCore:
    def __new__(cls, axiom: str, rules: Sequence[str], ignore: str, seed: int, max_length: int) -> LSystemCore: ...
    def derive(self, n: int, seed: Optional[int] = None, n_threads: Optional[int] = None) -> ModuleString: ...
    def length_bounds(self, n: int) -> Tuple[int, int]: ...
    @property
    def is_stochastic(self) -> bool: ...
    @property
    def n_rules(self) -> int: ...
    @property
    def axiom(self) -> ModuleString: ...

def lsystem_parse_text(text: str) -> Tuple[str, Optional[str], list[str], list[Tuple[str, str]]]: ...
def turtle_polylines(
    lstring: ModuleString, turtle: _TurtleArgs
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint64], npt.NDArray[np.float64], npt.NDArray[np.uint64]]: ...
def turtle_segments(
    lstring: ModuleString, turtle: _TurtleArgs
) -> Tuple[
    npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint32],
    npt.NDArray[np.float64], npt.NDArray[np.uint64],
]: ...
def turtle_mesh(lstring: ModuleString, turtle: _TurtleArgs, sides: int, n_threads: Optional[int] = None) -> _MeshDict: ...
def write_mesh(
    path: str | PathLike[str], format: str, mesh: _MeshLike, comments: Sequence[str] = ..., groups: Sequence[str] = ...
) -> None: ...
def plants_on_terrain(
    lsystem: LSystemCore,
    n: int,
    dem: npt.NDArray[np.float64],
    cell_size: float,
    density: float,
    seed: int,
    scale: float,
    max_plants: int,
    turtle: _TurtleArgs,
    sides: int,
    n_threads: Optional[int] = None,
) -> Tuple[_MeshDict, npt.NDArray[np.float64]]: ...
def ifs_check(
    maps: npt.NDArray[np.float64], probabilities: Optional[Sequence[float]] = None
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], Optional[float]]: ...
def ifs_preset(name: str) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], Optional[float]]: ...
def ifs_chaos_game(
    maps: npt.NDArray[np.float64],
    probabilities: Optional[Sequence[float]],
    n_points: int,
    seed: int,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def ifs_iterate(
    maps: npt.NDArray[np.float64], depth: int, max_points: int, n_threads: Optional[int] = None
) -> npt.NDArray[np.float64]: ...
def ifs_rasterize(
    points: npt.NDArray[np.float64],
    n_rows: int,
    n_cols: int,
    bounds: Optional[Sequence[float]] = None,
) -> Tuple[npt.NDArray[np.uint8], Tuple[float, float, float, float]]: ...
def moran_dimension(ratios: Sequence[float]) -> float: ...

# ---- transform ----
def gls_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    dilations: int,
    h0: float,
    dh: float,
    a: npt.NDArray[np.float64],
    da: npt.NDArray[np.float64],
    g: npt.NDArray[np.float64],
    se: Sequence[float],
    steps: int,
    min_valid: float,
    step: int = 1,
    anisotropy: bool = False,
    n_threads: Optional[int] = None,
) -> List[npt.NDArray[np.float32]]: ...
def variation_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    lags: Sequence[int],
    p: float,
    square: bool,
    min_valid: float,
    step: int = 1,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def mass_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    box_sizes: Sequence[int],
    z_scale: float,
    min_valid: float,
    step: int = 1,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def dbc_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    box_sizes: Sequence[int],
    z_scale: float,
    z0: float,
    partial_blocks: bool,
    min_valid: float,
    step: int,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def blanket_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    epsilons: Sequence[int],
    z_scale: float,
    min_valid: float,
    step: int,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def blanket_areas_image(
    image: npt.NDArray[np.float64],
    eps_max: int,
    z_scale: float,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], int]: ...
def lacunarity_transform_map(
    image: npt.NDArray[np.float64],
    window_size: int,
    box_sizes: Sequence[int],
    min_valid: float,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float32]: ...
def mass_curve_image(
    image: npt.NDArray[np.float64],
    box_sizes: Sequence[int],
    z_scale: float,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...


# --- dem: fractal resampling ---
RESAMPLE_HALO: int

def fractal_resample(
    dem: npt.NDArray[np.float64],
    # 2D (rows, cols) or 1 x 1 for every level, or 3D (levels, rows, cols) per level
    hurst: npt.NDArray[np.float64],
    sigma: npt.NDArray[np.float64],
    levels: int,
    area: bool,
    seed: int,
    detail: Sequence[bool],
    origin: Tuple[int, int] = ...,
    global_cols: int = 0,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def resample_stencil(
    which: int, hurst: float
) -> Tuple[list[float], float, list[Tuple[int, int]]]: ...
def resample_local_maps(
    dem: npt.NDArray[np.float64],
    half: int,
    step: int,
    border: int,
    hurst_range: Tuple[float, float],
    table: Optional[
        Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]
    ] = None,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int]: ...
def resample_node_variograms(
    dem: npt.NDArray[np.float64],
    half: int,
    step: int,
    lags: list[int],
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], int, int]: ...
def resample_interp_nodes(
    nodes: npt.NDArray[np.float64],
    k0r: int,
    k0c: int,
    shape: Tuple[int, int],
    t: int,
    step: int,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def resample_local_amplitude(
    dem: npt.NDArray[np.float64],
    d1: npt.NDArray[np.float64],
    t: int,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def tin_delaunay(
    points: npt.NDArray[np.float64],
    constraints: Optional[npt.NDArray[np.int64]] = None,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.int64]: ...
def tin_greedy(
    dem: npt.NDArray[np.float64],
    max_error: float,
    max_triangles: Optional[int] = None,
    shared_edges: bool = True,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.int64], npt.NDArray[np.float64], npt.NDArray[np.int64], float]: ...
def tin_grid(
    points: npt.NDArray[np.float64],
    values: npt.NDArray[np.float64],
    rows: int,
    cols: int,
    transform: Sequence[float],
    method: str,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def tin_rasterize(
    xy: npt.NDArray[np.float64],
    z: npt.NDArray[np.float64],
    triangles: npt.NDArray[np.int64],
    rows: int,
    cols: int,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...

# ---- radar ----
def speckle_f64(
    intensity: npt.NDArray[np.float64],
    looks: int,
    seed: int,
    origin: Tuple[int, int] = ...,
    global_cols: int = 0,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.float64]: ...
def radar_geometry(
    dem: npt.NDArray[np.float64],
    dx: float,
    dy: float,
    incidence: float,
    table: Sequence[float],
    table_step: float,
    n_threads: Optional[int] = None,
    slant: Optional[Tuple[float, int]] = None,
) -> Tuple[
    npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint8], int
]: ...
def radar_project(
    power: npt.NDArray[np.float64],
    position: npt.NDArray[np.float64],
    flags: npt.NDArray[np.uint8],
    n_bins: int,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.uint32], npt.NDArray[np.uint32]]: ...
def radar_geocode(
    slant_a: npt.NDArray[np.float64],
    slant_b: npt.NDArray[np.float64],
    count: npt.NDArray[np.uint32],
    position: npt.NDArray[np.float64],
    flags: npt.NDArray[np.uint8],
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.uint8]]: ...
def radar_scene(
    dem: npt.NDArray[np.float64],
    dx: float,
    dy: float,
    incidence: float,
    table: Sequence[float],
    table_step: float,
    looks: int,
    seed: int,
    n_threads: Optional[int] = None,
    row0: int = 0,
    slant: Optional[Tuple[float, int]] = None,
    progress: Optional[ProgressCounter] = None,
) -> Tuple[
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.float64],
    npt.NDArray[np.uint8],
    npt.NDArray[np.uint8],
]: ...
def radar_slant_extent(
    dem: npt.NDArray[np.float64], dx: float, incidence: float, n_threads: Optional[int] = None
) -> Tuple[float, float]: ...
# ---- radiometry ----

def radiometry_intersect(
    dem: npt.NDArray[np.float64],
    cell_size: Tuple[float, float],
    periodic: bool,
    split: str,
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    skip: Optional[npt.NDArray[np.int64]] = None,
    n_threads: Optional[int] = None,
) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.float64]]: ...
def radiometry_occluded(
    dem: npt.NDArray[np.float64],
    cell_size: Tuple[float, float],
    periodic: bool,
    split: str,
    origins: npt.NDArray[np.float64],
    directions: npt.NDArray[np.float64],
    skip: Optional[npt.NDArray[np.int64]] = None,
    n_threads: Optional[int] = None,
) -> npt.NDArray[np.bool_]: ...

@final
class RadiometryScene:
    @staticmethod
    def from_mesh(
        mesh: _MeshLike,
        materials: Sequence[Tuple[str, Sequence[float]]],
        material_ids: Optional[npt.NDArray[np.uint32]],
        periodic: bool,
        extent: Optional[Tuple[float, float, float, float]] = None,
    ) -> RadiometryScene: ...
    @staticmethod
    def from_instances(
        shapes: Sequence[_MeshLike],
        instance_shapes: npt.NDArray[np.uint32],
        transforms: npt.NDArray[np.float64],
        materials: Sequence[Tuple[str, Sequence[float]]],
        material_ids: Optional[npt.NDArray[np.uint32]],
        periodic: bool,
        extent: Tuple[float, float, float, float],
    ) -> RadiometryScene: ...
    @staticmethod
    def from_dem(
        dem: npt.NDArray[np.float64],
        cell_size: Tuple[float, float],
        periodic: bool,
        split: str,
        materials: Sequence[Tuple[str, Sequence[float]]],
        material_ids: Optional[npt.NDArray[np.uint32]],
    ) -> RadiometryScene: ...
    def brf(
        self,
        sun: Tuple[float, float],
        view: Tuple[float, float],
        spp: int,
        max_depth: int,
        seed: int,
        n_threads: Optional[int] = None,
    ) -> Tuple[float, float, int]: ...
    def albedo(
        self, sun: Tuple[float, float], spp: int, max_depth: int, seed: int, n_threads: Optional[int] = None
    ) -> Tuple[float, float, int]: ...
    def gap_fraction(
        self, sun: Tuple[float, float], ground: int, n: int, seed: int, n_threads: Optional[int] = None
    ) -> Tuple[float, float, int]: ...
    def absorption(
        self, sun: Tuple[float, float], spp: int, max_depth: int, seed: int, n_threads: Optional[int] = None
    ) -> Tuple[List[Tuple[float, float]], Tuple[float, float], Tuple[float, float], int]: ...
    def brf_sky(
        self,
        sun: Tuple[float, float],
        view: Tuple[float, float],
        sky: float,
        spp: int,
        max_depth: int,
        seed: int,
        n_threads: Optional[int] = None,
    ) -> Tuple[float, float, int]: ...
    def brf_orders(
        self,
        sun: Tuple[float, float],
        view: Tuple[float, float],
        sky: float,
        spp: int,
        max_depth: int,
        seed: int,
        n_threads: Optional[int] = None,
    ) -> Tuple[Tuple[float, float], Tuple[float, float], Tuple[float, float], int]: ...
    def bhr(
        self, spp: int, max_depth: int, seed: int, n_threads: Optional[int] = None
    ) -> Tuple[float, float, int]: ...
    def render_series(
        self,
        suns: Sequence[Tuple[float, float]],
        view: Tuple[float, float],
        sky: float,
        shape: Tuple[int, int],
        spp: int,
        max_depth: int,
        seed: int,
        psf: str,
        psf_params: Sequence[float],
        psf_table: Optional[npt.NDArray[np.float64]] = None,
        n_threads: Optional[int] = None,
        progress: Optional[ProgressCounter] = None,
    ) -> npt.NDArray[np.float32]: ...
    def render_perspective(
        self,
        sun: Tuple[float, float],
        sky: float,
        eye: Tuple[float, float, float],
        target: Tuple[float, float, float],
        fov: float,
        shape: Tuple[int, int],
        spp: int,
        max_depth: int,
        seed: int,
        n_threads: Optional[int] = None,
        progress: Optional[ProgressCounter] = None,
    ) -> npt.NDArray[np.float32]: ...
    def facets(self) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def footprint(self) -> Tuple[float, float, float, float]: ...
