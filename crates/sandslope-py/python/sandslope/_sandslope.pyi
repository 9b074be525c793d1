"""Type stubs of the compiled core (Rust, PyO3). Use the functions of ``sandslope``; the
classes ``Robot`` and ``Terrain`` are re-exported there."""

import os
from typing import Any, Dict, List, Optional, Tuple, Union

import numpy as np
import numpy.typing as npt
from typing_extensions import Unpack

from ._walk import WalkSettings

_Path = Union[str, "os.PathLike[str]"]
_F64 = npt.NDArray[np.float64]

REGIMES: Tuple[str, str, str, str]
OUTCOMES: Tuple[str, str, str, str]
CAUSES: Tuple[str, ...]
DEFAULT_MAX_RISK: float
DEFAULT_MAX_ROLL_DEG: float

class Robot:
    """A legged robot (docs/model.md §2), validated when built.

    Keys: ``mass_kg`` (m, kg), ``leg_radius_m`` (C-leg radius R), ``leg_width_m`` (W),
    ``hip_height_m`` (h, 0 <= h <= 2R), ``leg_speed_rad_s`` (omega), ``stance_legs`` (n),
    ``response_time_s`` (dt); optional ``leg_contact_area_m2`` (A_c, default W R),
    ``level_step_m`` (measured s*), ``min_step_m`` (s_min, default R).
    """

    def __init__(self, **keys: Any) -> None: ...
    @staticmethod
    def from_toml(path: _Path) -> "Robot":
        """The robot of a TOML file; ``ValueError`` names the file, key and valid range."""
    @staticmethod
    def load(file_or_preset: _Path) -> "Robot":
        """A TOML file or a built-in robot's name, as the CLI's ``--robot FILE|PRESET``."""
    @staticmethod
    def preset(name: str) -> "Robot":
        """A built-in robot, e.g. ``"paper-hexapod"``."""
    def with_mass(self, mass_kg: float) -> "Robot":
        """The same robot with another total mass, kg."""
    def to_dict(self) -> Dict[str, Any]:
        """The keys of docs/model.md §2 (optional keys only when given)."""
    @property
    def mass_kg(self) -> float:
        """Total mass m, kg."""
    @property
    def max_depth_m(self) -> float:
        """Leg reach below the surface ``d_max = 2R - h``, m."""
    @property
    def min_step_m(self) -> float:
        """Step for robust progress s_min, m."""
    def __eq__(self, other: object) -> bool: ...
    def __reduce__(self) -> Tuple[Any, ...]: ...

class Terrain:
    """A terrain table (docs/model.md §7): k_n and k_s (N/m^3, optional SDs) at measured
    slopes, interpolated linearly in degrees, held below the first point, extrapolated and
    floored at 0 above the last; optional angle of repose (at or above it: slippage)."""

    def __init__(
        self, points: List[Dict[str, float]], repose_deg: Optional[float] = None, name: Optional[str] = None
    ) -> None: ...
    @staticmethod
    def from_toml(path: _Path) -> "Terrain":
        """The terrain of a TOML file; ``ValueError`` names the file, key and valid range."""
    @staticmethod
    def load(file_or_preset: _Path) -> "Terrain":
        """A TOML file or a built-in terrain's name, as the CLI's ``--terrain FILE|PRESET``."""
    @staticmethod
    def preset(name: str) -> "Terrain":
        """A built-in terrain, e.g. ``"glass-beads-300um"``."""
    @staticmethod
    def constant(k_n: float, k_s: float) -> "Terrain":
        """The same k_n and k_s (N/m^3) at every slope."""
    def to_dict(self) -> Dict[str, Any]:
        """``{"name", "repose_deg", "points"}`` (points sorted by slope)."""
    def at(self, slope_deg: float) -> Dict[str, Any]:
        """k_n, k_s, k_n_sd, k_s_sd (None when absent) and ``extrapolated`` at one slope."""
    @property
    def name(self) -> Optional[str]: ...
    @property
    def repose_deg(self) -> Optional[float]: ...
    def __eq__(self, other: object) -> bool: ...
    def __reduce__(self) -> Tuple[Any, ...]: ...

def preset_names() -> List[Tuple[str, str, str]]: ...
def predict(
    robot: Robot,
    slope_deg: _F64,
    k_n: Optional[_F64] = None,
    k_s: Optional[_F64] = None,
    terrain: Optional[Terrain] = None,
    mass_kg: Optional[_F64] = None,
) -> Dict[str, np.ndarray]: ...
def phase(
    robot: Robot,
    slope_deg: float,
    k_n_axis: _F64,
    k_s_axis: _F64,
    terrain: Optional[Terrain] = None,
    repose_deg: Optional[float] = None,
    regime_only: bool = False,
) -> Dict[str, Any]: ...
def risk(
    robot: Robot, slope_deg: _F64, terrain: Terrain, cv_n: Optional[float] = None, cv_s: Optional[float] = None
) -> Dict[str, Any]: ...
def risk_map(
    robot: Robot,
    slope_deg: float,
    k_n_axis: Optional[_F64],
    k_s_axis: Optional[_F64],
    terrain: Terrain,
    max_risk: float = 0.05,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]: ...
def safe_slope(
    robot: Robot, terrain: Terrain, max_risk: float = 0.05, cv_n: Optional[float] = None, cv_s: Optional[float] = None
) -> Dict[str, Any]: ...
def safe_mass(
    robot: Robot,
    slope_deg: float,
    terrain: Terrain,
    max_risk: float = 0.05,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]: ...
def payload_envelope(
    robot: Robot,
    slope_deg: _F64,
    terrain: Terrain,
    max_risk: float = 0.05,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
) -> Dict[str, Any]: ...
def risk_raster(
    dem: _F64,
    cell_x: float,
    cell_y: float,
    robot: Robot,
    terrain: Terrain,
    nodata: Optional[float] = None,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = 20.0,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    row_widths_m: Optional[List[float]] = None,
) -> npt.NDArray[np.float32]: ...
def plan(
    dem: _F64,
    cell_x: float,
    cell_y: float,
    robot: Robot,
    terrain: Terrain,
    start: Tuple[int, int],
    goal: Tuple[int, int],
    objectives: List[str],
    origin: Optional[Tuple[float, float]],
    nodata: Optional[float] = None,
    cv_n: Optional[float] = None,
    cv_s: Optional[float] = None,
    max_roll_deg: float = 20.0,
    descent: str = "symmetric",
    allow_metastable: bool = False,
    time_weight: float = 1e-4,
    classes: Optional[_F64] = None,
    class_terrains: Optional[List[Tuple[int, Terrain]]] = None,
    row_widths_m: Optional[List[float]] = None,
) -> Dict[str, Any]: ...
def read_raster(path: _Path) -> Tuple[_F64, int, int, Dict[str, float]]: ...
def geotiff_nodata(path: _Path) -> Optional[float]:
    """The GDAL_NODATA value of a GeoTIFF (None when it has none), read from its tags only."""
def pds3_info(path: _Path) -> Dict[str, Any]:
    """A PDS3 DTM's ``{rows, cols, cell_x_m, cell_y_m, row_widths_m, notes}`` from its label alone."""
def pds3_window(path: _Path, top: int, bottom: int, left: int, right: int) -> np.ndarray:
    """Rows ``top:bottom``, columns ``left:right`` of a PDS3 DTM (metres, NaN where missing)."""
def fit(
    manifest: _Path,
    depth_window: Optional[Tuple[float, float]] = None,
    plateau_from: Optional[float] = None,
    air: str = "auto",
    counts_per_newton: Optional[float] = None,
    skip_malformed: bool = False,
) -> Dict[str, Any]: ...
def track(
    paths: List[_Path],
    robot: Robot,
    slope_deg: Optional[float] = None,
    format: Optional[str] = None,
    body: Optional[str] = None,
    upslope: Optional[List[float]] = None,
    max_gap: int = 10,
    cutoff_hz: float = 10.0,
    leg_speed_rad_s: Optional[float] = None,
    touchdowns: Optional[List[List[float]]] = None,
    topic: Optional[str] = None,
    frame: Optional[str] = None,
) -> Dict[str, Any]: ...
def calibrate(
    robot: Robot,
    terrain: Terrain,
    terrain_source: str,
    observed: Optional[_Path] = None,
    forces: Optional[str] = None,
    t1: Optional[_Path] = None,
    free: List[str] = ...,
    error_floor: Optional[float] = None,
    law: str = "linear",
    model: str = "closed-form",
    k_n: Optional[float] = None,
    name: Optional[str] = None,
    repose: Optional[float] = None,
) -> str: ...
def report(
    robot: Robot,
    terrain: Terrain,
    robot_source: str,
    terrain_source: str,
    observed: Optional[_Path] = None,
    forces: Optional[str] = None,
    t1: Optional[_Path] = None,
    tracks: Optional[List[Tuple[float, List[_Path]]]] = None,
    tracks_format: Optional[str] = None,
    tracks_body: Optional[str] = None,
    tracks_upslope: Optional[List[float]] = None,
    max_risk: float = 0.05,
    simulator_fit: bool = False,
    html: Optional[_Path] = None,
) -> str: ...
def walk_keyword_defaults() -> List[Tuple[str, Optional[str]]]: ...
def request_keywords(command: str) -> List[Tuple[str, Optional[str], str]]: ...
def simulate(
    robot: Robot,
    terrain: Terrain,
    slope_deg: float,
    duration_s: float,
    scaling_spread: bool = True,
    **keywords: Unpack[WalkSettings],
) -> Tuple[Dict[str, np.ndarray], Dict[str, Any]]: ...
def simulate_ensemble(
    robot: Robot,
    terrain: Terrain,
    slope_deg: float,
    duration_s: float,
    walks: int,
    **keywords: Unpack[WalkSettings],
) -> Dict[str, Any]: ...
def check_convergence(
    robot: Robot,
    terrain: Terrain,
    slope_deg: Union[float, List[float]],
    duration_s: float,
    walks: Optional[int] = None,
    **keywords: Unpack[WalkSettings],
) -> Union[Dict[str, Any], List[Dict[str, Any]]]: ...
def read_servo_log(path: _Path) -> Tuple[Dict[str, np.ndarray], Dict[str, str], List[str]]: ...
def infer_servo_log(
    robot: Robot,
    terrain: Terrain,
    slope_deg: float,
    leg: np.ndarray,
    leg_angle_rad: np.ndarray,
    drive_torque_n_m: np.ndarray,
    k_s_prior: Optional[Tuple[float, float]] = None,
    grid_points: Optional[int] = None,
) -> Dict[str, Any]: ...
def infer_servo_log_file(
    robot: Robot,
    terrain: Terrain,
    path: _Path,
    slope_deg: Optional[float] = None,
    k_s_prior: Optional[Tuple[float, float]] = None,
    grid_points: Optional[int] = None,
) -> Tuple[Dict[str, Any], List[str]]: ...
def drive_defaults() -> Dict[str, Any]: ...
def drive(
    robot: Robot,
    terrain: Terrain,
    slope_deg: Optional[float] = None,
    duration_s: Optional[float] = None,
    k_s: Optional[float] = None,
    noise_ma: Optional[float] = None,
    seed: Optional[int] = None,
    weaken: Optional[Tuple[float, float]] = None,
    stop_on_risk: Optional[float] = None,
    hold_s: Optional[float] = None,
    rate_hz: Optional[float] = None,
    live: Optional[bool] = None,
    force: Optional[bool] = None,
    window: Optional[int] = None,
    clock: Optional[str] = None,
) -> Tuple[Dict[str, np.ndarray], Dict[str, Any]]: ...

def read_touchdowns(path: _Path) -> List[float]: ...
def bag_topics(path: _Path) -> List[Tuple[str, str, str, int]]: ...
def read_bag_poses(
    path: _Path, topic: Optional[str] = None, frame: Optional[str] = None
) -> Tuple[Dict[str, np.ndarray], str]: ...
def read_bag_joints(
    path: _Path,
    legs: int,
    topic: Optional[str] = None,
    joints: Optional[List[str]] = None,
    effort_unit: str = "n_m",
) -> Tuple[Dict[str, np.ndarray], List[str]]: ...
def read_bag_load_cell(
    path: _Path,
    force_axis: str,
    force_topic: Optional[str] = None,
    position_topic: Optional[str] = None,
    frame: Optional[str] = None,
    position_axis: Optional[str] = None,
) -> Tuple[Dict[str, np.ndarray], str]: ...
