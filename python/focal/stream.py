"""Streaming input of a tiled run: a binary PLY mesh read in chunks, so that no process holds
the whole mesh (docs/SCALE.md, "Streaming input").

The file's vertex and face records (fixed-size records: triangles only) are read a chunk or a
set of ids at a time by the library's reader (focal::PlyTriangleReader, focal/io/mesh_io.h),
which parses the header as focal.read_mesh does.

- **Plan** (the driver, ``plan``): pass 1 over the vertices finds the box of the finite ones;
  pass 2 counts the vertices per cell of the library's coarse Morton grid and cuts the cells,
  in Morton order, into runs of about ``tile_vertices`` vertices (tiles.h, "Streamed tiles"):
  a vertex's tile is a function of its position (focal::tile_grid_tiles), nothing per vertex is
  kept; pass 2 also writes each tile's owned vertex ids to a file. Pass 3 over the faces, in
  whole blocks of ``_focal_ext.edge_length_block()`` faces, writes each face (its id and
  corners) to the face file of every tile owning one of its corners, and adds up the edge
  lengths per block, added in block order as ``mean_edge_length`` does: the whole mesh's mean
  edge length, bit for bit.
- **Choices** (the recommended estimator: a task per tile, ``tile_statistics``, then the driver,
  ``choose``): each tile's share of the whole mesh's choices (focal::tile_statistics, a halo of
  ``statistics_reach()`` rings), its per-vertex values in a file; the driver takes the exact
  medians over the files (``_median``: a radix selection on the values' bits) and makes the
  choices with focal::recommended_mesh_wide_from; they decide the estimate's halo.
- **Tile** (a worker, ``estimate_tile``): the halo by rings from the face files: round r takes,
  from the face files of the tiles owning the vertices found in round r - 1, the faces incident
  to them, as ``partition_mesh`` does in memory (every face of a vertex is in the face file of
  the tile owning it; the set operations by focal::ids_in). Then the tile's vertices and faces,
  sorted by global id, are read from the file and estimated with the whole mesh's choices; the
  owned rows are written to a part file (.npz, or .csv by focal.write_fields).

Memory: the driver holds the cell counts (8 bytes x 2^21 cells = 16 MB), the cell -> tile table
and one chunk; a worker holds one tile with its halo, its face files' records and
one neighbouring tile's face file at a time (16 bytes per face record), and ids_in's bitmap
(at most vertex count / 8 bytes).

What the plan cannot take from the whole mesh in streamed passes is the orientation of closed
components, which the estimate does when the normals come from the faces (the paper's estimator
with normals from the faces, either estimator on a file without normals): streaming needs the
file's normals, and says so otherwise.
"""

from __future__ import annotations

import json
import os
import resource
from typing import Any, Iterator, Optional

import numpy as np

import focal
from focal import _focal_ext as _ext
from focal._errors import InvalidInputError

__all__ = ["plan", "estimate_tile", "concatenate"]

#: Vertices or faces per chunk of a streamed pass.
CHUNK = 1 << 20

#: The per-vertex fields of focal.Curvature that tiles write back.
FIELDS = ("k1", "k2", "H", "K", "d1", "d2", "residual", "point_class", "rays_used",
          "rays_excluded")


def _open(path: "str | os.PathLike"):
    """The mesh file's reader (focal::PlyTriangleReader): its header read and checked, the
    records read by ranges or ids, never all at once."""
    name = os.fspath(path)
    if os.path.splitext(os.fsdecode(name))[1].lower() != ".ply":
        raise InvalidInputError(
            f"{os.fsdecode(name)}: streamed tiles (--parts, curvature_stream) read binary PLY "
            "only; convert it to binary PLY first (focal.write_mesh) or run without --parts"
        )
    return _ext.PlyTriangleReader(name)


def _ids(x: np.ndarray) -> np.ndarray:
    return np.ascontiguousarray(x, np.int32).reshape(-1)


def _ranges(n: int, step: int) -> Iterator[tuple]:
    for begin in range(0, n, step):
        yield begin, min(n, begin + step)


class _Grid:
    """Vertex position -> tile (focal::tile_grid_tiles, tiles.h "Streamed tiles"): the grid over
    the box of the finite vertices and each cell's tile."""

    def __init__(self, lo: Any, hi: Any, cell_tile: np.ndarray, threads: int):
        self.lo, self.hi, self.cell_tile, self.threads = list(lo), list(hi), cell_tile, threads

    def tiles(self, P: np.ndarray) -> np.ndarray:
        return _ext.tile_grid_tiles(P, self.lo, self.hi, self.cell_tile, self.threads)


def _uniform_options(options: dict, mesh: Any) -> None:
    if options["normals"] not in ("auto", "file") or not mesh.has_normals:
        raise focal.InvalidInputError(
            f"{mesh.path}: streaming input needs the file's normals (nx, ny, nz): normals "
            "from the faces, and the recommended estimator without normals, orient the faces "
            "of closed components over the whole mesh, which streaming does not do")


def plan(path: "str | os.PathLike", workdir: str, options: dict, tile_vertices: int) -> dict:
    """The plan of a streamed tiled run, its files written under `workdir`: see the module's
    docstring. `options` as focal._estimate_options gives them. Returns the plan (a dict that
    the tile tasks take, small)."""
    mesh = _open(path)
    _uniform_options(options, mesh)
    if int(tile_vertices) < 1:
        raise focal.InvalidInputError(f"tile_vertices must be >= 1, got {tile_vertices}")
    if mesh.vertex_count == 0:
        raise focal.FocalIOError(f"{mesh.path}: no vertices, nothing to compute")
    os.makedirs(workdir, exist_ok=True)
    threads = options["threads"]
    lo, hi = [np.inf] * 3, [-np.inf] * 3
    for b, e in _ranges(mesh.vertex_count, CHUNK):
        lo, hi = _ext.tile_grid_box(mesh.positions(b, e), lo, hi)
    counts = np.zeros(_ext.tile_grid_cell_count(), np.int64)
    for b, e in _ranges(mesh.vertex_count, CHUNK):
        counts += np.bincount(_ext.tile_grid_cells(mesh.positions(b, e), lo, hi, threads),
                              minlength=counts.size)
    cell_tile, tile_count = _ext.cut_tile_grid(counts, int(tile_vertices))
    tiles = _Grid(lo, hi, cell_tile, threads)
    np.save(os.path.join(workdir, "cell_tile.npy"), cell_tile)
    for t in range(tile_count):
        for kind in ("vertices", "faces"):
            open(_tile_file(workdir, kind, t), "wb").close()
    for b, e in _ranges(mesh.vertex_count, CHUNK):
        _append_grouped(workdir, "vertices", tiles.tiles(mesh.positions(b, e)),
                        np.arange(b, e, dtype=np.int32)[:, None])
    block = int(_ext.edge_length_block())
    edge_sum, edge_count = 0.0, 0
    for b, e in _ranges(mesh.face_count, block * max(1, CHUNK // block)):
        C = mesh.faces(b, e)
        ids, local = np.unique(C, return_inverse=True)
        P = mesh.positions(_ids(ids))
        sums, n = _ext.edge_length_sums(P, local.reshape(-1, 3).astype(np.int32), 1)
        for s, k in zip(sums.tolist(), n.tolist()):  # in block order, as mean_edge_length
            edge_sum += s
            edge_count += k
        corner_tiles = tiles.tiles(P)[local].reshape(-1, 3)
        records = np.column_stack([np.arange(b, e, dtype=np.int32), C])
        for c in range(3):  # each face once per distinct tile of its corners
            new = np.ones(len(C), bool)
            for earlier in range(c):
                new &= corner_tiles[:, c] != corner_tiles[:, earlier]
            _append_grouped(workdir, "faces", corner_tiles[new, c], records[new])
    mean_edge = edge_sum / edge_count if edge_count > 0 else 0.0
    out = {
        "path": os.path.abspath(mesh.path), "workdir": os.path.abspath(workdir),
        "vertex_count": mesh.vertex_count, "face_count": mesh.face_count,
        "tile_count": tile_count, "lo": list(lo), "hi": list(hi),
        "choices": {"mean_edge_length": mean_edge}, "options": options,
        # The recommended estimator's reach depends on its whole-mesh choices (choose()).
        "halo_rings": (None if options["estimator"] == "recommended"
                       else int(_ext.estimate_reach(options))),
    }
    _write_plan(out)
    return out


def _write_plan(p: dict) -> None:
    tmp = os.path.join(p["workdir"], ".plan.json.tmp")
    with open(tmp, "w") as f:
        json.dump(p, f, indent=1)
    os.replace(tmp, os.path.join(p["workdir"], "plan.json"))


#: Columns of a tile's statistics file (float64, one row per owned vertex).
STATISTICS = ("jet_residual", "angle_along", "angle_against", "file_roughness", "height_share")


def tile_statistics(p: dict, t: int) -> dict:
    """The task of tile t in the recommended estimator's plan: its owned vertices' share of the
    whole mesh's choices (focal::tile_statistics, with a halo of statistics_reach() rings). The
    per-vertex values go to the tile's statistics file (.npy, columns STATISTICS); returns the
    counts, the noise sample (whole-mesh ids and values) and the peak RSS."""
    a = tile_arrays(p, t, int(_ext.statistics_reach()))
    d = _ext.tile_statistics(a["V"], a["F"], a["N"], a["vertices"], a["owned"],
                             p["vertex_count"], p["options"], p["choices"]["mean_edge_length"])
    path = _tile_file(p["workdir"], "statistics", t)
    tmp = f"{path}.{os.getpid()}.tmp"
    with open(tmp, "wb") as f:
        np.save(f, np.column_stack([d[k] for k in STATISTICS]))
    os.replace(tmp, path)
    return {"tile": t, "along": int(d["along"]), "against": int(d["against"]),
            "sample": d["sample"].tolist(), "sample_noise": d["sample_noise"].tolist(),
            "peak_rss": peak_rss()}


def choose(p: dict, statistics: list) -> dict:
    """The recommended estimator's whole-mesh choices from every tile's statistics (the tasks'
    results and their files): exact medians over the files (_median, memory of one file and a
    histogram), then focal::recommended_mesh_wide_from; the plan gets the choices and the halo
    of the estimate they decide, and is written again. Returns the plan."""
    files = [_tile_file(p["workdir"], "statistics", t) for t in range(p["tile_count"])]
    sample = sorted((i, x) for r in statistics for i, x in zip(r["sample"], r["sample_noise"]))
    medians = {
        "jet_residual": _median(files, 0),
        "angle_along": _median(files, 1), "angle_against": _median(files, 2),
        "file_roughness": _median(files, 3), "height_share": _median(files, 4),
        "along": sum(r["along"] for r in statistics),
        "against": sum(r["against"] for r in statistics),
        "sample_noise": [x for _, x in sample], "has_normals": True,
    }
    p["choices"] = dict(_ext.recommended_choices(medians, p["choices"]["mean_edge_length"]))
    p["halo_rings"] = int(_ext.estimate_reach(p["options"], p["choices"]))
    _write_plan(p)
    return p


def _keys(x: np.ndarray) -> np.ndarray:
    """Finite doubles -> uint64 keys in the same order (-0.0 as +0.0)."""
    u = (x + 0.0).view(np.uint64)
    top = np.uint64(1 << 63)
    return np.where(u & top, ~u, u | top)


def _value(key: int) -> float:
    top = 1 << 63
    bits = key & ~top if key & top else ~key & ((1 << 64) - 1)
    return float(np.array([bits], np.uint64).view(np.float64)[0])


#: _median reads and partitions the candidates once they number at most this many.
_CANDIDATES = 1 << 22


def _median(files: list, column: int) -> float:
    """The median of the finite values of `column` over the statistics files, as the library's
    finite_median takes it (the value at rank size / 2 in ascending order; NaN when none): an
    exact radix selection on the values' bits, 16 at a time, each pass reading the files one at
    a time; once the candidates number at most _CANDIDATES, they are read and partitioned."""
    def finite_keys():
        for f in files:
            x = np.load(f, mmap_mode="r")[:, column]
            yield _keys(np.ascontiguousarray(x[np.isfinite(x)]))

    size = sum(k.size for k in finite_keys())
    if size == 0:
        return float("nan")
    rank, prefix = size // 2, 0
    for shift in (48, 32, 16, 0):
        counts = np.zeros(1 << 16, np.int64)
        for k in finite_keys():
            if shift < 48:
                k = k[(k >> np.uint64(shift + 16)) == np.uint64(prefix)]
            counts += np.bincount((k >> np.uint64(shift) & np.uint64(0xFFFF)).astype(np.int64),
                                  minlength=1 << 16)
        below = np.cumsum(counts) - counts
        digit = int(np.searchsorted(below + counts, rank, side="right"))
        rank -= int(below[digit])
        prefix = prefix << 16 | digit
        if shift > 0 and counts[digit] <= _CANDIDATES:
            shift_left = np.uint64(shift)
            rest = np.concatenate([k[(k >> shift_left) == np.uint64(prefix)]
                                   for k in finite_keys()])
            return _value(int(np.partition(rest, rank)[rank]))
    return _value(prefix)


def _tile_file(workdir: str, kind: str, t: int) -> str:
    return os.path.join(workdir, f"tile-{t:06d}.{kind}")


def _append_grouped(workdir: str, kind: str, tile: np.ndarray, rows: np.ndarray) -> None:
    """Appends rows (int32) to the files of their tiles."""
    order = np.argsort(tile, kind="stable")
    tile, rows = tile[order], rows[order]
    starts = np.flatnonzero(np.r_[True, tile[1:] != tile[:-1]]) if len(tile) else []
    for s, e in zip(starts, list(starts[1:]) + [len(tile)]):
        with open(_tile_file(workdir, kind, int(tile[s])), "ab") as f:
            f.write(np.ascontiguousarray(rows[s:e], np.int32).tobytes())


def _tile_records(workdir: str, kind: str, t: int, width: int) -> np.ndarray:
    return np.fromfile(_tile_file(workdir, kind, t), np.int32).reshape(-1, width)


def _distinct(x: np.ndarray) -> np.ndarray:
    """The distinct values of x, ascending (by a sort: NumPy's hashed unique is slower here)."""
    s = np.sort(x, axis=None)
    return s[np.r_[True, s[1:] != s[:-1]]] if s.size else s


def _member(x: np.ndarray, ascending: np.ndarray, threads: int = 1) -> np.ndarray:
    """Whether each value of x (ids >= 0) is in `ascending`: focal::ids_in (tiles.h), a bitmap
    over the span of `ascending` (at most vertex count / 8 bytes)."""
    return _ext.ids_in(np.ascontiguousarray(x, np.int32),
                       np.ascontiguousarray(ascending, np.int32), threads)


def _merge(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """The union of two ascending arrays without common values, ascending (a stable sort of two
    runs is a merge)."""
    return np.sort(np.concatenate([a, b]), kind="stable")


def tile_arrays(p: dict, t: int, halo_rings: Optional[int] = None) -> dict:
    """Tile t's arrays, read from the plan's files and the mesh: its vertices within the halo's
    rings of the owned ones (the plan's halo, or `halo_rings`) and the faces with a corner
    within one ring less, sorted by global id (as partition_mesh and extract_tile give them)."""
    halo_rings = p["halo_rings"] if halo_rings is None else halo_rings
    threads = p["options"]["threads"]
    mesh = _open(p["path"])
    tiles = _Grid(p["lo"], p["hi"],
                  np.load(os.path.join(p["workdir"], "cell_tile.npy"), mmap_mode="r"), threads)
    owned = np.sort(_tile_records(p["workdir"], "vertices", t, 1)[:, 0])
    reached, frontier = owned, owned
    taken = [np.empty((0, 4), np.int32)]
    taken_ids = np.empty(0, np.int32)
    for _ in range(halo_rings):
        if frontier.size == 0:
            break
        found = []
        for u in _distinct(tiles.tiles(mesh.positions(_ids(frontier)))):
            r = _tile_records(p["workdir"], "faces", int(u), 4)
            if u != t or taken_ids.size:  # else: every face of t's file has an owned corner
                m = _member(r[:, 1:], frontier, threads)
                r = r[m[:, 0] | m[:, 1] | m[:, 2]]
                r = r[~_member(r[:, 0], taken_ids, threads)]
            found.append(r)
        new = np.concatenate(found)
        new = new[np.argsort(new[:, 0], kind="stable")]
        new = new[np.r_[True, new[1:, 0] != new[:-1, 0]]] if len(new) else new
        taken.append(new)
        taken_ids = _merge(taken_ids, new[:, 0])
        corners = _distinct(new[:, 1:])
        frontier = corners[~_member(corners, reached, threads)]
        reached = _merge(reached, frontier)
    faces = np.concatenate(taken)
    faces = faces[np.argsort(faces[:, 0], kind="stable")]
    return {
        "V": mesh.positions(_ids(reached)),
        "N": mesh.normals(_ids(reached)) if mesh.has_normals else None,
        "F": np.searchsorted(reached, faces[:, 1:]).astype(np.int32),
        "vertices": np.ascontiguousarray(reached, np.int32), "faces": faces[:, 0],
        "owned": np.searchsorted(reached, owned).astype(np.int32),
    }


#: Formats of the parts: .npz (ids and the fields as arrays) or .csv (the rows of `focal
#: curvature -o fields.csv`, by focal.write_fields, with the ids beside them in a .ids.npy).
PART_FORMATS = ("npz", "csv")


def estimate_tile(p: dict, t: int, parts: str, part_format: str = "npz") -> dict:
    """The task of tile t: its estimate with the whole mesh's choices, the owned rows written
    to parts/part-NNNNNN.npz (ids and fields) or, for part_format "csv", parts/part-NNNNNN.csv
    (the bytes `focal curvature -o x.csv` writes for these rows, header included) and their ids
    in parts/part-NNNNNN.ids.npy; each through a temporary file renamed. Returns the part's
    name, its row count and the process's peak RSS (bytes, peak_rss)."""
    if part_format not in PART_FORMATS:
        raise focal.InvalidInputError(f"part_format: {part_format!r}, expected one of "
                                      f"{PART_FORMATS}")
    a = tile_arrays(p, t)
    d = _ext.estimate_tile(a["V"], a["F"], a["N"], p["options"], p["choices"])
    rows = a["owned"]
    ids = a["vertices"][rows]
    fields = {k: d[k][rows] for k in FIELDS}
    if d["crease"] is not None:  # the recommended estimator's crease flags
        fields["crease"] = d["crease"][rows]
    name = f"part-{t:06d}.{part_format}"
    out = {"tile": t, "part": name, "rows": int(rows.size), "vertices": int(a["V"].shape[0])}
    if part_format == "npz":
        tmp = os.path.join(parts, f".{name}.{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            np.savez(f, ids=ids, **fields)
        os.replace(tmp, os.path.join(parts, name))
    else:
        out["ids"] = f"part-{t:06d}.ids.npy"
        tmp = os.path.join(parts, f".{out['ids']}.{os.getpid()}.tmp")
        with open(tmp, "wb") as f:
            np.save(f, ids)
        os.replace(tmp, os.path.join(parts, out["ids"]))
        focal.write_fields(os.path.join(parts, name), focal.Curvature(**fields),
                           threads=p["options"]["threads"])
    out["peak_rss"] = peak_rss()
    return out


def peak_rss() -> int:
    """This process's peak resident memory in bytes: VmHWM on Linux (unlike ru_maxrss, not
    inherited across exec from the process that started it), else ru_maxrss."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) * 1024
    except OSError:
        pass
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024


#: Rows of the concatenated CSV gathered in memory at a time.
CSV_ROWS = 1 << 18


def concatenate(manifest: dict, parts: str, output: str) -> None:
    """The parts' rows in input order, as one file: a .npz of the fields from .npz parts, or
    from .csv parts the CSV that `focal curvature -o fields.csv` writes (concatenate_csv)."""
    formats = {os.path.splitext(part["part"])[1] for part in manifest["parts"]}
    wanted = os.path.splitext(output)[1].lower()
    if formats != {wanted}:
        raise focal.InvalidInputError(
            f"{output}: a {wanted} concatenation is made from {wanted} parts, these are "
            f"{', '.join(sorted(formats))}")
    if wanted == ".csv":
        return concatenate_csv(manifest, parts, output)
    _concatenate_npz(manifest, parts, output)


def concatenate_csv(manifest: dict, parts: str, output: str) -> None:
    """The .csv parts' rows in input order: the same bytes as the whole mesh's `focal curvature
    -o fields.csv`. The rows are the writer's bytes, moved, not formatted again: each part's rows
    are in ascending id order, so CSV_ROWS ids at a time, every part gives the next run of its
    lines (memory: those lines, and each part's ids mapped)."""
    n = manifest["vertex_count"]
    files, ids, cursor, header = [], [], [], None
    tmp = output + ".tmp"
    try:
        for part in manifest["parts"]:
            files.append(open(os.path.join(parts, part["part"]), "rb"))
            line = files[-1].readline()
            if header is None:
                header = line
            elif line != header:
                raise focal.FocalIOError(f"{part['part']}: its header is not the other parts'")
            ids.append(np.load(os.path.join(parts, part["ids"]), mmap_mode="r"))
            cursor.append(0)
        with open(tmp, "wb") as out:
            out.write(header or b"")
            for begin, end in _ranges(n, CSV_ROWS):
                lines = [b""] * (end - begin)
                for k, f in enumerate(files):
                    stop = int(np.searchsorted(ids[k], end))
                    for i in ids[k][cursor[k]:stop].tolist():
                        lines[i - begin] = f.readline()
                    cursor[k] = stop
                out.write(b"".join(lines))
        os.replace(tmp, output)
    finally:
        for f in files:
            f.close()
        if os.path.exists(tmp):
            os.unlink(tmp)


def _concatenate_npz(manifest: dict, parts: str, output: str) -> None:
    """The parts' rows in input order, as one .npz of the fields: each part's rows are written
    by id into .npy columns mapped for that part only (the written pages then belong to the
    page cache, not to this process), then the columns are stored in the .npz."""
    import zipfile

    n = manifest["vertex_count"]
    columns = {k: os.path.join(parts, f".{k}.npy") for k in manifest["fields"]}
    for k, column in columns.items():
        shape = (n, 3) if k in ("d1", "d2") else (n,)
        dtype = {"point_class": np.uint8, "rays_used": np.int32, "rays_excluded": np.int32,
                 "crease": np.uint8}.get(k, np.float64)
        np.lib.format.open_memmap(column, "w+", dtype, shape).flush()  # header, size
    for part in manifest["parts"]:
        with np.load(os.path.join(parts, part["part"])) as z:
            ids = z["ids"]
            for k, column in columns.items():
                m = np.load(column, mmap_mode="r+")
                m[ids] = z[k]
                del m  # unmapped: its dirty pages are written back by the kernel
    tmp = output + ".tmp"
    with zipfile.ZipFile(tmp, "w", zipfile.ZIP_STORED, allowZip64=True) as z:
        for k, column in columns.items():
            z.write(column, f"{k}.npy")
    for column in columns.values():
        os.unlink(column)
    os.replace(tmp, output)
