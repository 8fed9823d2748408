"""Scene archives: deterministic bytes, a faithful unpack, and refusal of
damaged or hostile archives."""

import gzip
import io
import json
import tarfile

import pytest

import candela
from candela import archive
from conftest import make_multifile_scene


def test_packing_twice_gives_the_same_bytes_and_unpacking_the_same_files(tmp_path):
    path, files = make_multifile_scene(tmp_path)
    a, b = archive.pack(path), archive.pack(path)
    assert a.data == b.data and a.digest == b.digest
    assert a.scene == "scene/scene.pbrt" and a.root == str(tmp_path)
    scene, root = archive.unpack(a.data, a.digest, root=str(tmp_path / "out"))
    for f in files:
        rel = f.relative_to(tmp_path)
        assert (tmp_path / "out" / a.digest / rel).read_bytes() == f.read_bytes()
    assert scene == str(tmp_path / "out" / a.digest / "scene" / "scene.pbrt")
    # Unpacked elsewhere, the scene renders to the same bytes as at home.
    here = candela.load(path).render(spp=2)
    there = candela.load(scene).render(spp=2)
    assert here.exr_bytes() == there.exr_bytes()
    assert here.fingerprint == there.fingerprint
    # A second unpack reuses the first.
    assert archive.unpack(a.data, a.digest, root=str(tmp_path / "out")) == (scene, root)


def test_a_changed_file_changes_the_digest(tmp_path):
    path, _ = make_multifile_scene(tmp_path)
    before = archive.pack(path).digest
    (tmp_path / "scene" / "refl.spd").write_text("400 0.3\n700 0.3\n")
    assert archive.pack(path).digest != before


def _tar(members: dict) -> bytes:
    raw = io.BytesIO()
    with tarfile.open(fileobj=raw, mode="w") as tar:
        for name, data in members.items():
            info = tarfile.TarInfo(name)
            info.size = len(data)
            tar.addfile(info, io.BytesIO(data))
    return gzip.compress(raw.getvalue())


def test_damaged_and_hostile_archives_are_refused(tmp_path):
    path, _ = make_multifile_scene(tmp_path)
    good = archive.pack(path)
    out = str(tmp_path / "out")
    with pytest.raises(ValueError, match="digest"):
        archive.unpack(good.data[:-1] + b"x", good.digest, root=out)
    import hashlib

    def packed(members):
        data = _tar(members)
        return data, hashlib.sha256(data).hexdigest()

    escape = b"x"
    manifest = {"format": 1, "scene": "s.pbrt",
                "files": {"../evil": hashlib.sha256(escape).hexdigest()}}
    data, digest = packed({archive.MANIFEST: json.dumps(manifest).encode(), "files/../evil": escape})
    with pytest.raises(ValueError, match="unsafe"):
        archive.unpack(data, digest, root=out)
    assert not (tmp_path / "evil").exists()
    manifest = {"format": 1, "scene": "s.pbrt", "files": {"s.pbrt": "0" * 64}}
    data, digest = packed({archive.MANIFEST: json.dumps(manifest).encode(), "files/s.pbrt": b"Shape"})
    with pytest.raises(ValueError, match="hash"):
        archive.unpack(data, digest, root=out)
    data, digest = packed({"files/s.pbrt": b""})
    with pytest.raises(ValueError, match="manifest"):
        archive.unpack(data, digest, root=out)
