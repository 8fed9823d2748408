"""Scene archives: a scene and every file it reads in one deterministic
archive, so that machines without the scene's filesystem can render it.

Format (version 1): a gzip stream (header mtime 0, no file name) of a POSIX
tar whose first member is ``candela-archive.json``::

    {"format": 1, "scene": "cornell-box/scene.pbrt",
     "files": {"cornell-box/scene.pbrt": "<sha256 hex>", ...}}

followed by every file as ``files/<name>``, sorted by name: regular files
only, mode 0644, mtime 0, uid/gid 0, no user or group names. Each name is
relative to the deepest directory that holds the scene file and every file
it reads, so a scene naming ``../textures/wood.png`` unpacks to the same
relative layout and renders (and fingerprints) as it does at home.

The files are those ``candela.scene_files`` finds: the scene files
(includes too) and every file a string parameter names (PLY meshes, images,
IES files, ``.spd`` spectra). An absolute path to a file in the scene is an
error, since the receiving machine would read its own disk.

Equal inputs give equal bytes, and an archive is known by the SHA-256 of
its bytes (``Archive.digest``). ``unpack`` checks that digest and every
file's, refuses names that leave the archive, and unpacks each archive once
per directory (atomically: a temporary directory renamed into place), so
concurrent tasks of one worker share it.
"""

from __future__ import annotations

import dataclasses
import gzip
import hashlib
import io
import json
import os
import posixpath
import shutil
import tarfile
import tempfile
import threading

from . import _native

FORMAT = 1
MANIFEST = "candela-archive.json"
_PREFIX = "files/"
_unpack_lock = threading.Lock()


@dataclasses.dataclass(frozen=True)
class Archive:
    """A packed scene: the archive's bytes, their SHA-256 (hex), the scene
    file's name inside it, and the directory it was packed from."""

    data: bytes
    digest: str
    scene: str
    root: str

    @property
    def files(self) -> list[str]:
        """Names of the packed files (relative to ``root``)."""
        return sorted(read_manifest(self.data)["files"])


def _sha256(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def _member(name: str, data: bytes) -> tuple[tarfile.TarInfo, io.BytesIO]:
    info = tarfile.TarInfo(name)
    info.size = len(data)
    info.mode = 0o644
    info.mtime = 0
    info.uid = info.gid = 0
    info.uname = info.gname = ""
    info.type = tarfile.REGTYPE
    return info, io.BytesIO(data)


def pack(scene_path: str | os.PathLike) -> Archive:
    """Packs the scene at ``scene_path`` and every file it reads (parsing
    the scene, not building it). Raises candela.SceneError if the scene
    does not parse or names a file by an absolute path."""
    scene_abs = os.path.abspath(scene_path)
    paths = [os.path.abspath(p) for p in _native.scene_files(scene_abs)]
    root = os.path.commonpath([os.path.dirname(scene_abs)] + [os.path.dirname(p) for p in paths])
    names = sorted({os.path.relpath(p, root).replace(os.sep, "/"): p for p in paths}.items())
    contents = {}
    for name, path in names:
        with open(path, "rb") as f:
            contents[name] = f.read()
    scene = os.path.relpath(scene_abs, root).replace(os.sep, "/")
    manifest = {
        "format": FORMAT,
        "scene": scene,
        "files": {n: _sha256(d) for n, d in contents.items()},
    }
    raw = io.BytesIO()
    with tarfile.open(fileobj=raw, mode="w", format=tarfile.PAX_FORMAT) as tar:
        tar.addfile(*_member(MANIFEST, json.dumps(manifest, sort_keys=True).encode()))
        for name, data in contents.items():
            tar.addfile(*_member(_PREFIX + name, data))
    out = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=out, mtime=0, compresslevel=6) as z:
        z.write(raw.getvalue())
    data = out.getvalue()
    return Archive(data=data, digest=_sha256(data), scene=scene, root=root)


def _safe_name(name: str) -> str:
    """``name`` if it stays inside the archive's directory, else ValueError."""
    norm = posixpath.normpath(name)
    if name.startswith("/") or norm.startswith("..") or "\\" in name or norm in ("", "."):
        raise ValueError(f"scene archive: unsafe member name {name!r}")
    return norm


def read_manifest(data: bytes) -> dict:
    """The manifest of archive ``data``."""
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        first = tar.next()
        if first is None or first.name != MANIFEST:
            raise ValueError("not a candela scene archive (no manifest first)")
        extracted = tar.extractfile(first)
        if extracted is None:
            raise ValueError("scene archive: the manifest is not a file")
        manifest = json.loads(extracted.read())
    if manifest.get("format") != FORMAT:
        raise ValueError(f"scene archive format {manifest.get('format')!r}, expected {FORMAT}")
    return manifest


def _extract(data: bytes, into: str) -> dict:
    """Writes the files of archive ``data`` under ``into``, checking names and hashes."""
    manifest = read_manifest(data)
    expected = manifest["files"]
    seen = set()
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:gz") as tar:
        for m in tar:
            if m.name == MANIFEST:
                continue
            if not m.isreg() or not m.name.startswith(_PREFIX):
                raise ValueError(f"scene archive: unexpected member {m.name!r}")
            name = _safe_name(m.name[len(_PREFIX):])
            f = tar.extractfile(m)
            content = f.read() if f is not None else b""
            if expected.get(name) != _sha256(content):
                raise ValueError(f"scene archive: {name} does not match its manifest hash")
            dest = os.path.join(into, *name.split("/"))
            os.makedirs(os.path.dirname(dest), exist_ok=True)
            with open(dest, "wb") as out:
                out.write(content)
            seen.add(name)
    if seen != set(expected):
        raise ValueError("scene archive: files listed in the manifest are missing")
    return manifest


def unpack(data: bytes, digest: str, root: str | None = None) -> tuple[str, str]:
    """Unpacks archive ``data`` (whose SHA-256 must be ``digest``) under
    ``root`` (default: the temporary directory), once; returns the scene
    file's path and the directory the archive's names are relative to."""
    if _sha256(data) != digest:
        raise ValueError("scene archive: the bytes do not match their digest")
    base = root or os.path.join(tempfile.gettempdir(), f"candela-farm-{getattr(os, 'getuid', lambda: 0)()}")
    final = os.path.join(base, digest)
    with _unpack_lock:
        if not os.path.isdir(final):
            os.makedirs(base, exist_ok=True)
            tmp = tempfile.mkdtemp(prefix=f".{digest[:16]}-", dir=base)
            try:
                _extract(data, tmp)
                os.rename(tmp, final)
            except OSError:
                # Another process unpacked the same archive first.
                shutil.rmtree(tmp, ignore_errors=True)
                if not os.path.isdir(final):
                    raise
            except BaseException:
                shutil.rmtree(tmp, ignore_errors=True)
                raise
    manifest = read_manifest(data)
    scene = os.path.join(final, *_safe_name(manifest["scene"]).split("/"))
    return scene, final
