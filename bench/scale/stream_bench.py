"""A streamed tiled run (focal.distributed.curvature_stream) against one process (docs/SCALE.md).

    python bench/scale/stream_bench.py MESH.ply PARTS_DIR [--workers 2] [--memory-limit 2GB]
        [--tile-vertices 1000000] [--no-single]

Prints, for one binary PLY mesh with normals and the paper's estimator:
  stream  the plan (the driver's streamed passes), the tasks, the concatenation, their sum; the
          driver's peak RSS and every task's process peak RSS (VmHWM, exact: the largest of a
          worker's tasks is that worker's peak);
  single  focal.read_mesh + focal.curvature in a child process (threads = workers), its time
          and peak RSS; skipped with --no-single (or when it fails: its error is printed);
  identical  whether the concatenated fields are the single run's, bit for bit.
"""

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

import focal.distributed as fd
from focal.stream import peak_rss

SINGLE = """
import json, sys, time, numpy as np, focal
from focal.stream import peak_rss
t = time.perf_counter()
m = focal.read_mesh(sys.argv[1], threads=int(sys.argv[3]))
c = focal.curvature(m.V, m.F, m.N, estimator="paper", threads=int(sys.argv[3]))
seconds = time.perf_counter() - t
del m
np.savez(sys.argv[2], **{k: getattr(c, k) for k in sys.argv[4].split(",")})
print(json.dumps({"seconds": seconds,
                  "peak_mb": peak_rss() / 2**20}))
"""


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("mesh")
    p.add_argument("parts")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--memory-limit", default="2GB")
    p.add_argument("--tile-vertices", type=int, default=1_000_000)
    p.add_argument("--no-single", action="store_true")
    p.add_argument("--compare", help="a single run's fields (.npz, as this bench writes them) "
                   "to compare with, in place of running it")
    a = p.parse_args()
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                           memory_limit=a.memory_limit, dashboard_address=":0")
    client = Client(cluster)
    out = os.path.join(a.parts, "fields.npz")
    timings = {}

    peaks = {}

    def on_phase(name, seconds):
        timings[name] = seconds
        peaks[name] = peak_rss() / 2**20  # the driver's peak so far

    t = time.perf_counter()
    manifest = fd.curvature_stream(a.mesh, a.parts, client, output=out,
                                   tile_vertices=a.tile_vertices, threads=1,
                                   estimator="paper", on_phase=on_phase)
    total = time.perf_counter() - t
    client.close()
    cluster.close()
    workers = max(r["peak_rss"] for r in manifest["parts"]) / 2**20
    halo = sum(r["vertices"] for r in manifest["parts"]) / manifest["vertex_count"] - 1
    print(f"mesh {a.mesh}: {manifest['vertex_count']} vertices, {manifest['face_count']} faces; "
          f"{manifest['tile_count']} tiles, halo {manifest['halo_rings']} rings, "
          f"+{100 * halo:.1f}% vertices")
    driver = peak_rss() / 2**20
    print("stream: " + ", ".join(f"{k} {v:.1f} s" for k, v in timings.items()) +
          f", total {total:.1f} s; driver peak RSS {driver:.0f} MB (after the plan "
          f"{peaks['plan']:.0f} MB); task peak RSS "
          f"{workers:.0f} MB (limit {a.memory_limit})")
    sys.stdout.flush()
    if a.compare:
        return print(f"identical to {a.compare}: {'yes' if same_fields(out, a.compare) else 'NO'}")
    if a.no_single:
        return
    single_out = os.path.join(a.parts, "single.npz")
    r = subprocess.run([sys.executable, "-c", SINGLE, a.mesh, single_out, str(a.workers),
                        ",".join(fd.FIELDS)], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"single: failed (exit {r.returncode}): {r.stderr[-2000:]}")
        return
    s = json.loads(r.stdout.strip().splitlines()[-1])
    print(f"single: {s['seconds']:.1f} s, peak RSS {s['peak_mb']:.0f} MB; stream / single "
          f"{total / s['seconds']:.2f} x")
    print(f"identical: {'yes' if same_fields(out, single_out) else 'NO'}")


def same_fields(a: str, b: str) -> bool:
    with np.load(a) as x, np.load(b) as y:
        return all(x[k].tobytes() == y[k].tobytes() for k in fd.FIELDS)


if __name__ == "__main__":
    main()
