"""Shared fixtures: the repository's scenes, the CLI binary, small scenes."""

import os
import shutil
import subprocess
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
CORNELL = REPO / "scenes" / "cornell-box" / "scene.pbrt"
# A quarter of the Cornell box (64×64 pixels around the boxes' corner).
CROP = (0.25, 0.5, 0.5, 0.75)


def cli() -> str:
    """The `candela` binary of this checkout (built by `cargo test --release`)."""
    path = os.environ.get("CANDELA_BIN") or str(REPO / "target" / "release" / "candela")
    if not os.path.exists(path):
        pytest.fail(f"{path} is missing: run `cargo build --release -p candela` (./test.sh does)")
    return path


def run_cli(*args: str) -> subprocess.CompletedProcess:
    """Runs the CLI, failing the test with its stderr if it fails."""
    r = subprocess.run([cli(), *args], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    return r


def cornell_with(tmp_path: Path, integrator: str) -> Path:
    """A copy of the Cornell box whose Integrator directive is `integrator`."""
    lines = CORNELL.read_text().splitlines()
    out = [f"Integrator {integrator}" if ln.startswith("Integrator") else ln for ln in lines]
    assert out != lines, "the Cornell box has an Integrator line"
    path = tmp_path / "cornell" / "scene.pbrt"
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text("\n".join(out) + "\n")
    return path


PPM = '"ppm" "float radius" [0.05] "integer photonsperiteration" [20000] "integer maxdepth" [5]'


@pytest.fixture
def ppm_cornell(tmp_path):
    """The Cornell box rendered by PPM with a radius fit for its size."""
    return cornell_with(tmp_path, PPM)


@pytest.fixture
def scene_dir(tmp_path):
    """An empty directory for a scene; removed afterwards."""
    d = tmp_path / "scene"
    d.mkdir()
    yield d
    shutil.rmtree(d, ignore_errors=True)


def _png(width: int, height: int, rgb) -> bytes:
    """A small 8-bit RGB PNG whose pixels are given by `rgb(x, y)`."""
    import struct
    import zlib

    rows = b"".join(
        b"\0" + b"".join(bytes(rgb(x, y)) for x in range(width)) for y in range(height)
    )

    def chunk(kind: bytes, data: bytes) -> bytes:
        body = kind + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    header = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) + chunk(b"IDAT", zlib.compress(rows)) + chunk(b"IEND", b"")


QUAD_PLY = """ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 2
property list uchar int vertex_indices
end_header
-0.6 0 0.3
0.6 0 0.3
0.6 1.2 0.3
-0.6 1.2 0.3
3 0 1 2
3 0 2 3
"""

MULTI_SCENE = """LookAt 0 1 -4  0 0.5 0  0 1 0
Camera "perspective" "float fov" [40]
Film "rgb" "integer xresolution" [24] "integer yresolution" [16]
Sampler "independent" "integer pixelsamples" [4]
Integrator "path" "integer maxdepth" [3]
WorldBegin
LightSource "infinite" "rgb L" [0.8 0.8 0.8]
# a comment naming "ghost.ply", which is no file
Texture "checks" "spectrum" "imagemap" "string filename" "tex/checks.png"
Material "diffuse" "texture reflectance" "checks"
Include "parts/floor.pbrt"
Material "diffuse" "spectrum reflectance" "refl.spd"
Shape "plymesh" "string filename" "../shared/quad.ply"
"""


def make_multifile_scene(root: Path) -> tuple:
    """A scene under `root/scene` reading an Include, a PNG texture, a
    `.spd` spectrum and a PLY mesh outside its directory
    (`root/shared/quad.ply`); returns (scene path, every file it reads)."""
    d = root / "scene"
    (d / "tex").mkdir(parents=True, exist_ok=True)
    (d / "parts").mkdir(exist_ok=True)
    (root / "shared").mkdir(exist_ok=True)
    (d / "tex" / "checks.png").write_bytes(
        _png(4, 4, lambda x, y: (230, 40, 40) if (x + y) % 2 else (40, 40, 230)))
    (d / "parts" / "floor.pbrt").write_text(
        'Shape "bilinearmesh" "point3 P" [-3 0 -3  3 0 -3  -3 0 3  3 0 3]\n')
    (d / "refl.spd").write_text("# a reflectance\n400 0.2\n500 0.5\n600 0.8\n700 0.6\n")
    (root / "shared" / "quad.ply").write_text(QUAD_PLY)
    (d / "scene.pbrt").write_text(MULTI_SCENE)
    files = [d / "scene.pbrt", d / "parts" / "floor.pbrt", d / "tex" / "checks.png",
             d / "refl.spd", root / "shared" / "quad.ply"]
    return d / "scene.pbrt", files
