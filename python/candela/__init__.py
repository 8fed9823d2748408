"""candela: a spectral renderer for pbrt-v4 scenes, as a Python module.

    import candela
    scene = candela.load("scenes/cornell-box/scene.pbrt")   # SceneError: file:line:col
    print(scene.info()["resolution"])
    a = scene.render(spp=64, passes=range(0, 32))
    b = scene.render(spp=64, passes=range(32, 64))
    image = a.merge(b)                  # exactly one render of passes 0..64
    rgb = image.layers["main"]          # numpy float32, (height, width, 3)
    image.save("out.exr")               # the bytes `candela render` writes

Renders release the GIL, and Ctrl-C stops them (KeyboardInterrupt).
`candela.farm` renders on a Dask cluster with the same bytes as one process.
`candela.measure` is reserved for photometric measurements (a later issue).
"""

from ._native import (
    CandelaError,
    Render,
    Scene,
    SceneError,
    StateError,
    __version__,
    load,
    merge_states,
    scene_files,
    state_info,
)
from . import archive

__all__ = [
    "archive",
    "CandelaError",
    "Render",
    "Scene",
    "SceneError",
    "StateError",
    "__version__",
    "load",
    "merge_states",
    "scene_files",
    "state_info",
]
