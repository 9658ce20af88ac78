"""The library pieces under focal.stream, without a cluster: the binary PLY reader by record ranges
and ids (focal::PlyTriangleReader) reads what focal.read_mesh reads, and refuses what it cannot
stream; the grid of streamed tiles (tiles.h, "Streamed tiles") gives the cells and tiles of the
plain NumPy reference below."""

import numpy as np
import pytest

import focal
from focal import _focal_ext as _ext

BITS = 7  # kTileGridBits


def write_ply(path, vertex, face, endian="little", before="", after=""):
    """A binary PLY of structured arrays `vertex` and `face` (face: count, corners[3], ...)."""
    def properties(a):
        lines = []
        for name in a.dtype.names:
            t = a.dtype[name]
            ply = {"f4": "float", "f8": "double", "u1": "uchar", "i2": "short", "u4": "uint",
                   "i4": "int"}
            if name == "corners":
                continue
            if name == "count":
                item = ply[a.dtype["corners"].base.str[1:]]
                lines.append(f"property list {ply[t.str[1:]]} {item} vertex_indices")
            else:
                lines.append(f"property {ply[t.str[1:]]} {name}")
        return "\n".join(lines) + "\n"

    header = (f"ply\nformat binary_{endian}_endian 1.0\n{before}element vertex {len(vertex)}\n"
              f"{properties(vertex)}element face {len(face)}\n{properties(face)}{after}"
              "end_header\n")
    path.write_bytes(header.encode() + vertex.tobytes() + face.tobytes())
    return path


@pytest.fixture(scope="module")
def torus():
    return focal.generate_surface("torus", 3000, triangulation="irregular", seed=3)


def records(s, order="<", pcl=False):
    names = ("normal_x", "normal_y", "normal_z") if pcl else ("nx", "ny", "nz")
    vertex = np.zeros(len(s.V), [("x", order + "f8"), ("y", order + "f8"), ("z", order + "f8"),
                                 ("red", "u1"), (names[0], order + "f4"),
                                 (names[1], order + "f4"), (names[2], order + "f4")])
    for i, axis in enumerate("xyz"):
        vertex[axis] = s.V[:, i]
        vertex[names[i]] = s.N[:, i]
    face = np.zeros(len(s.F), [("count", "u1"), ("corners", order + "i4", (3,)),
                               ("flags", order + "i2")])
    face["count"], face["corners"] = 3, s.F
    return vertex, face


@pytest.mark.parametrize("endian, pcl", [("little", False), ("big", True)])
def test_the_reader_reads_what_read_mesh_reads(torus, tmp_path, endian, pcl):
    order = "<" if endian == "little" else ">"
    vertex, face = records(torus, order, pcl)
    # A fixed-size element before the vertices is skipped, one after the faces is not read; a
    # header longer than the reader's first read (64 KiB) is read whole.
    comments = "".join(f"comment line {i} of a long header\n" for i in range(3000))
    extra = np.arange(8, dtype=order + "i4")
    path = tmp_path / "mesh.ply"
    body = vertex.tobytes() + face.tobytes()
    write_ply(path, vertex, face, endian)
    header, _ = path.read_bytes().split(b"end_header\n", 1)
    header = header.replace(b"element vertex", comments.encode() + b"element extra 8\n"
                            b"property int value\nelement vertex")
    header += b"element tail 1\nproperty double t\n"
    path.write_bytes(header + b"end_header\n" + extra.tobytes() + body + np.zeros(1).tobytes())
    m = focal.read_mesh(path)
    r = _ext.PlyTriangleReader(str(path))
    assert (r.vertex_count, r.face_count, r.has_normals) == (len(m.V), len(m.F), True)
    n = len(m.V)
    assert r.positions(0, n).tobytes() == m.V.tobytes()
    assert r.normals(0, n).tobytes() == m.N.tobytes()
    assert np.array_equal(r.faces(0, len(m.F)), m.F)
    assert np.array_equal(r.faces(10, 20), m.F[10:20])
    assert r.positions(5, 5).shape == (0, 3)
    rng = np.random.default_rng(1)
    ids = np.concatenate([np.sort(rng.choice(n, 500, replace=False)), [7, 7, 3, n - 1, 0]])
    ids = ids.astype(np.int32)
    assert r.positions(ids).tobytes() == m.V[ids].tobytes()
    assert r.normals(ids).tobytes() == m.N[ids].tobytes()


def test_the_reader_refuses_what_it_cannot_stream(torus, tmp_path):
    vertex, face = records(torus)
    path = write_ply(tmp_path / "mesh.ply", vertex, face)
    r = _ext.PlyTriangleReader(str(path))
    with pytest.raises(focal.InvalidInputError, match="vertex -1 is not in"):
        r.positions(np.array([0, -1], np.int32))
    with pytest.raises(focal.InvalidInputError, match="not in"):
        r.positions(0, len(vertex) + 1)
    with pytest.raises(focal.InvalidInputError, match="not in"):
        r.faces(3, 2)
    header, body = path.read_bytes().split(b"end_header\n", 1)
    cases = {
        "tristrips": (header + b"element tristrips 0\nproperty list int int vertex_indices\n",
                      "tristrips"),
        "vertex_list": (header.replace(b"property uchar red", b"property list uchar int red"),
                        "'red' is a list"),
        "no_faces": (header.split(b"element face")[0], "needs a vertex and a face element"),
    }
    for name, (bad_header, message) in cases.items():
        bad = tmp_path / f"{name}.ply"
        bad.write_bytes(bad_header + b"end_header\n" + body)
        with pytest.raises(focal.FocalIOError, match=message):
            _ext.PlyTriangleReader(str(bad))
    with pytest.raises(focal.FocalIOError, match="no such file"):
        _ext.PlyTriangleReader(str(tmp_path / "missing.ply"))
    (tmp_path / "text.ply").write_text("solid\n")
    with pytest.raises(focal.FocalIOError, match="not a PLY file"):
        _ext.PlyTriangleReader(str(tmp_path / "text.ply"))


def reference_cells(P, lo, hi):
    """The grid cells as NumPy computes them: the plain reference of tile_grid_cells."""
    side = 1 << BITS
    extent = np.where(hi > lo, hi - lo, 1.0)
    with np.errstate(invalid="ignore"):
        t = np.clip((P - lo) / extent, 0.0, 1.0)
    finite = np.isfinite(P).all(axis=1)
    ijk = np.minimum((np.nan_to_num(t) * side).astype(np.int64), side - 1)
    spread = np.zeros(side, np.int64)
    for b in range(BITS):
        spread |= ((np.arange(side) >> b) & 1) << (3 * b)
    code = spread[ijk[:, 0]] | spread[ijk[:, 1]] << 1 | spread[ijk[:, 2]] << 2
    return np.where(finite, code, side ** 3)


def test_the_tile_grid_gives_the_reference_cells_and_tiles():
    rng = np.random.default_rng(4)
    P = rng.normal(size=(20000, 3)) * [1.0, 3.0, 0.01]
    P[::97, 1] = np.nan
    P[::101, 2] = np.inf
    lo, hi = [np.inf] * 3, [-np.inf] * 3
    for chunk in np.array_split(P, 7):
        lo, hi = _ext.tile_grid_box(np.ascontiguousarray(chunk), lo, hi)
    finite = P[np.isfinite(P).all(axis=1)]
    assert lo == finite.min(axis=0).tolist() and hi == finite.max(axis=0).tolist()
    Q = np.vstack([P, [lo, hi, [hi[0] + 5, lo[1] - 5, lo[2]]]])  # the corners, outside the box
    cells = _ext.tile_grid_cells(Q, lo, hi, 2)
    assert np.array_equal(cells, reference_cells(Q, np.array(lo), np.array(hi)))
    assert cells[-3] == 0 and cells[-2] == (1 << 3 * BITS) - 1
    # x in the last part, y and z in the first: every bit 0 of the triples set.
    assert cells[-1] == sum(1 << 3 * b for b in range(BITS))
    assert cells[97] == 1 << 3 * BITS  # non-finite: the last cell
    counts = np.bincount(cells, minlength=_ext.tile_grid_cell_count())
    assert counts.size == (1 << 3 * BITS) + 1
    for tile_vertices in (1, 700, 5000, len(Q)):
        cell_tile, tile_count = _ext.cut_tile_grid(counts, tile_vertices)
        before = np.cumsum(counts) - counts
        full = counts > 0
        _, dense = np.unique(before[full] // tile_vertices, return_inverse=True)
        assert tile_count == dense.max() + 1
        assert np.array_equal(cell_tile[full], dense) and not cell_tile[~full].any()
        tiles = _ext.tile_grid_tiles(Q, lo, hi, cell_tile, 1)
        assert np.array_equal(tiles, cell_tile[cells])
        sizes = np.bincount(tiles)
        assert sizes.size == tile_count and (sizes > 0).all()
    assert _ext.cut_tile_grid(counts, len(Q))[1] == 1
    with pytest.raises(focal.InvalidInputError, match="tile_vertices"):
        _ext.cut_tile_grid(counts, 0)
    with pytest.raises(focal.InvalidInputError, match="counts"):
        _ext.cut_tile_grid(counts[:-1], 10)
