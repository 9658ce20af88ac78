"""Tests of the focal Python package: values against analytic truth, the same numbers as the
`focal` command line, no copies of results, every error path, determinism over threads, the GIL
released, file round trips.

Run by `make test` (the `python` ctest) on the build tree's package. `import focal` is not
guarded: if the extension cannot be imported, collection fails and so does the run.
"""

import csv
import inspect
import math
import os
import pathlib
import re
import subprocess
import threading
import time

import numpy as np
import pytest

import focal

REPO = pathlib.Path(__file__).resolve().parents[2]


def same_bits(a, b):
    a, b = np.asarray(a), np.asarray(b)
    return a.dtype == b.dtype and a.shape == b.shape and a.tobytes() == b.tobytes()


@pytest.fixture(scope="module")
def sphere():
    return focal.generate_surface("sphere", 2000, a=2.0)


@pytest.fixture(scope="module")
def torus():
    return focal.generate_surface("torus", 3000, triangulation="irregular", seed=3)


# --- analytic truth -------------------------------------------------------------------------


def test_sphere_exact_normals_paper_closed_form_is_exact(sphere):
    # Normal rays of a sphere with exact normals all pass through its centre: the two-slit fit
    # is exact, so only rounding separates k from 1/r (r = 2).
    c = focal.curvature(sphere.V, sphere.F, sphere.N, estimator="paper")
    assert not c.undefined.any()
    for k in (c.k1, c.k2, c.H):
        np.testing.assert_allclose(k, 0.5, rtol=1e-9)
    np.testing.assert_allclose(c.K, 0.25, rtol=1e-9)
    assert (c.point_class == focal.PointClass.umbilic).all()
    # d1, d2 unit, tangent and (d1, d2, N) right-handed.
    np.testing.assert_allclose(np.linalg.norm(c.d1, axis=1), 1, atol=1e-12)
    np.testing.assert_allclose(np.einsum("ij,ij->i", c.d1, sphere.N), 0, atol=1e-9)
    np.testing.assert_allclose(np.einsum("ij,ij->i", np.cross(c.d1, c.d2), sphere.N), 1,
                               atol=1e-9)


def test_sphere_recommended_estimator_is_exact(sphere):
    # Max's normals are exact on a sphere and the recommended estimator keeps an exact fit.
    c = focal.curvature(sphere.V, sphere.F)
    np.testing.assert_allclose(c.k1, 0.5, rtol=1e-9)
    np.testing.assert_allclose(c.k2, 0.5, rtol=1e-9)
    assert c.plan["rings"] == 1


def test_inward_normals_flip_the_sign(sphere):
    c = focal.curvature(sphere.V, sphere.F, -sphere.N, estimator="paper")
    np.testing.assert_allclose(c.k1, -0.5, rtol=1e-9)
    np.testing.assert_allclose(c.H, -0.5, rtol=1e-9)


def test_torus_against_truth(torus):
    # Irregular torus, 3000 vertices: mean edge length h ~ 0.1; the 1-ring fit's error is O(h)
    # relative to the largest curvature 1/b = 2.5 (measured below 0.05 x 2.5 on this mesh).
    c = focal.curvature(torus.V, torus.F, torus.N, estimator="paper")
    ok = ~c.undefined
    assert ok.mean() > 0.99
    assert np.median(np.abs(c.H[ok] - (torus.k1 + torus.k2)[ok] / 2)) < 0.05 * 2.5
    assert np.median(np.abs(c.k1[ok] - torus.k1[ok])) < 0.05 * 2.5


def test_vertex_normals_max_exact_on_sphere(sphere):
    N = focal.vertex_normals(sphere.V, sphere.F)
    assert N.shape == sphere.V.shape and N.dtype == np.float64
    np.testing.assert_allclose(N, sphere.N, atol=1e-12)
    # Area weights are exact only to first order in the edge length h (h / r ~ 0.07 here).
    Na = focal.vertex_normals(sphere.V, sphere.F, "area", threads=1)
    assert 1e-6 < np.abs(Na - sphere.N).max() < 0.05


def test_focal_meshes_of_sphere_meet_at_the_centre(sphere):
    fm = focal.focal_meshes(sphere.V, sphere.F, sphere.N, estimator="paper")
    for g in (fm.gamma1, fm.gamma2):
        np.testing.assert_allclose(g.V, 0, atol=1e-9)
        assert (g.flag == focal.FocalPointFlag.finite).all()
        assert len(g.F) == len(sphere.F) and same_bits(g.kept_faces, np.arange(len(sphere.F),
                                                                              dtype=np.int32))


def test_focal_meshes_drop_faces_at_infinity():
    cyl = focal.generate_surface("cylinder", 1000)
    fm = focal.focal_meshes(cyl.V, cyl.F, cyl.N, estimator="paper", drop_faces_at_infinity=True,
                            max_distance=50.0)
    assert (fm.gamma2.flag == focal.FocalPointFlag.infinite).mean() > 0.5
    assert len(fm.gamma2.F) < len(cyl.F)
    assert np.linalg.norm(fm.gamma2.V - cyl.V, axis=1).max() <= 50.0 + 1e-9


def test_check_mesh(sphere):
    clean = focal.check_mesh(sphere.V, sphere.F, sphere.N)
    assert not clean.has_problems and clean.summary == ""
    assert clean.component_count == 1 and clean.boundary_edge_count == 0
    F = np.vstack([sphere.F, sphere.F[:1]])
    found = focal.check_mesh(sphere.V, F)
    assert found.has_problems and found.duplicate_face_count == 1
    assert "duplicate face" in found.summary


def test_undefined_vertex_is_nan():
    s = focal.generate_surface("sphere", 500)
    V = np.vstack([s.V, [[5.0, 5.0, 5.0]]])  # in no face
    c = focal.curvature(V, s.F, estimator="paper")
    assert c.undefined[-1] and not c.undefined[:-1].any()
    assert math.isnan(c.k1[-1]) and np.isnan(c.d1[-1]).all()


def test_to_dict(sphere):
    c = focal.curvature(sphere.V, sphere.F, sphere.N, estimator="paper")
    d = c.to_dict()
    assert set(d) >= {"k1", "k2", "H", "K", "d1", "d2", "residual", "point_class"}
    assert d["k1"] is c.k1
    assert c.k1.shape == (len(sphere.V),) and c.d1.shape == (len(sphere.V), 3)
    assert c.point_class.dtype == np.uint8


# --- the same numbers as the command line ---------------------------------------------------


def cli():
    path = os.environ.get("FOCAL_CLI")
    if not path:
        candidate = REPO / "build" / "release" / "cli" / "focal"
        if not candidate.exists():
            pytest.skip("no focal command (set FOCAL_CLI; `make test` does)")
        path = str(candidate)
    assert os.access(path, os.X_OK), f"FOCAL_CLI={path} is not executable"
    return path


def read_cli_csv(path):
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    header, body = rows[0], rows[1:]
    cols = {name: [r[i] for r in body] for i, name in enumerate(header)}
    out = {n: np.array([float(x) for x in cols[n]]) for n in header if n != "class"}
    names = [c.name for c in focal.PointClass]
    out["class"] = np.array([names.index(x) for x in cols["class"]], dtype=np.uint8)
    return out


@pytest.mark.parametrize("estimator, flags, with_normals", [
    ("recommended", [], True),
    ("recommended", [], False),
    ("paper", ["--paper"], True),
    ("paper", ["--paper"], False),
])
def test_identical_to_cli(tmp_path, estimator, flags, with_normals):
    s = focal.generate_surface("ellipsoid", 1500, triangulation="irregular", seed=2)
    mesh_path = tmp_path / "ellipsoid.ply"
    focal.write_mesh(mesh_path, s.V, s.F, s.N if with_normals else None)
    out = tmp_path / "k.csv"
    subprocess.run([cli(), "curvature", str(mesh_path), "-o", str(out), *flags], check=True,
                   capture_output=True)
    expected = read_cli_csv(out)
    m = focal.read_mesh(mesh_path)
    assert (m.N is not None) == with_normals
    c = focal.curvature(m.V, m.F, m.N, estimator=estimator)
    for name in ("k1", "k2", "H", "K", "residual"):
        assert same_bits(getattr(c, name), expected[name]), name
    for i, axis in enumerate("xyz"):
        assert same_bits(c.d1[:, i].copy(), expected["d1" + axis])
        assert same_bits(c.d2[:, i].copy(), expected["d2" + axis])
    assert same_bits(c.point_class, expected["class"])


@pytest.mark.parametrize("estimator, flags, with_normals", [
    ("recommended", [], False),
    ("paper", ["--paper"], True),
])
@pytest.mark.parametrize("ext", [".csv", ".ply"])
def test_write_fields_writes_the_clis_bytes(tmp_path, estimator, flags, with_normals, ext):
    s = focal.generate_surface("torus", 1500, triangulation="irregular", seed=4)
    mesh_path = tmp_path / "torus.ply"
    focal.write_mesh(mesh_path, s.V, s.F, s.N if with_normals else None)
    expected, got = tmp_path / ("cli" + ext), tmp_path / ("python" + ext)
    subprocess.run([cli(), "curvature", str(mesh_path), "-o", str(expected), *flags], check=True,
                   capture_output=True)
    m = focal.read_mesh(mesh_path)
    c = focal.curvature(m.V, m.F, m.N, estimator=estimator)
    focal.write_fields(got, c, m.V, m.F, m.N)
    assert got.read_bytes() == expected.read_bytes()


def test_write_fields_errors(tmp_path, sphere):
    c = focal.curvature(sphere.V, sphere.F, sphere.N, estimator="paper")
    with pytest.raises(focal.InvalidInputError, match="needs the mesh"):
        focal.write_fields(tmp_path / "x.ply", c)
    with pytest.raises(focal.InvalidInputError, match=".csv or .ply"):
        focal.write_fields(tmp_path / "x.obj", c, sphere.V, sphere.F)
    with pytest.raises(focal.InvalidInputError, match="V must have shape"):
        focal.write_fields(tmp_path / "x.ply", c, sphere.V[:10], sphere.F)
    with pytest.raises(focal.FocalIOError):
        focal.write_fields(tmp_path / "no" / "x.csv", c)
    assert not (tmp_path / "no").exists() and not list(tmp_path.iterdir())


def read_binary_ply(path):
    """(header lines, vertex records as a NumPy structured array) of a binary little-endian PLY
    with scalar vertex properties."""
    data = pathlib.Path(path).read_bytes()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode().splitlines()
    types = {"float": "<f4", "double": "<f8", "uchar": "u1", "int": "<i4"}
    n, fields, in_vertex = 0, [], False
    for line in header:
        words = line.split()
        if words[:2] == ["element", "vertex"]:
            n, in_vertex = int(words[2]), True
        elif words[0] == "element":
            in_vertex = False
        elif words[0] == "property" and in_vertex:
            fields.append((words[2], types[words[1]]))
    return header, np.frombuffer(data, dtype=np.dtype(fields), count=n, offset=end)


def test_write_fields_float32_holds_the_float_of_every_value(tmp_path, torus):
    c = focal.curvature(torus.V, torus.F, torus.N)
    k1 = np.array(c.k1)
    assert np.isnan(k1).sum() == 0  # undefined rows below are made by hand
    c.k1[:3] = [np.nan, np.inf, 1e300]  # undefined, infinite, beyond float: inf
    names = ["k1", "k2", "H", "K", "d1x", "d1y", "d1z", "d2x", "d2y", "d2z", "residual"]
    values = np.column_stack([c.k1, c.k2, c.H, c.K, c.d1, c.d2, c.residual])
    with np.errstate(over="ignore"):  # 1e300 becomes inf, as in the writer
        values32 = values.astype(np.float32)
    nan = np.isnan(values)
    # CSV: each number the shortest text of its float; class and crease as the double file has.
    focal.write_fields(tmp_path / "f64.csv", c)
    focal.write_fields(tmp_path / "f32.csv", c, float32=True)
    rows32 = list(csv.reader((tmp_path / "f32.csv").open()))
    rows64 = list(csv.reader((tmp_path / "f64.csv").open()))
    assert rows32[0] == rows64[0] == names + ["class", "crease"]
    got = np.array([[np.float32(x) for x in r[:11]] for r in rows32[1:]], dtype=np.float32)
    assert np.array_equal(np.isnan(got), nan) and same_bits(got[~nan], values32[~nan])
    assert [r[11:] for r in rows32] == [r[11:] for r in rows64]
    assert [r[0] for r in rows32[1:4]] == ["nan", "inf", "inf"]
    assert (tmp_path / "f32.csv").stat().st_size < (tmp_path / "f64.csv").stat().st_size * 2 / 3
    # Binary PLY: positions and normals as float too, the class and crease codes unchanged.
    focal.write_fields(tmp_path / "f32.ply", c, torus.V, torus.F, torus.N, float32=True)
    header, v = read_binary_ply(tmp_path / "f32.ply")
    assert not any("double" in line for line in header)
    assert "property float x" in header and "property float nz" in header
    for name, column in zip(["x", "y", "z"], torus.V.T):
        assert same_bits(v[name], column.astype(np.float32))
    for i, name in enumerate(names):
        defined = ~nan[:, i]
        assert same_bits(np.isnan(v[name]), nan[:, i])
        assert same_bits(v[name][defined], values32[defined, i])
    assert same_bits(v["class"], np.asarray(c.point_class, dtype=np.uint8))
    assert same_bits(v["crease"], np.asarray(c.crease, dtype=np.uint8))
    m = focal.read_mesh(tmp_path / "f32.ply")
    assert same_bits(m.V, torus.V.astype(np.float32).astype(np.float64))
    # The default stays doubles.
    focal.write_fields(tmp_path / "f64.ply", c, torus.V, torus.F, torus.N)
    header, v = read_binary_ply(tmp_path / "f64.ply")
    assert "property double x" in header and same_bits(v["x"], torus.V[:, 0])


def test_write_mesh_float32(tmp_path, torus):
    # Binary PLY reads back as the floats; text as the doubles nearest the decimals written,
    # which round to the floats.
    for ext in (".ply", ".obj", ".off", ".xyz"):
        focal.write_mesh(tmp_path / ("m" + ext), torus.V, torus.F, torus.N, float32=True)
        m = focal.read_mesh(tmp_path / ("m" + ext))
        V, N = (m.V, m.N) if ext == ".ply" else (m.V.astype(np.float32), m.N.astype(np.float32))
        assert same_bits(V, torus.V.astype(np.float32).astype(V.dtype)), ext
        assert same_bits(N, torus.N.astype(np.float32).astype(N.dtype)), ext


# --- inputs: dtypes, layouts, one conversion ------------------------------------------------


def test_input_layouts_give_the_same_bits(torus):
    ref = focal.curvature(torus.V, torus.F, torus.N)
    variants = [
        (np.asfortranarray(torus.V), torus.F.astype(np.int64), torus.N),
        (torus.V.tolist(), torus.F.tolist(), torus.N.tolist()),
        (torus.V, np.asfortranarray(torus.F.astype(np.uint32)), np.asfortranarray(torus.N)),
    ]
    for V, F, N in variants:
        c = focal.curvature(V, F, N)
        assert same_bits(c.k1, ref.k1) and same_bits(c.d2, ref.d2)


def test_float32_input_is_the_float32_values(sphere):
    V32 = sphere.V.astype(np.float32)
    a = focal.curvature(V32, sphere.F, estimator="paper")
    b = focal.curvature(V32.astype(np.float64), sphere.F, estimator="paper")
    assert same_bits(a.k1, b.k1)


def test_inputs_in_the_library_layout_are_not_copied(sphere):
    assert focal._as_rows(sphere.V, "V", np.float64) is sphere.V
    assert focal._as_rows(sphere.F, "F", np.int32) is sphere.F
    converted = focal._as_rows(np.asfortranarray(sphere.V, dtype=np.float32), "V", np.float64)
    assert converted.flags.c_contiguous and converted.dtype == np.float64


def test_results_own_the_library_buffers(sphere):
    c = focal.curvature(sphere.V, sphere.F, sphere.N, estimator="paper")
    for name, a in c.to_dict().items():
        # A view on the C++ buffer: NumPy did not allocate (copy) it, and it is not a view of
        # another NumPy array.
        assert not a.flags.owndata, name
        assert not isinstance(a.base, np.ndarray), name
        assert a.flags.c_contiguous and a.flags.writeable, name
    assert not np.shares_memory(c.k1, c.k2)
    # The buffers stay valid after the result object is gone.
    k1 = c.k1
    del c
    np.testing.assert_allclose(k1, 0.5, rtol=1e-9)


# --- determinism and the GIL ----------------------------------------------------------------


@pytest.mark.parametrize("estimator", ["recommended", "paper"])
def test_threads_do_not_change_results(torus, estimator):
    a = focal.curvature(torus.V, torus.F, torus.N, estimator=estimator, threads=1)
    b = focal.curvature(torus.V, torus.F, torus.N, estimator=estimator, threads=2)
    for name, x in a.to_dict().items():
        assert same_bits(x, getattr(b, name)), name


def test_gil_is_released():
    # Two Python threads start the same estimate together (a barrier). If the GIL were held
    # during the computation, the second could not even take its start time before the first
    # returned; released, both computations overlap.
    s = focal.generate_surface("torus", 40000)
    barrier = threading.Barrier(2)
    spans = [None, None]

    def work(i):
        barrier.wait()
        t0 = time.perf_counter()
        focal.curvature(s.V, s.F, s.N, estimator="paper", rings=2, threads=1)
        spans[i] = (t0, time.perf_counter())

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert max(s[0] for s in spans) < min(s[1] for s in spans), spans


# --- files ----------------------------------------------------------------------------------


@pytest.mark.parametrize("ext", [".ply", ".obj", ".off"])
def test_write_read_round_trip(tmp_path, torus, ext):
    path = tmp_path / ("torus" + ext)
    focal.write_mesh(path, torus.V, torus.F, torus.N)
    m = focal.read_mesh(str(path))
    assert same_bits(m.V, torus.V) and same_bits(m.F, torus.F) and same_bits(m.N, torus.N)
    focal.write_mesh(path, torus.V, torus.F)
    assert focal.read_mesh(path).N is None


# --- errors ---------------------------------------------------------------------------------


def test_error_hierarchy():
    assert issubclass(focal.InvalidInputError, ValueError)
    assert issubclass(focal.FocalIOError, OSError)
    assert issubclass(focal.DeviceError, RuntimeError)
    for e in (focal.InvalidInputError, focal.FocalIOError, focal.DeviceError):
        assert issubclass(e, focal.FocalError)


@pytest.mark.parametrize("call, message", [
    (lambda s: focal.curvature(s.V[:, :2], s.F), r"V must have shape \(n, 3\), got shape \(\d+, 2\)"),
    (lambda s: focal.curvature(s.V.ravel(), s.F), r"V must have shape \(n, 3\)"),
    (lambda s: focal.curvature(s.V, s.F[:, :2]), r"F must have shape \(n, 3\)"),
    (lambda s: focal.curvature(s.V, s.F, s.N[:-1]), r"N must have shape \(\d+, 3\) like V"),
    (lambda s: focal.curvature(s.V, s.F.astype(float)), r"F must hold integer vertex indices"),
    (lambda s: focal.curvature(s.V.astype(str), s.F), r"V must hold numbers"),
    (lambda s: focal.curvature([[0, 0], [1]], s.F), r"V"),
    (lambda s: focal.curvature(s.V, s.F.astype(np.int64) + 2**31), r"F holds vertex index"),
    (lambda s: focal.curvature(s.V, s.F.astype(np.int64) - 1), r"F holds vertex index -1"),
    (lambda s: focal.curvature(s.V, s.F - 1), r"face 0 refers to vertex -1"),
    (lambda s: focal.curvature(s.V[:10], s.F), r"refers to vertex 10, but there are 10 vertices"),
    (lambda s: focal.curvature(s.V, s.F, estimator="fast"), r"estimator: unknown value 'fast'"),
    (lambda s: focal.curvature(s.V, s.F, rings=2), r"rings: option\(s\) of estimator='paper'"),
    (lambda s: focal.curvature(s.V, s.F, estimator="paper", file_agreement=3.0),
     r"file_agreement: option\(s\) of estimator='recommended'"),
    (lambda s: focal.curvature(s.V, s.F, normals="file"), r"normal"),
    (lambda s: focal.curvature(s.V, s.F, normals="max"), r"recommended"),
    (lambda s: focal.curvature(s.V, s.F, normals="jets"), r"normals: unknown value 'jets'"),
    (lambda s: focal.curvature(s.V, s.F, estimator="paper", rings=0), r"ring"),
    (lambda s: focal.curvature(s.V, s.F, estimator="paper", method="edge"), r"method"),
    (lambda s: focal.curvature(s.V, s.F, threads=-1), r"threads must be None or >= 0"),
    (lambda s: focal.vertex_normals(s.V, s.F, "cotan"), r"weighting: unknown value 'cotan'"),
    (lambda s: focal.check_mesh(s.V, s.F[:, ::-1][:, :2]), r"F must have shape"),
    (lambda s: focal.focal_meshes(s.V, s.F, max_distance=-1.0), r"max_distance"),
    (lambda s: focal.generate_surface("klein-bottle"), r"klein-bottle"),
    (lambda s: focal.generate_surface("sphere", 3), r"target_vertices|vertices"),
    (lambda s: focal.write_mesh("x.ply", s.V, s.F[:, :1]), r"F must have shape"),
])
def test_invalid_input(sphere, call, message):
    with pytest.raises(focal.InvalidInputError, match=message):
        call(sphere)


def test_unknown_keyword_is_a_type_error(sphere):
    with pytest.raises(TypeError):
        focal.curvature(sphere.V, sphere.F, ringz=2)
    with pytest.raises(TypeError):
        focal.focal_meshes(sphere.V, sphere.F, ringz=2)


def test_io_errors(tmp_path, sphere):
    with pytest.raises(focal.FocalIOError, match="missing.ply") as e:
        focal.read_mesh(tmp_path / "missing.ply")
    assert isinstance(e.value, OSError)
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(focal.FocalIOError, match="bad.off"):
        focal.read_mesh(bad)
    with pytest.raises(focal.FocalIOError, match="txt"):
        focal.read_mesh(tmp_path / "mesh.txt")
    with pytest.raises(focal.FocalIOError):
        focal.write_mesh(tmp_path / "mesh.stl", sphere.V, sphere.F)
    with pytest.raises(focal.FocalIOError):
        focal.write_mesh(tmp_path / "no-such-dir" / "mesh.ply", sphere.V, sphere.F)


# --- the package ----------------------------------------------------------------------------


def test_defaults_are_the_librarys():
    lib = focal._ext.default_options()
    sig = inspect.signature(focal.curvature).parameters
    for name in ("rings", "gaussian_width", "lm_initial_angles", "lm_max_iterations",
                 "lm_tolerance", "zero_tolerance", "umbilic_tolerance", "noise_for_two_rings",
                 "noise_for_three_rings", "file_agreement", "outlier_disagreement"):
        assert sig[name].default == lib[name], name
    assert lib["recommended_zero_tolerance"] == lib["zero_tolerance"]
    assert lib["recommended_umbilic_tolerance"] == lib["umbilic_tolerance"]
    fsig = inspect.signature(focal.focal_meshes).parameters
    assert fsig["max_distance"].default == lib["max_distance"]
    assert fsig["drop_faces_at_infinity"].default == lib["drop_faces_at_infinity"]


def test_version_is_the_cmake_project_version():
    text = (REPO / "CMakeLists.txt").read_text()
    assert focal.__version__ == re.search(r"project\(focal\s+VERSION\s+([0-9.]+)", text).group(1)


def test_point_class_codes():
    assert [c.name for c in focal.PointClass] == [
        "elliptic", "hyperbolic", "parabolic", "umbilic", "flat", "undefined"]
    assert focal.PointClass.undefined == 5


def subdivided_cube(n):
    """The surface of [-1, 1]^3 with an n x n grid on each side, welded, faces outward."""
    index, V, F = {}, [], []

    def vertex(p):
        key = tuple(int(round(x)) for x in p)
        if key not in index:
            index[key] = len(V)
            V.append([2.0 * x / n - 1.0 for x in key])
        return index[key]

    for axis in range(3):
        for side in (0, n):
            u, v = [a for a in range(3) if a != axis]
            for i in range(n):
                for j in range(n):
                    quad = []
                    for di, dj in ((0, 0), (1, 0), (1, 1), (0, 1)):
                        p = [0, 0, 0]
                        p[axis], p[u], p[v] = side, i + di, j + dj
                        quad.append(vertex(p))
                    F += [[quad[0], quad[1], quad[2]], [quad[0], quad[2], quad[3]]]
    V, F = np.array(V), np.array(F, dtype=np.int32)
    # Outward: the face normal along the face centroid (the cube's centre is the origin).
    a, b, c = V[F[:, 0]], V[F[:, 1]], V[F[:, 2]]
    inward = np.einsum("ij,ij->i", np.cross(b - a, c - a), (a + b + c) / 3.0) < 0.0
    F[inward] = F[inward][:, ::-1]
    return V, F


def test_crease_flags_of_a_cube(tmp_path):
    """The recommended estimator flags exactly the vertices on the cube's edges (two or three
    coordinates at +-1: a 90 degree dihedral angle), in the result and the written fields. (With
    8 x 8 cells per side most 2-rings touch an edge, the jets' residuals read as position noise
    and the estimator takes the noisy plan, which has no crease test: measured, hence 16.)"""
    V, F = subdivided_cube(16)
    c = focal.curvature(V, F)
    on_edges = (np.abs(np.abs(V) - 1.0) < 1e-12).sum(axis=1) >= 2
    assert c.crease is not None and c.crease.dtype == np.uint8
    assert np.array_equal(c.crease.astype(bool), on_edges)
    assert focal.curvature(V, F, estimator="paper").crease is None
    out = tmp_path / "cube.csv"
    focal.write_fields(out, c)
    rows = list(csv.DictReader(out.open()))
    assert [int(r["crease"]) for r in rows] == c.crease.tolist()
