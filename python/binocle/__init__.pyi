# SPDX-License-Identifier: MIT
# Type stubs of the binocle module (python/binocle_module.cpp), for editors and mypy.
import os
from types import TracebackType
from typing import Any, Dict, Iterator, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str
ABI_VERSION: int
API_VERSION: int

# A dict of rig keys to values, or "key=value" texts, as `binocle run --set`.
SetArg = Union[None, Mapping[str, Any], Sequence[str], str]
# A path: a str or a pathlib.Path (bytes are refused).
PathArg = Union[str, "os.PathLike[str]"]

class Error(RuntimeError):
    """An error of Binocle, with the message of the `binocle` command for the same mistake."""

class UsageError(Error, ValueError):
    """A mistake in the call: a `set` key or value, an argument."""

class PluginError(Error):
    """A plugin refused a call or misbehaved; the message names it."""

class Frame:
    """One finished frame of a run; its arrays stay valid as long as they are used."""
    @property
    def index(self) -> int: ...
    @property
    def sequence(self) -> int: ...
    @property
    def left(self) -> npt.NDArray[np.uint8]:
        """Rectified left image: H x W, or H x W x 3 (BGR)."""
    @property
    def right(self) -> npt.NDArray[np.uint8]: ...
    @property
    def disparity(self) -> npt.NDArray[np.float32]:
        """H x W disparity in pixels; invalid pixels <= 0."""
    @property
    def cloud(self) -> npt.NDArray[np.float32]:
        """N x 3 points in mm, in `cloud_frame`."""
    @property
    def colors(self) -> npt.NDArray[np.uint8]:
        """N x 3 (R, G, B) per point, or 0 x 3."""
    @property
    def cloud_frame(self) -> str:
        """'ground' or 'camera'."""
    @property
    def figures(self) -> Dict[str, float]:
        """Every evaluator figure: {'evaluator.metric': value}."""
    @property
    def metrics(self) -> Dict[str, Dict[str, Any]]: ...
    @property
    def valid_pixel_ratio(self) -> float: ...
    @property
    def seconds(self) -> float: ...
    @property
    def latency_s(self) -> float: ...

class Run(Iterator[Frame]):
    """The frames of a run, in order; leaving the loop early stops the run cleanly."""
    def __iter__(self) -> "Run": ...
    def __next__(self) -> Frame: ...
    def close(self) -> None: ...
    def __enter__(self) -> "Run": ...
    def __exit__(self, exc_type: Optional[type], exc: Optional[BaseException], tb: Optional[TracebackType]) -> None: ...
    @property
    def summary(self) -> Optional[Dict[str, Any]]:
        """The run's summary (as summary.json) once it ended; None before."""

class Rig:
    """A rig file, loaded and checked as `binocle run RIG --set KEY=VALUE` does."""
    def __init__(self, file: PathArg, set: SetArg = None) -> None: ...
    def run(self, frames: Optional[int] = None, out: Optional[PathArg] = None, force: bool = False,
            progress: bool = False, queue_depth: int = 4) -> Run: ...
    @property
    def name(self) -> str: ...
    @property
    def file(self) -> str: ...
    @property
    def yaml(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def matcher(self) -> str: ...

def experiment(file: PathArg, set: SetArg = None, out: Optional[PathArg] = None, tests: Sequence[str] = (),
               force: bool = False, progress: bool = False) -> Dict[str, Any]:
    """Runs an experiment file as `binocle experiment`; returns its results.json (rows under 'tests')
    plus 'out', 'failed' and 'seconds'."""

Numbers = Union[str, float, Sequence[float], None]

def design(*, range: Numbers = None, band: Numbers = None, lenses: Numbers = None, baselines: Numbers = None,
           pixel_pitch_um: Optional[float] = None, image_width: Optional[int] = None, image_height: Optional[int] = None,
           num_disparities: Optional[int] = None, camera_height_mm: Optional[float] = None,
           inclination_deg: Optional[float] = None, panel_width_mm: Optional[float] = None,
           panel_height_mm: Optional[float] = None, predictors_from: Optional[PathArg] = None,
           predictor: Optional[str] = None, simulate: bool = False, simulate_count: int = 12,
           rig: Optional[PathArg] = None, out: Optional[PathArg] = None, force: bool = False,
           progress: bool = False) -> List[Dict[str, Any]]:
    """Ranks baselines and lenses as `binocle design` does; returns design.json's candidates, best first."""

def plugins(load: Sequence[str] = (), timeout_ms: int = 5000) -> List[Dict[str, Any]]:
    """The plugins `binocle plugins` lists, with their settings."""

def refused_plugins(load: Sequence[str] = (), timeout_ms: int = 5000) -> List[Dict[str, str]]:
    """The files `binocle plugins` lists as refused, with the reason."""

def plugin_search_path() -> List[str]: ...
def install_prefix() -> str: ...
