"""focal on a Dask cluster: a mesh cut into spatial tiles with halos, one task per tile, and the
owned vertices of every tile written back, giving the same bits as ``focal.curvature`` on the
whole mesh (include/focal/tiles/tiles.h, docs/SCALE.md).

The driver (this process) holds the whole mesh, measures once what the estimate takes from the
whole mesh (the mean edge length, the recommended estimator's noise and file-normal choices, the
orientation of closed components) and cuts the tiles; the workers each hold one tile at a time.
Tasks are submitted a few per worker thread at a time, so that the scheduler holds only those
tiles' arrays; results are written into the output as they arrive. A task whose worker dies is
run again elsewhere by Dask; a task that raises is retried ``retries`` times.

    import focal.distributed
    c = focal.distributed.curvature("scan.ply", tile_vertices=250_000)   # a LocalCluster
    c = focal.distributed.curvature((V, F, N), client=Client("tcp://scheduler:8786"))
    c = focal.distributed.cloud_curvature(points, normals, tile_vertices=250_000)  # a cloud

or from a shell: ``python -m focal.distributed scan.ply -o fields.npz --scheduler ADDRESS``.
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import uuid
import warnings
from typing import Any, Callable, Optional

import numpy as np

import focal
from focal import _focal_ext as _ext
from focal import _clouds, stream

#: The per-vertex fields of focal.Curvature that tiles write back.
FIELDS = stream.FIELDS

__all__ = ["cloud_curvature", "curvature", "curvature_stream", "main"]

#: What is missing when Dask is not installed, in one line.
_NO_DASK = ("focal.distributed needs Dask (the distributed package): "
            "pip install 'focal-surfaces[distributed]'")


def _dask():
    """The ``distributed`` module, or a one-line ModuleNotFoundError naming the extra that
    installs it."""
    try:
        import distributed
    except ModuleNotFoundError as e:
        if e.name not in ("distributed", "dask"):
            raise
        raise ModuleNotFoundError(_NO_DASK, name="distributed") from None
    return distributed

#: Tasks in flight per worker thread: enough to keep workers busy while results come back,
#: few enough that the scheduler holds only a few tiles' arrays.
_TASKS_PER_THREAD = 2


def _estimate_tile(V: np.ndarray, F: np.ndarray, N: Optional[np.ndarray], owned: np.ndarray,
                   options: dict, choices: dict) -> dict:
    """The task: a tile's estimate with the whole mesh's choices, its owned rows only."""
    d = _ext.estimate_tile(V, F, N, options, choices)
    fields = {name: d[name][owned] for name in FIELDS}
    if d["crease"] is not None:  # the recommended estimator's crease flags
        fields["crease"] = d["crease"][owned]
    return fields


def _estimate_cloud_tile(V: np.ndarray, N: np.ndarray, outlier: Optional[np.ndarray],
                         owned: np.ndarray, options: dict, choices: dict) -> dict:
    """The task of a cloud's tile: the fit with the whole cloud's choices, its owned rows only."""
    d = _ext.estimate_cloud_tile(V, N, outlier, options, choices)
    return {name: d[name][owned] for name in FIELDS}


def _mesh_of(path_or_arrays: Any):
    if isinstance(path_or_arrays, (str, os.PathLike)):
        m = focal.read_mesh(path_or_arrays)
        return m.V, m.F, m.N
    if isinstance(path_or_arrays, focal.Mesh):
        return path_or_arrays.V, path_or_arrays.F, path_or_arrays.N
    if isinstance(path_or_arrays, tuple) and len(path_or_arrays) in (2, 3):
        return (*path_or_arrays, None) if len(path_or_arrays) == 2 else path_or_arrays
    raise focal.InvalidInputError(
        "path_or_arrays must be a path, a focal.Mesh or a tuple (V, F) or (V, F, N), "
        f"got {type(path_or_arrays).__name__}"
    )


def _local_client(workers: Optional[int], memory_limit: Any):
    Client, LocalCluster = _dask().Client, _dask().LocalCluster

    cluster = LocalCluster(
        n_workers=workers or os.cpu_count() or 1,
        threads_per_worker=1,
        memory_limit=memory_limit if memory_limit is not None else "auto",
        processes=True,
        dashboard_address=":0",
    )
    return Client(cluster), cluster


def curvature(
    path_or_arrays: Any,
    client: Any = None,
    *,
    tile_vertices: int = 250_000,
    workers: Optional[int] = None,
    memory_limit: Any = None,
    retries: int = 2,
    progress: bool = False,
    on_tile: Optional[Callable[[int, np.ndarray, dict], None]] = None,
    **options: Any,
) -> focal.Curvature:
    """``focal.curvature`` of a mesh, tile by tile on a Dask cluster: the same bits.

    Parameters
    ----------
    path_or_arrays : a mesh file (read by ``focal.read_mesh``), a ``focal.Mesh`` or a tuple
        ``(V, F)`` / ``(V, F, N)``; one without faces (a cloud file, F of shape (0, 3)) is a
        point cloud, run as ``cloud_curvature`` (options: those of ``focal.cloud_curvature``).
    client : a ``distributed.Client``; None: a ``LocalCluster`` of ``workers`` processes (default
        one per core) with one thread each and ``memory_limit`` per worker (Dask's "auto"
        default), closed at the end.
    tile_vertices : owned vertices per tile (each tile also holds a halo of the estimate's reach,
        a few rings). A worker's memory is about that of ``focal.curvature`` on one tile.
    retries : how many times a task that raised is run again (a task whose worker died is
        rescheduled by Dask whatever this is).
    progress : show Dask's progress bar (it waits for all tasks, then results are collected).
    on_tile : called in the driver as each tile's result arrives, with the tile's index, the
        global ids of its owned vertices and their fields (a dict of arrays by name), e.g. to
        write the result in parts.
    options : the keywords of ``focal.curvature`` (estimator, normals, threads, ...). threads is
        per task; None with the default LocalCluster: 1 (one thread per worker).

    Returns a ``focal.Curvature`` with the per-vertex fields (N, F, plan and the reports of a
    whole run are not filled: the fields are what a tiled run writes back).

    Raises InvalidInputError as ``focal.curvature``, FocalIOError for an unreadable file.
    """
    V, F, N = _mesh_of(path_or_arrays)
    if isinstance(F, np.ndarray) and F.ndim == 2 and F.shape[0] == 0:
        # A file (or focal.Mesh) without faces is a point cloud: its estimator is the cloud's.
        if options.pop("estimator", "recommended") != "recommended":
            raise focal.InvalidInputError("a point cloud (no faces) has one estimator: "
                                          "estimator='paper' applies to meshes")
        return cloud_curvature(V, N, client, tile_vertices=tile_vertices, workers=workers,
                               memory_limit=memory_limit, retries=retries, progress=progress,
                               on_tile=on_tile, **options)
    if int(tile_vertices) < 1:
        raise focal.InvalidInputError(f"tile_vertices must be >= 1, got {tile_vertices}")
    own_cluster = client is None
    if own_cluster and options.get("threads") is None:
        options["threads"] = 1
    estimator, threads, opts = focal._curvature_options(options)
    o = focal._estimate_options(estimator, threads, opts)
    Va, Fa, Na = focal._mesh_arrays(V, F, N)
    plan = _ext.tile_plan(Va, Fa, Na, o, int(tile_vertices))
    faces = plan["F"] if plan["F"] is not None else Fa

    def task(t: dict) -> tuple:
        a = _ext.extract_tile(Va, faces, Na, t["vertices"], t["faces"])
        return _estimate_tile, (a["V"], a["F"], a["N"], t["owned"], o, plan["choices"])

    out = _run_tiles(plan["tiles"], task, Va.shape[0], client, workers, memory_limit, retries,
                     progress, on_tile)
    return focal.Curvature(**out)


def cloud_curvature(
    points: Any,
    normals: Any = None,
    client: Any = None,
    *,
    tile_vertices: int = 250_000,
    workers: Optional[int] = None,
    memory_limit: Any = None,
    retries: int = 2,
    progress: bool = False,
    on_tile: Optional[Callable[[int, np.ndarray, dict], None]] = None,
    k: int = 0,
    radius: Optional[float] = None,
    normal_method: str = "jet",
    viewpoint: Any = None,
    solver: str = "closed-form",
    outlier_ratio: float = 3.0,
    off_surface_ratio: float = 10.0,
    threads: Optional[int] = None,
) -> focal.Curvature:
    """``focal.cloud_curvature`` of a point cloud, the fit tile by tile on a Dask cluster: the
    same bits (include/focal/tiles/tiles.h, docs/SCALE.md "Point clouds").

    The driver makes the plan on the whole cloud (the neighbourhoods, outlier flags, mean
    spacing and normals: estimated normals are oriented over the whole cloud) and cuts the
    tiles: a tile holds its owned points and their neighbours. Each task fits its tile's points.
    Cloud options as ``focal.cloud_curvature`` except ``adaptive_radius`` (not tiled: a
    point's radius reads its neighbours' neighbours, beyond a tile's halo); the others as
    ``curvature``.
    """
    if int(tile_vertices) < 1:
        raise focal.InvalidInputError(f"tile_vertices must be >= 1, got {tile_vertices}")
    if client is None and threads is None:
        threads = 1
    # No adaptive radius: a point's radius reads its neighbours' neighbours, beyond the halo.
    P, k, r, _, t = _clouds._cloud_arguments(points, k, radius, None, threads)
    N = None
    if normals is not None:
        N = focal._as_rows(normals, "normals", np.float64)
        if N.shape[0] != P.shape[0]:
            raise focal._shape_error("normals", f"({P.shape[0]}, 3) like points", N.shape)
    o = {"k": k, "radius": r, "normal_method": normal_method,
         "viewpoint": _clouds._viewpoint(viewpoint), "solver": solver,
         "outlier_ratio": float(outlier_ratio), "off_surface_ratio": float(off_surface_ratio),
         "threads": t}
    plan = _ext.cloud_tile_plan(P, N, o, int(tile_vertices))
    Np, outlier = plan["N"], plan["outlier"]

    def task(tile: dict) -> tuple:
        a = _ext.extract_cloud_tile(P, Np, outlier, tile["vertices"])
        return _estimate_cloud_tile, (a["V"], a["N"], a["outlier"], tile["owned"], o,
                                      plan["choices"])

    out = _run_tiles(plan["tiles"], task, P.shape[0], client, workers, memory_limit, retries,
                     progress, on_tile)
    return focal.Curvature(**out)


def _run_tiles(tiles: list, task: Callable[[dict], tuple], n: int, client: Any,
               workers: Optional[int], memory_limit: Any, retries: int, progress: bool,
               on_tile: Optional[Callable[[int, np.ndarray, dict], None]]) -> dict:
    """Runs task(tile) = (function, arguments) of every tile on `client` (None: a LocalCluster,
    closed at the end), a few per worker thread in flight, and writes each result's owned rows
    into the fields of n vertices, which it returns."""
    as_completed = _dask().as_completed

    out = _empty_fields(n)
    cluster = None
    if client is None:
        client, cluster = _local_client(workers, memory_limit)
    try:
        in_flight = max(1, _TASKS_PER_THREAD * sum(client.nthreads().values()))
        tile_of = {}

        def submit(i: int):
            function, arguments = task(tiles[i])
            # The arrays travel inside the task, not scattered ahead: Dask can then rerun the
            # task elsewhere when its worker dies (scattered data would die with the worker).
            # Dask warns about such tasks ("Sending large graph"); here that is the intent.
            with warnings.catch_warnings():
                warnings.filterwarnings("ignore", message="Sending large graph")
                fut = client.submit(function, *arguments,
                                    key=f"focal-tile-{i}-{uuid.uuid4().hex}", retries=retries)
            tile_of[fut.key] = i
            return fut

        first = [submit(i) for i in range(min(in_flight, len(tiles)))]
        if progress:
            dask_progress = _dask().progress

            dask_progress(first)
        pending = as_completed(first, with_results=True)
        next_tile = len(first)
        for fut, fields in pending:
            i = tile_of.pop(fut.key)
            ids = tiles[i]["vertices"][tiles[i]["owned"]]
            for name in FIELDS:
                out[name][ids] = fields[name]
            if "crease" in fields:
                out.setdefault("crease", np.zeros(n, np.uint8))[ids] = fields["crease"]
            if on_tile is not None:
                on_tile(i, ids, fields)
            fut.release()
            if next_tile < len(tiles):
                pending.add(submit(next_tile))
                next_tile += 1
    finally:
        if cluster is not None:
            client.close()
            cluster.close()
    return out


def curvature_stream(
    path: "str | os.PathLike",
    parts: "str | os.PathLike",
    client: Any = None,
    *,
    output: "Optional[str | os.PathLike]" = None,
    tile_vertices: int = 250_000,
    workers: Optional[int] = None,
    memory_limit: Any = None,
    retries: int = 2,
    progress: bool = False,
    on_phase: Optional[Callable[[str, float], None]] = None,
    part_format: str = "npz",
    **options: Any,
) -> dict:
    """``curvature`` of a binary PLY mesh that no process holds whole (focal/stream.py): the
    driver plans the tiles in streamed passes over the file; each task reads its tile (with its
    halo) from the file and the plan's files, and writes its owned rows to a part in `parts`
    (part_format "npz": part-NNNNNN.npz, ``ids`` and the fields; "csv": part-NNNNNN.csv, the
    rows `focal curvature -o x.csv` writes for those vertices, and their ids in
    part-NNNNNN.ids.npy); ``parts/manifest.json`` lists the parts. With `output` (.npz from
    npz parts, .csv from csv parts), the parts are also concatenated in input order: the
    whole run's fields, and for .csv the bytes of `focal curvature -o output.csv`. The same bits
    as ``focal.curvature`` on the whole mesh.

    The plan's files (the tiles' vertex and face ids, about 4 bytes per vertex and 16 to 48 per
    face) go to ``parts/plan``; `parts` must be a folder every worker can read and write (a
    shared file system on a cluster). Needs the file's normals (see focal.stream); the
    recommended estimator's whole-mesh choices come from a first pass of tasks (each tile's
    statistics) and exact medians over them. `on_phase(name, seconds)` is called after each
    phase ("plan", "choices" for the recommended estimator, "tiles", "concatenate"). Returns
    the manifest (a dict). Options as ``curvature``.
    """
    import json
    import time

    as_completed = _dask().as_completed

    own_cluster = client is None
    if own_cluster and options.get("threads") is None:
        options["threads"] = 1
    estimator, threads, opts = focal._curvature_options(options)
    o = focal._estimate_options(estimator, threads, opts)
    if part_format not in stream.PART_FORMATS:
        raise focal.InvalidInputError(f"part_format: {part_format!r}, expected one of "
                                      f"{stream.PART_FORMATS}")
    if output is not None and not os.fspath(output).lower().endswith("." + part_format):
        raise focal.InvalidInputError(
            f"{os.fspath(output)}: the concatenation of {part_format} parts is a "
            f".{part_format} file")
    parts = os.fspath(parts)
    os.makedirs(parts, exist_ok=True)
    phase = [time.perf_counter()]

    def phase_done(name: str) -> None:
        now = time.perf_counter()
        if on_phase is not None:
            on_phase(name, now - phase[0])
        phase[0] = now

    plan = stream.plan(path, os.path.join(parts, "plan"), o, int(tile_vertices))
    phase_done("plan")
    cluster = None
    if own_cluster:
        client, cluster = _local_client(workers, memory_limit)

    def run(function, name: str, *arguments) -> list:
        futures = [client.submit(function, plan, t, *arguments, retries=retries,
                                 key=f"focal-stream-{name}-{t}-{uuid.uuid4().hex}")
                   for t in range(plan["tile_count"])]
        if progress:
            dask_progress = _dask().progress

            dask_progress(futures)
        return sorted((r for _, r in as_completed(futures, with_results=True)),
                      key=lambda r: r["tile"])

    try:
        statistics = None
        if o["estimator"] == "recommended":
            # The whole mesh's choices from every tile's statistics (a pass of tasks), then
            # the tiles' estimates with them.
            statistics = run(stream.tile_statistics, "statistics")
            stream.choose(plan, statistics)
            phase_done("choices")
        done = run(stream.estimate_tile, "tile", parts, part_format)
    finally:
        if cluster is not None:
            client.close()
            cluster.close()
    phase_done("tiles")
    manifest = {k: plan[k] for k in ("path", "vertex_count", "face_count", "tile_count",
                                      "halo_rings", "choices", "options")}
    manifest["fields"] = list(stream.FIELDS) + (["crease"] if statistics is not None else [])
    manifest["part_format"] = part_format
    manifest["parts"] = done
    if statistics is not None:
        manifest["statistics_peak_rss"] = max(r["peak_rss"] for r in statistics)
    with open(os.path.join(parts, "manifest.json"), "w") as f:
        json.dump(manifest, f, indent=1)
    if output is not None:
        stream.concatenate(manifest, parts, os.fspath(output))
        phase_done("concatenate")
    return manifest


def _empty_fields(n: int) -> dict:
    return {
        "k1": np.empty(n), "k2": np.empty(n), "H": np.empty(n), "K": np.empty(n),
        "d1": np.empty((n, 3)), "d2": np.empty((n, 3)), "residual": np.empty(n),
        "point_class": np.empty(n, np.uint8), "rays_used": np.empty(n, np.int32),
        "rays_excluded": np.empty(n, np.int32),
    }


def _write_atomically(path: str, write: Callable[[str], None]) -> None:
    """Writes through a temporary file beside `path`, renamed at the end: no half-written file."""
    folder = os.path.dirname(os.path.abspath(path))
    fd, tmp = tempfile.mkstemp(prefix=".focal-", suffix=os.path.splitext(path)[1], dir=folder)
    os.close(fd)
    try:
        write(tmp)
        os.replace(tmp, path)
    except BaseException:
        os.unlink(tmp)
        raise


def _write_fields(path: str, c: focal.Curvature) -> None:
    if path.endswith(".npz"):
        def write_npz(tmp: str) -> None:
            with open(tmp, "wb") as f:
                np.savez(f, **c.to_dict())

        _write_atomically(path, write_npz)
    elif path.endswith(".csv"):
        focal.write_fields(path, c)  # the bytes of `focal curvature -o fields.csv`
    else:
        raise focal.InvalidInputError(f"{path}: the output must end in .npz or .csv")


class _Parser(argparse.ArgumentParser):
    """Usage errors exit 1, as the focal command line's (2 is for unreadable input)."""

    def error(self, message: str):
        self.print_usage(sys.stderr)
        print(f"Error: {message}", file=sys.stderr)
        sys.exit(1)


def main(argv: Optional[list] = None) -> int:
    """``python -m focal.distributed``: the command line of ``curvature``. Exit codes as
    ``focal``: 0 success, 1 usage error, 2 unreadable input or invalid data."""
    p = _Parser(
        prog="python -m focal.distributed",
        description="focal curvature of a mesh, tile by tile on a Dask cluster (the same "
        "numbers as `focal curvature`).",
    )
    p.add_argument("input", help="mesh or point cloud file (.ply, .obj, .off, .stl; clouds: "
                   ".xyz .xyzn .xyzrgb .pts .txt .csv .pcd .las, PLY/OBJ without faces)")
    p.add_argument("-o", "--output", help="fields, .npz or .csv (input order); with --parts, "
                   "the parts concatenated (.npz or .csv, as the parts)")
    p.add_argument("--parts", help="stream the input (binary PLY with normals): no process "
                   "holds the whole mesh; each tile's fields go to PARTS/part-NNNNNN.npz (or "
                   ".csv), listed in PARTS/manifest.json")
    p.add_argument("--part-format", choices=stream.PART_FORMATS, default=None,
                   help="with --parts: the parts' format (default: the output's, else npz)")
    p.add_argument("--scheduler", help="address of a running Dask scheduler "
                   "(default: a LocalCluster here)")
    p.add_argument("--workers", type=int, help="LocalCluster worker processes (default: cores)")
    p.add_argument("--memory-limit", help="LocalCluster memory per worker, e.g. 2GB")
    p.add_argument("--tile-vertices", type=int, default=250_000,
                   help="owned vertices per tile (default 250000)")
    p.add_argument("--paper", action="store_true", help="the paper's estimator, not the default")
    p.add_argument("--threads", type=int, help="threads per task")
    p.add_argument("--progress", action="store_true", help="show Dask's progress bar")
    args = p.parse_args(argv)
    if args.scheduler and (args.workers or args.memory_limit):
        p.error("--workers and --memory-limit configure a LocalCluster: not with --scheduler")
    if args.output is None and args.parts is None:
        p.error("one of -o/--output and --parts is required")
    if args.output is not None and not args.output.endswith((".npz", ".csv")):
        p.error(f"{args.output}: the output must end in .npz or .csv")
    if args.part_format is not None and args.parts is None:
        p.error("--part-format is for --parts")
    part_format = args.part_format or ("csv" if args.output and args.output.endswith(".csv")
                                       else "npz")
    if args.parts is not None and args.output is not None and \
            not args.output.endswith("." + part_format):
        p.error(f"{args.output}: with --parts, the concatenation of {part_format} parts is "
                f".{part_format}")
    client = None
    try:
        if args.scheduler:
            client = _dask().Client(args.scheduler)
        common = dict(tile_vertices=args.tile_vertices, workers=args.workers,
                      memory_limit=args.memory_limit, progress=args.progress,
                      threads=args.threads, estimator="paper" if args.paper else "recommended")
        if args.parts is not None:
            curvature_stream(args.input, args.parts, client, output=args.output,
                             part_format=part_format, **common)
        else:
            mesh = focal.read_mesh(args.input)
            if mesh.F.shape[0] == 0:
                common["k"] = 0  # a cloud: the library's default plan, as `focal curvature`'s
            _write_fields(args.output, curvature(mesh, client, **common))
    except (focal.FocalIOError, focal.InvalidInputError, OSError, ModuleNotFoundError) as e:
        print(f"Error: {e}", file=sys.stderr)
        return 2
    finally:
        if client is not None:
            client.close()
    return 0


if __name__ == "__main__":
    sys.exit(main())
