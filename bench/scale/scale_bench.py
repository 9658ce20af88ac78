"""Tiled runs on a Dask LocalCluster against one process (docs/SCALE.md).

    python bench/scale/scale_bench.py MESH.ply [--workers 2] [--memory-limit 3GB]
        [--tile-vertices 250000] [--estimator recommended|paper] [--repeat 1] [--no-single]

Prints, for one mesh in one run (so that the times are comparable on a shared machine):
  single  focal.curvature on the whole mesh in this process (threads = workers), its time and
          this process's peak RSS growth;
  plan    the driver's share of a tiled run: the whole mesh's choices and the tiles;
  tiled   focal.distributed.curvature end to end (plan + tasks + results), the ratio to single,
          every worker's peak RSS, and whether the fields are bit-identical to single's.
"""

import argparse
import os
import resource
import threading
import time

import numpy as np

import focal
import focal.distributed as fd
from focal import _focal_ext as ext


def peak_rss_mb() -> float:
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def worker_rss_mb() -> float:
    import psutil

    return psutil.Process().memory_info().rss / 2**20


class RssSampler:
    """The largest RSS of every worker, sampled in a thread while a block runs."""

    def __init__(self, client, period: float = 0.2):
        self.client, self.period, self.peak = client, period, {}
        self.done = threading.Event()

    def run(self) -> None:
        while not self.done.wait(self.period):
            for w, mb in self.client.run(worker_rss_mb).items():
                self.peak[w] = max(self.peak.get(w, 0.0), mb)

    def __enter__(self):
        self.thread = threading.Thread(target=self.run, daemon=True)
        self.thread.start()
        return self

    def __exit__(self, *exc):
        self.done.set()
        self.thread.join()


def start_cluster(workers: int, memory_limit: str):
    """A LocalCluster of `workers` processes x 1 thread with focal imported, its client, and the
    workers' idle RSS. Started before the input is read, so that the workers do not start as
    copies of a large driver."""
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           memory_limit=memory_limit, dashboard_address=":0")
    client = Client(cluster)
    client.run(lambda: __import__("focal"))  # import once, outside the timing
    return client, cluster, client.run(worker_rss_mb)


def report_tiled(client, run, single, t_single, idle, memory_limit) -> None:
    """Times run() (a tiled run), sampling its workers' peak RSS, and compares its fields with
    `single`'s (a dict by name, or None)."""
    with RssSampler(client) as sampler:
        t = time.perf_counter()
        tiled = run()
        t_tiled = time.perf_counter() - t
    line = f"tiled    {t_tiled:.2f} s"
    if single is not None:
        same = all(getattr(tiled, n).tobytes() == single[n].tobytes() for n in fd.FIELDS)
        line += f" = {t_tiled / t_single:.2f} x single; bit-identical: {same}"
    print(line)
    print("workers  peak RSS " + ", ".join(f"{v:.0f} MB" for v in sampler.peak.values()) +
          f" (idle {max(idle.values()):.0f} MB; limit {memory_limit} each)")


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("mesh")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--memory-limit", default="3GB")
    p.add_argument("--tile-vertices", type=int, default=250_000)
    p.add_argument("--estimator", default="recommended")
    p.add_argument("--no-single", action="store_true", help="skip the one-process run")
    args = p.parse_args()
    client, cluster, idle = start_cluster(args.workers, args.memory_limit)
    t = time.perf_counter()
    m = focal.read_mesh(args.mesh)
    print(f"read     {len(m.V):,} vertices, {len(m.F):,} faces in {time.perf_counter() - t:.2f} s"
          f" (driver RSS {peak_rss_mb():.0f} MB)")
    base = peak_rss_mb()
    options = {"estimator": args.estimator, "threads": args.workers}
    single = None
    if not args.no_single:
        t = time.perf_counter()
        single = focal.curvature(m.V, m.F, m.N, **options)
        t_single = time.perf_counter() - t
        print(f"single   {t_single:.2f} s, peak RSS +{peak_rss_mb() - base:.0f} MB over the mesh")
        single = {n: getattr(single, n) for n in fd.FIELDS}

    estimator, threads, opts = focal._curvature_options(options)
    o = focal._estimate_options(estimator, 0, opts)
    t = time.perf_counter()
    plan = ext.tile_plan(m.V, m.F, m.N, o, args.tile_vertices)
    t_plan = time.perf_counter() - t
    sizes = [len(x["vertices"]) for x in plan["tiles"]]
    print(f"plan     {t_plan:.2f} s: {len(sizes)} tiles, halo {plan['halo_rings']} rings, "
          f"tile vertices with halo {min(sizes):,}..{max(sizes):,} "
          f"(+{100.0 * (sum(sizes) / len(m.V) - 1):.1f}% halo)")
    if not args.no_single:
        o_threads = dict(o, threads=args.workers)
        t = time.perf_counter()
        plan = ext.tile_plan(m.V, m.F, m.N, o_threads, args.tile_vertices)
        faces = plan["F"] if plan["F"] is not None else m.F
        same = True
        for x in plan["tiles"]:
            a = ext.extract_tile(m.V, faces, m.N, x["vertices"], x["faces"])
            r = ext.estimate_tile(a["V"], a["F"], a["N"], o_threads, plan["choices"])
            ids = x["vertices"][x["owned"]]
            same &= all(r[n][x["owned"]].tobytes() == single[n][ids].tobytes() for n in fd.FIELDS)
        t_serial = time.perf_counter() - t
        print(f"serial   {t_serial:.2f} s = {t_serial / t_single:.2f} x single; "
              f"bit-identical: {same}")
    del plan

    report_tiled(client, lambda: fd.curvature(m, client, tile_vertices=args.tile_vertices,
                                              threads=1, estimator=args.estimator),
                 single, None if single is None else t_single, idle, args.memory_limit)
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
