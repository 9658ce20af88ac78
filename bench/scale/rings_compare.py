"""A streamed tile's halo rounds (focal.stream.tile_arrays) with two versions of focal/stream.py
on the same plan: the times (best of two, alternating) and whether the arrays are the same.

    git show REV:python/focal/stream.py > /tmp/stream_before.py
    python bench/scale/rings_compare.py PARTS/plan/plan.json /tmp/stream_before.py
"""

import importlib.util
import json
import sys
import time

import numpy as np

from focal import stream as after


def main() -> None:
    spec = importlib.util.spec_from_file_location("focal.stream_before", sys.argv[2])
    before = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(before)
    p = json.load(open(sys.argv[1]))
    for t in range(p["tile_count"]):
        runs = []
        for name, m in (("before", before), ("after", after)) * 2:
            start = time.perf_counter()
            a = m.tile_arrays(p, t)
            runs.append((name, time.perf_counter() - start, a))
        same = all(np.array_equal(runs[0][2][k], r[2][k]) for r in runs
                   for k in ("vertices", "faces", "owned", "F"))
        best = {n: min(s for m, s, _ in runs if m == n) for n in ("before", "after")}
        print(f"tile {t} ({len(runs[0][2]['vertices'])} vertices, {p['halo_rings']} rings): "
              f"before {best['before']:.2f} s, after {best['after']:.2f} s; same arrays: {same}")


if __name__ == "__main__":
    main()
