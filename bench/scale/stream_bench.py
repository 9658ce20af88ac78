"""A streamed tiled run (focal.distributed.curvature_stream) against one process (docs/SCALE.md).

    python bench/scale/stream_bench.py MESH.ply PARTS_DIR [--workers 2] [--memory-limit 2GB]
        [--tile-vertices 1000000] [--estimator recommended|paper] [--format npz|csv]
        [--no-single] [--focal build/release/cli/focal]

Prints, for one binary PLY mesh with normals:
  stream  the plan (the driver's streamed passes), for the recommended estimator the choices
          (a pass of statistics tasks and the exact medians), the estimate tasks, the
          concatenation, their sum; the driver's peak RSS and every task's process peak RSS
          (VmHWM, exact: the largest of a worker's tasks is that worker's peak);
  single  npz: focal.read_mesh + focal.curvature in a child process (threads = workers); csv:
          `focal curvature MESH -o single.csv` (--focal, threads = workers) under
          /usr/bin/time -v; its time and peak RSS; skipped with --no-single;
  identical  npz: whether the concatenated fields are the single run's, bit for bit; csv:
          whether the two files are the same bytes (cmp).
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
c = focal.curvature(m.V, m.F, m.N, estimator=sys.argv[5], threads=int(sys.argv[3]))
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
    p.add_argument("--estimator", choices=("recommended", "paper"), default="recommended")
    p.add_argument("--format", choices=("npz", "csv"), default="npz")
    p.add_argument("--focal", default="build/release/cli/focal", help="the focal command, "
                   "for the single run of --format csv")
    p.add_argument("--compare", help="a single run's fields (.npz, as this bench writes them) "
                   "to compare with, in place of running it")
    a = p.parse_args()
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=a.workers, threads_per_worker=1, processes=True,
                           memory_limit=a.memory_limit, dashboard_address=":0")
    client = Client(cluster)
    out = os.path.join(a.parts, "fields." + a.format)
    timings = {}

    peaks = {}

    def on_phase(name, seconds):
        timings[name] = seconds
        peaks[name] = peak_rss() / 2**20  # the driver's peak so far

    t = time.perf_counter()
    manifest = fd.curvature_stream(a.mesh, a.parts, client, output=out,
                                   tile_vertices=a.tile_vertices, threads=1,
                                   estimator=a.estimator, on_phase=on_phase,
                                   part_format=a.format)
    total = time.perf_counter() - t
    client.close()
    cluster.close()
    workers = max(r["peak_rss"] for r in manifest["parts"]) / 2**20
    workers = max(workers, manifest.get("statistics_peak_rss", 0) / 2**20)
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
    if a.format == "csv":
        return single_csv(a, out, total)
    single_out = os.path.join(a.parts, "single.npz")
    r = subprocess.run([sys.executable, "-c", SINGLE, a.mesh, single_out, str(a.workers),
                        ",".join(fd.FIELDS), a.estimator], capture_output=True, text=True)
    if r.returncode != 0:
        print(f"single: failed (exit {r.returncode}): {r.stderr[-2000:]}")
        return
    s = json.loads(r.stdout.strip().splitlines()[-1])
    print(f"single: {s['seconds']:.1f} s, peak RSS {s['peak_mb']:.0f} MB; stream / single "
          f"{total / s['seconds']:.2f} x")
    print(f"identical: {'yes' if same_fields(out, single_out) else 'NO'}")


def single_csv(a, out: str, total: float) -> None:
    import filecmp

    single_out = os.path.join(a.parts, "single.csv")
    command = ["/usr/bin/time", "-v", a.focal, "curvature", a.mesh, "-o", single_out,
               "--threads", str(a.workers)] + (["--paper"] if a.estimator == "paper" else [])
    r = subprocess.run(command, capture_output=True, text=True)
    if r.returncode != 0:
        print(f"single: failed (exit {r.returncode}): {r.stderr[-2000:]}")
        return
    report = dict(line.strip().rsplit(": ", 1) for line in r.stderr.splitlines()
                  if ": " in line)
    h, m, sec = ([0.0] * 3 + [float(x) for x in report[
        "Elapsed (wall clock) time (h:mm:ss or m:ss)"].split(":")])[-3:]
    seconds = 3600 * h + 60 * m + sec
    peak = int(report["Maximum resident set size (kbytes)"]) / 1024
    print(f"single: {' '.join(command[2:])}: {seconds:.1f} s, peak RSS {peak:.0f} MB; "
          f"stream / single {total / seconds:.2f} x")
    print(f"identical (cmp): {'yes' if filecmp.cmp(out, single_out, shallow=False) else 'NO'}")


def same_fields(a: str, b: str) -> bool:
    with np.load(a) as x, np.load(b) as y:
        return all(x[k].tobytes() == y[k].tobytes() for k in fd.FIELDS)


if __name__ == "__main__":
    main()
