"""Where the in-memory Dask path's time goes (docs/SCALE.md, "Overhead"), in one run:

    python bench/scale/overhead.py MESH.ply [--tile-vertices 250000] [--estimator paper]

single (2 threads); the driver's plan (whole-mesh choices + cut) on 1 and on 2 threads; the
driver's extraction of every tile's arrays; pickling them (what Dask sends per task); the tiles'
estimates one after the other (2 threads); the Dask run end to end (LocalCluster, 2 workers x 1
thread). Each timed twice, the smaller kept.
"""

import argparse
import pickle
import time

import focal
import focal.distributed as fd
from focal import _focal_ext as ext


def best(f, repeat=2):
    times = []
    for _ in range(repeat):
        t = time.perf_counter()
        f()
        times.append(time.perf_counter() - t)
    return min(times)


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("mesh")
    p.add_argument("--tile-vertices", type=int, default=250_000)
    p.add_argument("--estimator", default="paper")
    a = p.parse_args()
    from distributed import Client, LocalCluster

    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0")
    client = Client(cluster)
    client.run(lambda: __import__("focal"))
    m = focal.read_mesh(a.mesh)
    _, _, opts = focal._curvature_options({"estimator": a.estimator})
    o = {t: focal._estimate_options(a.estimator, t, opts) for t in (1, 2)}
    rows = {"single": best(lambda: focal.curvature(m.V, m.F, m.N, estimator=a.estimator,
                                                   threads=2))}
    for t in (1, 2):
        rows[f"plan, {t} thread(s)"] = best(
            lambda: ext.tile_plan(m.V, m.F, m.N, o[t], a.tile_vertices))
    plan = ext.tile_plan(m.V, m.F, m.N, o[2], a.tile_vertices)
    faces = plan["F"] if plan["F"] is not None else m.F

    def extract():
        return [ext.extract_tile(m.V, faces, m.N, x["vertices"], x["faces"])
                for x in plan["tiles"]]

    rows["extract tiles (driver)"] = best(extract)
    arrays = extract()
    rows["pickle tiles (driver)"] = best(
        lambda: [pickle.dumps((x["V"], x["F"], x["N"]), protocol=5) for x in arrays])
    rows["estimate tiles, serial"] = best(
        lambda: [ext.estimate_tile(x["V"], x["F"], x["N"], o[2], plan["choices"])
                 for x in arrays])
    rows["Dask end to end"] = best(lambda: fd.curvature(m, client, tile_vertices=a.tile_vertices,
                                                        threads=1, estimator=a.estimator))
    print(f"{a.mesh}: {len(m.V):,} vertices, {len(plan['tiles'])} tiles of "
          f"{a.tile_vertices:,}, {a.estimator}")
    for k, v in rows.items():
        print(f"  {k:28s} {v:7.2f} s  {v / rows['single']:5.2f} x single")
    client.close()
    cluster.close()


if __name__ == "__main__":
    main()
