#!/usr/bin/env python3
"""focal from Python against the curvature estimators of other Python libraries, in one process
on the same NumPy arrays (bench/python/run.sh runs it; docs/PYTHON.md shows its tables).

  bench.py accuracy             relative RMS of H against the analytic truth (interior vertices)
  bench.py timing MESH...       compute-only medians, as ratios to focal (default estimator)
  bench.py overhead             the Python call against the C++ call it makes, 100K vertices;
                                NumPy allocations during the call (copies of inputs would be)

Peers are bench/peers/peers.py's (libigl, pymeshlab, trimesh, VTK through pyvista, trueform, and
CGAL's jets where FOCAL_CGAL_PEER names a built bench/points/cgal_peer; their outputs brought to
focal's sign convention there). Every peer gets the positions
and faces only, as does focal (its normals from the faces): no one gets exact normals.
(pymeshlab's mesh takes a normal matrix: zeros are passed; its curvature filters recompute the
normals, measured: the same H with zeros or area-weighted normals given.)
"""
import argparse
import gc
import math
import os
import statistics
import sys
import time
import tracemalloc

import numpy as np

import focal

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "peers"))
import peers  # noqa: E402  (bench/peers/peers.py: the peers and their conventions)


def focal_default(V, F, N):
    return focal.curvature(V, F).__dict__


def focal_paper(V, F, N):
    return focal.curvature(V, F, estimator="paper").__dict__


METHODS = {
    "focal (default: recommended)": focal_default,
    "focal estimator=\"paper\"": focal_paper,
    **peers.available_peers(),
}


def interior(F, n):
    """Vertices on no boundary edge (an edge of one face)."""
    e = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
    edges, counts = np.unique(e, axis=0, return_counts=True)
    inside = np.ones(n, dtype=bool)
    inside[edges[counts == 1].ravel()] = False
    return inside


def relative_rms(H, truth, where):
    ok = where & np.isfinite(H)
    return math.sqrt(np.mean((H[ok] - truth[ok]) ** 2) / np.mean(truth[ok] ** 2)), int(
        np.count_nonzero(where & ~np.isfinite(H)))


SURFACES = ["sphere", "ellipsoid", "torus", "saddle", "monkey-saddle", "pear"]


def cmd_accuracy(args):
    rows = {name: [] for name in METHODS}
    for kind in SURFACES:
        s = focal.generate_surface(kind, args.vertices, triangulation="irregular", seed=args.seed)
        truth = 0.5 * (s.k1 + s.k2)
        inside = interior(s.F, len(s.V))
        for name, method in METHODS.items():
            try:
                rows[name].append(relative_rms(np.asarray(method(s.V, s.F, np.zeros_like(s.V))["H"]), truth,
                                               inside))
            except Exception as e:  # a peer that fails on a surface is reported, not hidden
                rows[name].append((float("nan"), f"error: {type(e).__name__}"))
    print(f"Relative RMS of H against the analytic truth, interior vertices, irregular "
          f"triangulations of about {args.vertices} vertices (seed {args.seed}); positions and "
          f"faces only. In parentheses: vertices without a value (NaN).\n")
    print("| method | " + " | ".join(SURFACES) + " |")
    print("|---|" + "---|" * len(SURFACES))
    for name, values in rows.items():
        cells = []
        for rms, missing in values:
            cell = "fails" if isinstance(missing, str) else f"{rms:.2e}"
            if not isinstance(missing, str) and missing:
                cell += f" ({missing})"
            cells.append(cell)
        print(f"| {name} | " + " | ".join(cells) + " |", flush=True)


def median_seconds(method, V, F, repeats):
    N = np.zeros_like(V)  # see the module's docstring (pymeshlab)
    times = []
    for _ in range(repeats):
        gc.collect()
        start = time.perf_counter()
        method(V, F, N)
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def load(spec):
    if spec.startswith("torus:"):
        s = focal.generate_surface("torus", int(float(spec.split(":")[1])))
        return f"torus, {len(s.V):,} vertices", s.V, s.F
    m = focal.read_mesh(spec)
    return f"{os.path.basename(spec)}, {len(m.V):,} vertices", m.V, m.F


def cmd_timing(args):
    threads = os.cpu_count()
    print(f"Compute-only time through each library's Python API on the same arrays (conversions "
          f"a library makes of them included), median of {args.repeats} runs ({args.repeats_large} "
          f"above 200K vertices), as a ratio to "
          f"focal's default estimator; focal on all {threads} hardware threads (shared with other "
          f"work: ratios in one run), the peers as their libraries run. A ratio above 1 is "
          f"slower than focal.\n")
    for spec in args.meshes:
        label, V, F = load(spec)
        print(f"\n**{label}**\n\n| method | median s | ratio to focal default |\n|---|---|---|")
        base = None
        for name, method in METHODS.items():
            if name in args.skip_large and len(V) > 200_000:
                print(f"| {name} | not run above 200K vertices (minutes) | |", flush=True)
                continue
            repeats = args.repeats if len(V) <= 200_000 else args.repeats_large
            try:
                t = median_seconds(method, V, F, repeats)
            except Exception as e:
                print(f"| {name} | fails: {type(e).__name__}: {str(e)[:80]} | |", flush=True)
                continue
            base = base or t
            print(f"| {name} | {t:.3f} | {t / base:.2f} |", flush=True)


def cmd_overhead(args):
    s = focal.generate_surface("torus", args.vertices)
    V, F = s.V, s.F
    estimator, threads, options = focal._curvature_options({})
    o = focal._estimate_options(estimator, threads, options)
    python, cpp = [], []

    def time_python():
        start = time.perf_counter()
        c = focal.curvature(V, F)
        python.append(time.perf_counter() - start)
        return c  # freed after the clock stops, as the C++ result is in _estimate_seconds

    for i in range(args.repeats):  # interleaved, in alternating order, so that load hits both
        if i % 2:
            time_python()
            cpp.extend(focal._ext._estimate_seconds(V, F, None, o, 1))
        else:
            cpp.extend(focal._ext._estimate_seconds(V, F, None, o, 1))
            time_python()
    tiny = focal.generate_surface("sphere", 16)
    tp, tc = [], []
    for _ in range(200):
        start = time.perf_counter()
        focal.curvature(tiny.V, tiny.F)
        tp.append(time.perf_counter() - start)
        tc.extend(focal._ext._estimate_seconds(tiny.V, tiny.F, None, o, 1))
    fixed = statistics.median(tp) - statistics.median(tc)
    mp, mc = statistics.median(python), statistics.median(cpp)
    print(f"Python call overhead, torus of {len(V):,} vertices, default estimator, "
          f"{args.repeats} interleaved runs: Python focal.curvature median {mp * 1e3:.1f} ms, "
          f"the C++ call it makes (timed in C++) {mc * 1e3:.1f} ms: difference "
          f"{100 * (mp - mc) / mc:+.2f}% (noise of a shared machine included). Fixed cost of "
          f"the Python layer, from a {len(tiny.V)}-vertex mesh (200 runs): {fixed * 1e6:.0f} us = "
          f"{100 * fixed / mc:.3f}% of the 100K call.")
    tracemalloc.start()
    c = focal.curvature(V, F)
    _, peak = tracemalloc.get_traced_memory()
    tracemalloc.stop()
    print(f"NumPy/Python allocations during the call (tracemalloc peak; copies of V or F "
          f"would be {V.nbytes + F.nbytes:,} bytes): {peak:,} bytes. Results own the "
          f"library's buffers: H.flags.owndata = {c.H.flags.owndata}, base "
          f"{type(c.H.base).__name__}.")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    a = sub.add_parser("accuracy")
    a.add_argument("--vertices", type=int, default=20000)
    a.add_argument("--seed", type=int, default=1)
    t = sub.add_parser("timing")
    t.add_argument("meshes", nargs="+", help="mesh files, or torus:N for a generated torus")
    t.add_argument("--repeats", type=int, default=3)
    t.add_argument("--repeats-large", type=int, default=3, help="runs per method above 200K")
    t.add_argument("--skip-large", nargs="*", default=[], help="methods not run above 200K")
    o = sub.add_parser("overhead")
    o.add_argument("--vertices", type=int, default=100_000)
    o.add_argument("--repeats", type=int, default=11)
    args = p.parse_args()
    {"accuracy": cmd_accuracy, "timing": cmd_timing, "overhead": cmd_overhead}[args.command](args)


if __name__ == "__main__":
    main()
