"""Rendering on a Dask cluster, exact to the byte.

    python -m candela.farm SCENE.pbrt --scheduler tcp://HOST:8786 --passes 256 --chunk 8 -o out.exr

or, from Python, ``candela.farm.render(client, "scene.pbrt", passes=256, chunk=8,
output="out.exr")`` with a ``dask.distributed.Client``.

How it works:

1. The client parses the scene (it does not build it) and packs it with
   every file it reads into one archive (``candela.archive``), which is
   scattered to every worker once: no shared filesystem is needed.
2. One task builds the scene on a worker and returns its summary, so a
   scene that cannot be built (a missing PLY) fails at once, with its
   ``file:line:col`` mapped back to the client's paths.
3. Each task renders a pass range ``[a, b)`` and returns the exact state of
   those passes (the bytes of a ``.cndl`` file). A task is a pure function
   of (archive digest, settings, pass range) and its key says so: when a
   worker dies, Dask reruns its tasks elsewhere and gets the same bytes.
4. As partial states arrive they are merged pairwise on the workers (a tree
   reduction in completion order; the sums are integers, so the order does
   not change a bit), and the client holds only futures, never the parts.
5. A last task develops the merged state into the EXR, which is the very
   file ``candela render --spp N`` writes in one process.

Byte-exactness needs every worker to run the same candela build (the same
binary, hence the same libm) as a single-process run; different builds
agree only to rounding.
"""

from __future__ import annotations

import argparse
import dataclasses
import hashlib
import json
import math
import os
import sys
import threading
import time
from typing import Callable, Optional, Union

from . import _native, archive

ProgressFn = Callable[[int, int, float], None]

_scenes: dict = {}
_scenes_lock = threading.Lock()


# --- worker side -------------------------------------------------------------


def _settings_token(digest: str, settings: dict) -> str:
    """A short name for (archive, settings), used in task keys."""
    text = digest + json.dumps(settings, sort_keys=True)
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _scene(data: bytes, digest: str, settings: dict):
    """The worker's Scene for archive ``digest``, unpacked and built once;
    a SceneError is marked with the directory it was unpacked to."""
    with _scenes_lock:
        hit = _scenes.get(digest)
    if hit is not None:
        return hit
    path, root = archive.unpack(data, digest)
    try:
        scene = _native.load(path, **settings)
    except _native.SceneError as e:
        setattr(e, "archive_root", root)  # read back by _localize on the client
        raise
    with _scenes_lock:
        _scenes.setdefault(digest, scene)
        while len(_scenes) > 4:
            _scenes.pop(next(iter(_scenes)))
    return scene


def _task_threads(threads: Optional[int]) -> int:
    """Render threads of one task: ``threads``, else the worker's cores
    shared among its task slots."""
    if threads:
        return threads
    try:
        from distributed import get_worker

        slots = get_worker().state.nthreads
    except (ImportError, ValueError, AttributeError):
        slots = 1
    return max(1, (os.cpu_count() or 1) // max(1, slots))


def check_task(data: bytes, digest: str, settings: dict) -> dict:
    """Builds the scene and returns what the client needs of its summary."""
    info = _scene(data, digest, settings).info(**settings)
    keep = ("passes", "independent_passes", "integrator_name", "resolution", "fingerprint")
    return {k: info[k] for k in keep}


def render_task(data: bytes, digest: str, settings: dict, a: int, b: int, threads=None) -> bytes:
    """The exact state of passes ``[a, b)`` (bytes of a ``.cndl`` file)."""
    scene = _scene(data, digest, settings)
    return scene.render(passes=range(a, b), threads=_task_threads(threads), **settings).to_bytes()


def merge_task(a: bytes, b: bytes) -> bytes:
    """Two partial states merged (disjoint passes)."""
    return _native.merge_states(a, b)


def develop_task(data: bytes, digest: str, settings: dict, state: bytes) -> bytes:
    """The EXR bytes of ``state``."""
    scene = _scene(data, digest, settings)
    return _native.Render.from_bytes(scene, state).exr_bytes()


# --- client side -------------------------------------------------------------


@dataclasses.dataclass
class FarmResult:
    """A finished farm render: the merged state's bytes (``candela merge``
    and ``candela.Render.from_bytes`` read them) and the EXR's bytes."""

    state: bytes
    exr: bytes
    passes: int
    chunks: int
    seconds: float
    archive_bytes: int

    def save(self, path: Union[str, os.PathLike]) -> None:
        """Writes the EXR to ``path`` atomically."""
        _write_atomic(os.fspath(path), self.exr)

    def to_render(self, scene) -> "_native.Render":
        """The result as a ``candela.Render`` of ``scene`` (a local Scene)."""
        return _native.Render.from_bytes(scene, self.state)


def _write_atomic(path: str, data: bytes) -> None:
    tmp = f"{path}.tmp-{os.getpid()}"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def _localize(e: BaseException, root: str) -> BaseException:
    """A worker's SceneError with the worker's unpack directory replaced by
    the directory the client packed from."""
    far = getattr(e, "archive_root", None)
    if not isinstance(e, _native.SceneError) or not far:
        return e
    local = _native.SceneError(str(e).replace(far, root))
    file = getattr(e, "file", None)
    local.file = file.replace(far, root) if file else file
    local.line = getattr(e, "line", 0)
    local.col = getattr(e, "col", 0)
    return local


class _Meter:
    """Passes done of total, with elapsed time and ETA, to a callback or stderr."""

    def __init__(self, total: int, progress: Union[bool, ProgressFn]):
        self.total, self.done, self.t0 = total, 0, time.monotonic()
        self.fn = progress if callable(progress) else (self._print if progress else None)
        self.last_line = 0.0

    def add(self, passes: int) -> None:
        self.done += passes
        if self.fn is not None:
            self.fn(self.done, self.total, time.monotonic() - self.t0)

    def _print(self, done: int, total: int, elapsed: float) -> None:
        tty = sys.stderr.isatty()
        if not tty and done < total and time.monotonic() - self.last_line < 1.0:
            return
        self.last_line = time.monotonic()
        eta = elapsed / done * (total - done) if done else float("nan")
        line = f"candela.farm: {done}/{total} passes, {elapsed:.1f} s, ETA {eta:.1f} s"
        end = "\n" if done >= total or not tty else ""
        print(("\r" if tty else "") + line, end=end, file=sys.stderr, flush=True)


def _chunks(total: int, chunk: int) -> list:
    return [(a, min(a + chunk, total)) for a in range(0, total, chunk)]


def _default_chunk(client, total: int) -> int:
    """About four tasks per task slot of the cluster."""
    workers = client.scheduler_info().get("workers", {})
    slots = sum(w.get("nthreads", 1) for w in workers.values()) or 1
    return max(1, math.ceil(total / (4 * slots)))


def render(
    client,
    scene: Union[str, os.PathLike],
    *,
    passes: Optional[int] = None,
    chunk: Optional[int] = None,
    integrator: Optional[str] = None,
    seed: Optional[int] = None,
    crop: Optional[tuple] = None,
    threads: Optional[int] = None,
    output: Union[str, os.PathLike, None] = None,
    progress: Union[bool, ProgressFn] = True,
) -> FarmResult:
    """Renders ``scene`` on the cluster of ``client`` (a
    ``dask.distributed.Client``): ``passes`` passes (the scene's own count
    if None; the CLI's ``--spp``) in tasks of ``chunk`` passes (default:
    about four per task slot), with the CLI's ``integrator``, ``seed`` and
    ``crop`` overrides, ``threads`` render threads per task (default: the
    worker's cores over its task slots). Writes the EXR to ``output`` if
    given. ``progress`` is True (a line on stderr), False, or a callable
    ``(passes_done, passes_total, seconds)``. Raises candela.SceneError
    (with the client's paths) for a scene that cannot be read or built."""
    if chunk is not None and chunk < 1:
        raise ValueError("chunk must be at least 1")
    t0 = time.monotonic()
    packed = archive.pack(scene)
    settings = {"spp": passes, "integrator": integrator, "seed": seed,
                "crop": tuple(crop) if crop is not None else None}
    token = _settings_token(packed.digest, settings)
    [data] = client.scatter([packed.data], broadcast=True, hash=True)
    futures: list = []
    try:
        check = client.submit(check_task, data, packed.digest, settings, key=f"candela-check-{token}")
        futures.append(check)
        try:
            info = check.result()
        except _native.SceneError as e:
            raise _localize(e, packed.root) from None
        total = info["passes"]
        step = chunk or _default_chunk(client, total)
        if not info["independent_passes"]:
            step = total  # SPPM: its passes depend on each other, one task renders them all
        ranges = _chunks(total, step)
        state = _reduce(client, data, packed, settings, token, ranges, threads,
                        _Meter(total, progress), futures)
        exr = client.submit(develop_task, data, packed.digest, settings, state,
                            key=f"candela-develop-{token}")
        futures.append(exr)
        result = FarmResult(state=state.result(), exr=exr.result(), passes=total,
                            chunks=len(ranges), seconds=time.monotonic() - t0,
                            archive_bytes=len(packed.data))
    except BaseException:
        # Ctrl-C or an error: drop every task (running ones end their chunk).
        client.cancel(futures)
        raise
    if output is not None:
        result.save(output)
    return result


def _reduce(client, data, packed, settings, token, ranges, threads, meter, futures):
    """Submits the pass ranges and merges their states pairwise as they
    finish; returns the future of the merged state."""
    from distributed import as_completed

    sizes = {}
    for a, b in ranges:
        f = client.submit(render_task, data, packed.digest, settings, a, b, threads,
                          key=f"candela-passes-{token}-{a}-{b}")
        sizes[f.key] = b - a
        futures.append(f)
    waiting = []
    queue = as_completed(list(futures[-len(ranges):]))
    for f in queue:
        if f.status == "error":
            try:
                f.result()
            except _native.SceneError as e:
                raise _localize(e, packed.root) from None
        if f.key in sizes:
            meter.add(sizes.pop(f.key))
        waiting.append(f)
        if len(waiting) >= 2:
            x, y = waiting.pop(0), waiting.pop(0)
            pair = "-".join(sorted([x.key, y.key]))
            key = "candela-merge-" + hashlib.sha256(pair.encode()).hexdigest()[:24]
            m = client.submit(merge_task, x, y, key=key)
            futures.append(m)
            queue.add(m)
    [final] = waiting
    return final


# --- command line ------------------------------------------------------------


def _crop(text: str) -> tuple:
    try:
        v = tuple(float(t) for t in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError("expected x0,x1,y0,y1") from None
    if len(v) != 4:
        raise argparse.ArgumentTypeError("expected x0,x1,y0,y1")
    return v


def main(argv: Optional[list] = None) -> int:
    """``python -m candela.farm``; returns the exit code."""
    p = argparse.ArgumentParser(
        prog="python -m candela.farm",
        description="Render a pbrt-v4 scene on a Dask cluster; the EXR equals a one-process render byte for byte.",
    )
    p.add_argument("scene", help="scene file (.pbrt)")
    where = p.add_mutually_exclusive_group(required=True)
    where.add_argument("--scheduler", help="address of the Dask scheduler, tcp://HOST:PORT")
    where.add_argument("--local", type=int, metavar="N", help="start a local cluster of N workers instead")
    p.add_argument("--passes", type=int, help="passes to render (the CLI's --spp; default: the scene's)")
    p.add_argument("--chunk", type=int, help="passes per task (default: about 4 tasks per task slot)")
    p.add_argument("-o", "--outfile", required=True, help="output EXR")
    p.add_argument("--state", help="also write the merged state (.cndl) here")
    p.add_argument("--integrator")
    p.add_argument("--seed", type=int)
    p.add_argument("--crop", type=_crop, help="x0,x1,y0,y1 in [0, 1] (the CLI's --cropwindow)")
    p.add_argument("--threads", type=int, help="render threads per task")
    p.add_argument("--quiet", action="store_true")
    args = p.parse_args(argv)
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=args.local, threads_per_worker=1) if args.local else None
    client = Client(cluster if cluster is not None else args.scheduler)
    try:
        r = render(client, args.scene, passes=args.passes, chunk=args.chunk,
                   integrator=args.integrator, seed=args.seed, crop=args.crop,
                   threads=args.threads, output=args.outfile, progress=not args.quiet)
        if args.state:
            _write_atomic(args.state, r.state)
        if not args.quiet:
            print(f"candela.farm: {r.passes} passes in {r.chunks} tasks, {r.seconds:.2f} s; wrote {args.outfile}",
                  file=sys.stderr)
        return 0
    except KeyboardInterrupt:
        print("candela.farm: interrupted", file=sys.stderr)
        return 130
    except (_native.CandelaError, ValueError, OSError) as e:
        print(f"candela.farm: error: {e}", file=sys.stderr)
        return 1
    finally:
        client.close()
        if cluster is not None:
            cluster.close()


if __name__ == "__main__":
    # Run the imported module's main, so tasks name `candela.farm.*` (which
    # workers import) and not functions of `__main__`.
    from candela import farm as _farm

    sys.exit(_farm.main())
