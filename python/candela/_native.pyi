"""Type stubs of candela's native module (PyO3)."""

import os
from typing import Callable, Optional, Tuple, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "CandelaError",
    "Render",
    "Scene",
    "SceneError",
    "StateError",
    "load",
    "merge_states",
    "scene_files",
    "state_info",
    "__version__",
]

__version__: str

_Crop = Tuple[float, float, float, float]
"""(x0, x1, y0, y1): fractions of the film, 0 ≤ x0 < x1 ≤ 1, 0 ≤ y0 < y1 ≤ 1 (the CLI's --cropwindow)."""

_PassRange = Union[range, Tuple[int, int]]
"""Passes a ≤ i < b: range(a, b) (step 1) or (a, b)."""

_ProgressFn = Callable[[int, int, float], object]
"""progress(passes_done, passes_total, seconds)."""

class CandelaError(Exception):
    """Base class of candela's errors."""

class SceneError(CandelaError):
    """A scene that cannot be read or built; str(e) is "file:line:col: what"."""

    file: Optional[str]
    """The file of the problem (None if it has no place)."""
    line: int
    """1-based line, 0 if unknown."""
    col: int
    """1-based column, 0 if unknown."""

class StateError(CandelaError):
    """Render-state bytes that cannot be read, or states that cannot be merged."""

def load(
    path: Union[str, os.PathLike[str]],
    *,
    spp: Optional[int] = None,
    integrator: Optional[str] = None,
    seed: Optional[int] = None,
    crop: Optional[_Crop] = None,
) -> Scene:
    """Parses and builds a pbrt-v4 scene (GIL released), with the overrides it
    will be rendered with; raises SceneError with file:line:col."""

def scene_files(path: Union[str, os.PathLike[str]]) -> list[str]:
    """Every file the scene reads (scene files, PLY, images, IES, spectra), from a
    parse only; SceneError for a parse error or an absolute path to a file."""

def merge_states(a: bytes, b: bytes) -> bytes:
    """The bytes of two states (disjoint passes of one render) merged; no scene needed."""

def state_info(data: bytes) -> dict:
    """fingerprint, integrator, total_passes, passes, pass_count, settings of a state."""

@final
class Scene:
    """A parsed and built scene (candela.load)."""

    @property
    def path(self) -> str:
        """The scene file as given to load."""
    def files(self) -> list[str]:
        """Every file the scene reads, sorted."""
    def info(
        self,
        *,
        spp: Optional[int] = None,
        integrator: Optional[str] = None,
        seed: Optional[int] = None,
        crop: Optional[_Crop] = None,
    ) -> dict:
        """camera, film, sampler, integrator, shapes, primitives, triangles, lights,
        materials, textures, instances, bounds, warnings, resolution (w, h), passes,
        integrator_name, independent_passes, fingerprint."""
    def render(
        self,
        *,
        spp: Optional[int] = None,
        integrator: Optional[str] = None,
        seed: Optional[int] = None,
        crop: Optional[_Crop] = None,
        passes: Optional[_PassRange] = None,
        threads: Optional[int] = None,
        progress: Optional[_ProgressFn] = None,
    ) -> Render:
        """Renders `passes` (default: all `spp` of them) with the GIL released;
        Ctrl-C stops it and raises KeyboardInterrupt. `threads` does not change the bytes."""

@final
class Render:
    """Some passes of a render: exact fixed-point sums plus the setup that develops them."""

    @staticmethod
    def from_bytes(scene: Scene, data: bytes) -> Render:
        """A render from its state bytes (to_bytes, or a .cndl file), checked against scene."""
    def to_bytes(self) -> bytes:
        """The state as the bytes of a .cndl file (candela merge reads it)."""
    def merge(self, other: Render) -> Render:
        """This render and other (disjoint passes) merged exactly, as a new Render."""
    def exr_bytes(self) -> bytes:
        """The EXR `candela render` writes for these passes."""
    def save(self, path: Union[str, os.PathLike[str]]) -> None:
        """Writes the EXR atomically."""
    @property
    def layers(self) -> dict[str, npt.NDArray[np.float32]]:
        """Layers by name ("main" is the root layer): arrays of shape (height, width, channels)."""
    @property
    def channels(self) -> dict[str, Tuple[str, ...]]:
        """Channel names of each layer, in the order of the arrays' last axis."""
    @property
    def size(self) -> Tuple[int, int]:
        """(width, height)."""
    @property
    def passes(self) -> list[Tuple[int, int]]:
        """Passes held, as (a, b) ranges."""
    @property
    def pass_count(self) -> int: ...
    @property
    def total_passes(self) -> int:
        """Passes the render was planned with (spp)."""
    @property
    def integrator(self) -> str: ...
    @property
    def fingerprint(self) -> int:
        """Hash of the scene's files and the settings that decide the passes."""
    @property
    def settings(self) -> str:
        """The overrides stored with the state, as key=value lines."""

