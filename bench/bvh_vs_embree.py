#!/usr/bin/env python3
"""Ray casting throughput of candela's BVH against Embree 4 on the same mesh
and the same rays, measured interleaved in one run.

    python3 bench/bvh_vs_embree.py [--rounds 5]

One command from a fresh clone: it installs `embreex` (Embree 4's Python
binding) and numpy from PyPI if they are missing, builds and starts the
`bvh_peer` example of candela-core (the criterion bench's 1,036,800-triangle
displaced sphere and its 2^20 incoherent rays: origins uniform in the mesh's
bounds, directions uniform on the sphere), which writes the mesh and rays to
`bench/out/bvh/` and answers timing requests on stdin. Embree builds its
scene from those files and traces the same rays (`tnear` 0, `tfar` 1e37).

Each round times, for closest hit (`rtcIntersect1`) and any hit
(`rtcOccluded1`) on 1 and 2 threads, candela then Embree (A B A B ...); the
medians over rounds are printed with the ratio candela / Embree. Embree's
binding holds the GIL per call, so Embree's two threads are two worker
processes with a scene each, each tracing half the rays; the wall time of both
is what counts. Both sides include their per-ray call overhead (Cython loop
for Embree). Other processes on the machine skew both sides alike, since the
runs alternate; still, say how loaded the machine was when quoting numbers.
"""
import argparse, multiprocessing as mp, os, statistics, subprocess, sys, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "bench", "out", "bvh")
PEER = os.path.join(ROOT, "target", "release", "examples", "bvh_peer")


def ensure_modules():
    for module, package in (("numpy", "numpy"), ("embreex", "embreex")):
        try:
            __import__(module)
        except ImportError:
            print(f"installing {package} from PyPI ...", file=sys.stderr)
            subprocess.check_call([sys.executable, "-m", "pip", "install", "-q", package])


def load(out):
    import numpy as np
    v = np.fromfile(os.path.join(out, "vertices.f32"), dtype="<f4").reshape(-1, 3)
    f = np.fromfile(os.path.join(out, "triangles.u32"), dtype="<u4").astype(np.int32).reshape(-1, 3)
    r = np.fromfile(os.path.join(out, "rays.f32"), dtype="<f4").reshape(-1, 6)
    return v, f, np.ascontiguousarray(r[:, :3]), np.ascontiguousarray(r[:, 3:])


def embree_worker(out, part, parts, requests, replies):
    """Builds an Embree scene and traces its share of the rays on request."""
    import numpy as np
    from embreex.rtcore_scene import EmbreeScene
    from embreex.mesh_construction import TriangleMesh
    v, f, o, d = load(out)
    n = len(o)
    o, d = o[part * n // parts:(part + 1) * n // parts], d[part * n // parts:(part + 1) * n // parts]
    scene = EmbreeScene()
    TriangleMesh(scene, v, f)
    t0 = time.perf_counter()
    scene.run(o[:1], d[:1])  # The first query commits (builds) the scene.
    replies.put(("built", time.perf_counter() - t0, 0))
    while True:
        query = requests.get()
        if query is None:
            return
        t0 = time.perf_counter()
        res = scene.run(o, d, query=query)
        replies.put((query, time.perf_counter() - t0, int(np.count_nonzero(res >= 0))))


class Embree:
    """Persistent Embree worker processes, so timing excludes start-up and build."""

    def __init__(self, out, workers=2):
        ctx = mp.get_context("spawn")
        self.requests = [ctx.Queue() for _ in range(workers)]
        self.replies = ctx.Queue()
        self.workers = {}
        for threads in (1, 2):
            # One process for the single-thread runs, two for the two-thread runs.
            procs = []
            for part in range(threads):
                q = ctx.Queue()
                p = ctx.Process(target=embree_worker, args=(out, part, threads, q, self.replies))
                p.start()
                procs.append((p, q))
            self.workers[threads] = procs
        builds = [self.replies.get()[1] for _ in range(3)]
        self.build = min(builds)

    def run(self, query, threads):
        t0 = time.perf_counter()
        for _, q in self.workers[threads]:
            q.put(query)
        hits = sum(self.replies.get()[2] for _ in self.workers[threads])
        return time.perf_counter() - t0, hits

    def close(self):
        for procs in self.workers.values():
            for p, q in procs:
                q.put(None)
                p.join()


class Candela:
    """The bvh_peer example, answering `closest|any THREADS` on stdin."""

    def __init__(self, out):
        subprocess.check_call(["cargo", "build", "-q", "--release", "-p", "candela-core",
                               "--example", "bvh_peer"], cwd=ROOT)
        self.p = subprocess.Popen([PEER, out], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                  text=True, cwd=ROOT)
        self.info = self.p.stdout.readline().strip()
        assert self.p.stdout.readline().strip() == "ready"

    def run(self, query, threads):
        self.p.stdin.write(f"{query} {threads}\n")
        self.p.stdin.flush()
        secs, hits = self.p.stdout.readline().split()
        return float(secs), int(hits)

    def close(self):
        self.p.stdin.close()
        self.p.wait()


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()
    ensure_modules()
    candela = Candela(OUT)
    print("candela:", candela.info)
    embree = Embree(OUT)
    print(f"embree:  build {embree.build:.3f} s (rtcCommitScene, its own threads)")
    n_rays = len(load(OUT)[2])
    configs = [("closest", "INTERSECT", 1), ("closest", "INTERSECT", 2),
               ("any", "OCCLUDED", 1), ("any", "OCCLUDED", 2)]
    times = {(c, t): ([], []) for c, _, t in configs}
    for r in range(args.rounds):
        for ours, theirs, threads in configs:
            a, b = times[(ours, threads)]
            secs, hits_a = candela.run(ours, threads)
            a.append(secs)
            secs, hits_b = embree.run(theirs, threads)
            b.append(secs)
            if r == 0:
                print(f"{ours:7} {threads} thread(s): hits candela {hits_a}, embree {hits_b}")
    candela.close()
    embree.close()
    print(f"\n{n_rays} rays, medians of {args.rounds} interleaved rounds; load average "
          f"{os.getloadavg()[0]:.1f} on {os.cpu_count()} cores")
    print(f"{'query':8} {'threads':>7} {'candela Mrays/s':>16} {'embree Mrays/s':>15} {'ratio':>6}")
    for ours, _, threads in configs:
        a, b = times[(ours, threads)]
        ma, mb = n_rays / statistics.median(a) / 1e6, n_rays / statistics.median(b) / 1e6
        print(f"{ours:8} {threads:>7} {ma:>16.2f} {mb:>15.2f} {ma / mb:>6.2f}")


if __name__ == "__main__":
    main()
