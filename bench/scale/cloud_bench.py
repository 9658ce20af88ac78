"""A point cloud in tiles on a Dask LocalCluster against one process (docs/SCALE.md, "Point
clouds").

    python bench/scale/cloud_bench.py CLOUD.xyz [--workers 2] [--memory-limit 2GB]
        [--tile-vertices 250000] [--k 0] [--no-normals]

Prints, in one run (times comparable on a shared machine):
  single  focal.cloud_curvature of the whole cloud in this process (threads = workers), its time
          and this process's peak RSS growth;
  plan    the driver's share of a tiled run: plan_cloud_curvature and partition_cloud;
  serial  the tiles' fits one after the other in this process, and whether they are the single
          run's bits;
  tiled   focal.distributed.cloud_curvature end to end, the ratio to single, every worker's peak
          RSS, and whether the fields are bit-identical to single's.
"""

import argparse
import time

import focal
import focal.distributed as fd
from focal import _focal_ext as ext
from scale_bench import peak_rss_mb, report_tiled, start_cluster


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("cloud")
    p.add_argument("--workers", type=int, default=2)
    p.add_argument("--memory-limit", default="2GB")
    p.add_argument("--tile-vertices", type=int, default=250_000)
    p.add_argument("--k", type=int, default=0, help="0: the library's default plan")
    p.add_argument("--no-normals", action="store_true", help="estimate the normals")
    args = p.parse_args()
    client, cluster, idle = start_cluster(args.workers, args.memory_limit)
    t = time.perf_counter()
    m = focal.read_mesh(args.cloud)
    P, N = m.V, None if args.no_normals else m.N
    print(f"read     {len(P):,} points (normals: {N is not None}) in "
          f"{time.perf_counter() - t:.2f} s (driver RSS {peak_rss_mb():.0f} MB)")
    base = peak_rss_mb()
    t = time.perf_counter()
    single = focal.cloud_curvature(P, N, k=args.k, threads=args.workers)
    t_single = time.perf_counter() - t
    print(f"single   {t_single:.2f} s, peak RSS +{peak_rss_mb() - base:.0f} MB over the cloud")
    single = {n: getattr(single, n) for n in fd.FIELDS}

    o = {"k": args.k, "radius": 0.0, "normal_method": "jet", "viewpoint": None,
         "solver": "closed-form", "outlier_ratio": 3.0, "threads": args.workers}
    t = time.perf_counter()
    plan = ext.cloud_tile_plan(P, N, o, args.tile_vertices)
    t_plan = time.perf_counter() - t
    sizes = [len(x["vertices"]) for x in plan["tiles"]]
    print(f"plan     {t_plan:.2f} s = {t_plan / t_single:.2f} x single: {len(sizes)} tiles, "
          f"k {plan['choices']['k']}, points with halo {min(sizes):,}..{max(sizes):,} "
          f"(+{100.0 * (sum(sizes) / len(P) - 1):.1f}% halo)")
    t = time.perf_counter()
    same = True
    for x in plan["tiles"]:
        a = ext.extract_cloud_tile(P, plan["N"], plan["outlier"], x["vertices"])
        r = ext.estimate_cloud_tile(a["V"], a["N"], a["outlier"], o, plan["choices"])
        ids = x["vertices"][x["owned"]]
        same &= all(r[n][x["owned"]].tobytes() == single[n][ids].tobytes() for n in fd.FIELDS)
    t_serial = time.perf_counter() - t
    print(f"serial   {t_serial:.2f} s = {t_serial / t_single:.2f} x single (tiles only; plan + "
          f"tiles {(t_plan + t_serial) / t_single:.2f} x); bit-identical: {same}")
    del plan

    report_tiled(client, lambda: fd.cloud_curvature(P, N, client, k=args.k, threads=1,
                                                    tile_vertices=args.tile_vertices),
                 single, t_single, idle, args.memory_limit)
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
