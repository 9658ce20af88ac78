"""focal.distributed on a Dask LocalCluster of 2 worker processes: tile by tile, the same bits as
focal.curvature on the whole mesh (meshes with boundaries, several components, one inward, a
non-manifold fin) and on point clouds (graded density, outliers, with and without normals), also
when a worker is killed during the run; the command line's outputs and exit codes.

`import distributed` is not guarded: `make test` installs dask[distributed] into its venv, and a
missing one fails the run.
"""

import os
import signal
import subprocess
import sys

import numpy as np
import pytest
from distributed import Client, LocalCluster

import focal
import focal.distributed as fd


def same_fields(a, b):
    """Every field and the crease flags (None for the paper's estimator) bit for bit."""
    if (a.crease is None) != (b.crease is None):
        return False
    names = fd.FIELDS + (("crease",) if a.crease is not None else ())
    return all(getattr(a, n).tobytes() == getattr(b, n).tobytes() for n in names)


def two_worker_client():
    cluster = LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                           dashboard_address=":0", memory_limit="1GB")
    c = Client(cluster)
    yield c
    c.close()
    cluster.close()


@pytest.fixture(scope="module")
def client():
    yield from two_worker_client()


@pytest.fixture
def own_client():
    """A cluster of the test's own, for the tests that kill a worker: the nanny's restart of the
    killed process is Dask's business, and once (2026-11-24) the nanny closed right after
    restarting it, which left the module's shared cluster one worker short for later tests."""
    yield from two_worker_client()


def joined(*meshes):
    V = np.vstack([m[0] for m in meshes])
    N = np.vstack([m[2] for m in meshes])
    offsets = np.cumsum([0] + [len(m[0]) for m in meshes[:-1]])
    F = np.vstack([m[1] + o for m, o in zip(meshes, offsets)]).astype(np.int32)
    return V, F, N


@pytest.fixture(scope="module")
def awkward():
    """A torus (closed), a saddle (boundary), an ellipsoid turned inward and a fin: three faces on
    one edge of the torus."""
    torus = focal.generate_surface("torus", 1500, triangulation="irregular", seed=2)
    saddle = focal.generate_surface("saddle", 700, triangulation="irregular", seed=3)
    ellipsoid = focal.generate_surface("ellipsoid", 500, triangulation="irregular", seed=4)
    inward = ellipsoid.F[:, [0, 2, 1]]
    V, F, N = joined((torus.V, torus.F, torus.N), (saddle.V + [3, 0, 0], saddle.F, saddle.N),
                     (ellipsoid.V + [0, 3, 0], inward, ellipsoid.N))
    tip = len(V)
    V = np.vstack([V, [[1.0, 0.1, 0.9]]])
    N = np.vstack([N, [[0.0, 0.0, 1.0]]])
    F = np.vstack([F, [[F[0, 0], F[0, 1], tip]]]).astype(np.int32)
    return V, F, N


@pytest.mark.parametrize(
    "options",
    [{}, {"normals": None}, {"estimator": "paper"}, {"estimator": "paper", "normals": "area"},
     {"estimator": "paper", "rings": 2, "ray_weighting": "gaussian"},
     {"estimator": "paper", "method": "triangle", "normals": "max"}],
    ids=["recommended", "recommended-no-normals", "paper", "paper-area", "paper-2-rings",
         "paper-triangle"],
)
def test_tiles_on_dask_give_the_whole_mesh_bits(client, awkward, options):
    V, F, N = awkward
    options = dict(options)
    if "normals" in options and options["normals"] is None:
        options.pop("normals")
        N = None
    whole = focal.curvature(V, F, N, **options)
    tiled = fd.curvature((V, F, N), client, tile_vertices=400, threads=1, **options)
    assert same_fields(whole, tiled)
    assert not tiled.undefined.all()


def test_noisy_positions_plan_wider_rings_and_stay_identical(client):
    s = focal.generate_surface("monkey-saddle", 2500, triangulation="irregular", seed=5)
    rng = np.random.default_rng(5)
    h = np.mean(np.linalg.norm(s.V[s.F[:, 0]] - s.V[s.F[:, 1]], axis=1))
    V = s.V + (0.1 * h * rng.uniform(-1, 1, len(s.V)))[:, None] * s.N
    whole = focal.curvature(V, s.F)
    assert whole.plan["rings"] == 3  # 10% vertex noise: the widest plan (recommended.h)
    tiled = fd.curvature((V, s.F), client, tile_vertices=300, threads=1)
    assert same_fields(whole, tiled)


@pytest.mark.parametrize("kind", ["mesh", "cloud"])
def test_a_worker_killed_during_the_run_gives_the_same_result(own_client, awkward, cloud, kind):
    client = own_client
    if kind == "mesh":
        V, F, N = awkward
        whole = focal.curvature(V, F, N)
    else:
        P, PN, _ = cloud
        whole = focal.cloud_curvature(P, PN)
    pids = client.run(os.getpid)
    victim = next(iter(pids.values()))
    killed = []

    def kill_on_first_tile(index, ids, fields):
        if not killed:
            os.kill(victim, signal.SIGKILL)
            killed.append(index)

    if kind == "mesh":
        tiled = fd.curvature((V, F, N), client, tile_vertices=60, threads=1,
                             on_tile=kill_on_first_tile)
    else:
        tiled = fd.cloud_curvature(P, PN, client, tile_vertices=100, threads=1,
                                   on_tile=kill_on_first_tile)
    assert killed
    assert same_fields(whole, tiled)
    assert victim not in client.run(os.getpid).values()


def test_on_tile_streams_every_vertex_once(client, awkward):
    V, F, N = awkward
    seen = np.zeros(len(V), int)

    def count(index, ids, fields):
        seen[ids] += 1
        assert len(fields["k1"]) == len(ids)

    fd.curvature((V, F, N), client, tile_vertices=500, threads=1, on_tile=count)
    assert (seen == 1).all()


def test_bad_input_is_an_error_before_any_task(client, awkward):
    V, F, N = awkward
    with pytest.raises(focal.InvalidInputError, match="tile_vertices"):
        fd.curvature((V, F, N), client, tile_vertices=0)
    with pytest.raises(focal.InvalidInputError, match="face 0 refers to vertex"):
        fd.curvature((V, F + len(V), N), client)
    with pytest.raises(focal.InvalidInputError, match="path_or_arrays"):
        fd.curvature(42, client)
    with pytest.raises(focal.FocalIOError):
        fd.curvature("/nonexistent/mesh.ply", client)


# Point clouds: the plan on the whole cloud in the driver, the fit tile by tile on the workers.


@pytest.fixture(scope="module")
def cloud():
    """A torus's vertices as a cloud, its density graded along x (a sparser part: points 0.4 of
    the way and beyond kept with falling probability), with 1% outliers in the bounding box."""
    s = focal.generate_surface("torus", 4000, triangulation="irregular", seed=7)
    rng = np.random.default_rng(7)
    x = (s.V[:, 0] - s.V[:, 0].min()) / np.ptp(s.V[:, 0])
    keep = rng.uniform(size=len(x)) >= 0.6 * np.clip(x - 0.4, 0, None) / 0.6
    P, N = s.V[keep], s.N[keep]
    lo, hi = P.min(axis=0), P.max(axis=0)
    far = lo + (hi - lo) * rng.uniform(size=(len(P) // 100, 3))
    P = np.vstack([P, far])
    N = np.vstack([N, np.tile([0.0, 0.0, 1.0], (len(far), 1))])
    return P, N, len(far)


@pytest.mark.parametrize(
    "normals, options",
    [(True, {}), (False, {}), (False, {"k": 0}), (True, {"k": 0}), (False, {"radius": 0.2}),
     (True, {"outlier_ratio": 0})],
    ids=["normals", "no-normals", "adaptive-no-normals", "adaptive-normals", "radius",
         "no-outlier-test"],
)
def test_cloud_tiles_on_dask_give_the_whole_clouds_bits(client, cloud, normals, options):
    P, N, far = cloud
    N = N if normals else None
    whole = focal.cloud_curvature(P, N, **options)
    if options.get("outlier_ratio") != 0:
        # Many land near the surface in the torus's thin box; the others are left out.
        assert np.isnan(whole.H[-far:]).mean() > 0.3
    tiled = fd.cloud_curvature(P, N, client, tile_vertices=450, threads=1, **options)
    assert same_fields(whole, tiled)
    assert not tiled.undefined.all()


def test_a_cloud_file_runs_as_a_cloud(client, cloud, tmp_path):
    P, N, _ = cloud
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, np.hstack([P, N]), fmt="%.17g")
    m = focal.read_mesh(path)
    whole = focal.cloud_curvature(m.V, m.N)
    seen = np.zeros(len(P), int)

    def count(index, ids, fields):
        seen[ids] += 1

    assert same_fields(whole, fd.curvature(str(path), client, tile_vertices=700, on_tile=count))
    assert (seen == 1).all()
    out = tmp_path / "fields.csv"
    r = run_cli(str(path), "-o", str(out), "--scheduler", client.scheduler.address,
                "--tile-vertices", "900")
    assert r.returncode == 0, r.stderr
    # The command line runs the library's default plan (k=0), as `focal curvature` on a cloud.
    expected = tmp_path / "whole.csv"
    focal.write_fields(expected, focal.cloud_curvature(m.V, m.N, k=0))
    assert out.read_bytes() == expected.read_bytes()
    with pytest.raises(focal.InvalidInputError, match="applies to meshes"):
        fd.curvature(str(path), client, estimator="paper")
    with pytest.raises(focal.InvalidInputError, match="tile_vertices"):
        fd.cloud_curvature(P, None, client, tile_vertices=0)
    with pytest.raises(focal.InvalidInputError, match="normals"):
        fd.cloud_curvature(P, N[:10], client)


def run_cli(*args):
    env = dict(os.environ)
    return subprocess.run([sys.executable, "-m", "focal.distributed", *args],
                          capture_output=True, text=True, env=env, timeout=240)


def test_command_line_writes_the_whole_mesh_fields(tmp_path, client, awkward):
    V, F, N = awkward
    mesh = tmp_path / "mesh.ply"
    focal.write_mesh(mesh, V, F, N)
    out = tmp_path / "fields.npz"
    address = client.scheduler.address
    r = run_cli(str(mesh), "-o", str(out), "--scheduler", address, "--tile-vertices", "700",
                "--threads", "1", "--paper")
    assert r.returncode == 0, r.stderr
    whole = focal.curvature(*(lambda m: (m.V, m.F, m.N))(focal.read_mesh(mesh)), estimator="paper")
    saved = np.load(out)
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)
    csv = tmp_path / "fields.csv"
    assert run_cli(str(mesh), "-o", str(csv), "--scheduler", address).returncode == 0
    # The recommended estimator (the default), written as `focal curvature -o x.csv` writes it:
    # its crease flags as the last column.
    expected = tmp_path / "whole.csv"
    focal.write_fields(expected, focal.curvature(V, F, N))
    assert csv.read_bytes() == expected.read_bytes()
    assert csv.read_text().splitlines()[0].endswith(",class,crease")


def test_command_line_errors(tmp_path, client):
    address = client.scheduler.address
    r = run_cli(str(tmp_path / "missing.ply"), "-o", str(tmp_path / "x.npz"), "--scheduler",
                address)
    assert r.returncode == 2 and "Error:" in r.stderr
    assert not (tmp_path / "x.npz").exists()
    r = run_cli(str(tmp_path / "m.ply"), "-o", str(tmp_path / "x.txt"))
    assert r.returncode == 1 and ".npz or .csv" in r.stderr
    r = run_cli(str(tmp_path / "m.ply"), "-o", str(tmp_path / "x.npz"), "--scheduler", address,
                "--workers", "2")
    assert r.returncode == 1


# Streaming input (focal/stream.py): the driver and the workers read the binary PLY in chunks.


@pytest.fixture(scope="module")
def awkward_ply(tmp_path_factory, awkward):
    """The awkward mesh with an unreferenced vertex and a NaN vertex (its face too), as a binary
    PLY with normals; and its arrays as focal.read_mesh gives them."""
    V, F, N = awkward
    V = np.vstack([V, [[0.5, 0.5, 0.5], [np.nan, 0.0, 0.0]]])
    N = np.vstack([N, [[0.0, 0.0, 1.0], [0.0, 0.0, 1.0]]])
    F = np.vstack([F, [[0, 1, len(V) - 1]]]).astype(np.int32)
    path = tmp_path_factory.mktemp("stream") / "awkward.ply"
    focal.write_mesh(path, V, F, N)
    m = focal.read_mesh(path)
    return path, (m.V, m.F, m.N)


@pytest.mark.parametrize(
    "options, tile_vertices",
    [({}, 400), ({"rings": 2, "ray_weighting": "gaussian"}, 250), ({"method": "triangle"}, 900),
     ({}, 100_000), ({}, None)],
    ids=["paper", "paper-2-rings", "paper-triangle", "one-tile", "one-tile-exactly"],
)
def test_streamed_tiles_give_the_whole_mesh_bits(client, awkward_ply, tmp_path, options,
                                                tile_vertices):
    path, (V, F, N) = awkward_ply
    tile_vertices = tile_vertices or len(V)  # None: the vertex count (no empty tile after it)
    whole = focal.curvature(V, F, N, estimator="paper", **options)
    out = tmp_path / "fields.npz"
    manifest = fd.curvature_stream(path, tmp_path / "parts", client, output=out,
                                   tile_vertices=tile_vertices, threads=1, estimator="paper",
                                   **options)
    saved = np.load(out)
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)
    assert not np.isnan(saved["k1"]).all()
    rows = sum(p["rows"] for p in manifest["parts"])
    assert rows == len(V) and manifest["tile_count"] == len(manifest["parts"])
    assert (manifest["tile_count"] > 1) == (tile_vertices < len(V))
    ids = np.concatenate([np.load(tmp_path / "parts" / p["part"])["ids"]
                          for p in manifest["parts"]])
    assert np.array_equal(np.sort(ids), np.arange(len(V)))  # every vertex in one part


@pytest.fixture(scope="module")
def streamed_meshes(tmp_path_factory, awkward_ply, awkward):
    """Binary PLY meshes with normals for the recommended estimator: the awkward one (an
    unreferenced and a NaN vertex too), its normals turned inward with some rows zero (the
    majority side, rows filled from the faces), and a torus beside a monkey saddle with 5% and
    10% vertex noise (2- and 3-ring plans)."""
    folder = tmp_path_factory.mktemp("streamed")
    out = {"awkward": awkward_ply[0]}
    V, F, N = awkward
    N = -N
    N[::50] = 0.0
    focal.write_mesh(folder / "inward.ply", V, F, N)
    out["inward"] = folder / "inward.ply"
    torus = focal.generate_surface("torus", 1500, triangulation="irregular", seed=6)
    saddle = focal.generate_surface("monkey-saddle", 700, triangulation="irregular", seed=7)
    V, F, N = joined((torus.V, torus.F, torus.N), (saddle.V + [3, 0, 0], saddle.F, saddle.N))
    h = np.mean(np.linalg.norm(V[F[:, 0]] - V[F[:, 1]], axis=1))
    rng = np.random.default_rng(8)
    u = rng.uniform(-1, 1, len(V))[:, None]
    for percent in (5, 10):
        path = folder / f"noise{percent}.ply"
        focal.write_mesh(path, V + percent / 100 * h * u * N, F, N)
        out[f"noise{percent}"] = path
    return out


@pytest.mark.parametrize("mesh, tile_vertices, rings", [
    ("awkward", 400, 1), ("awkward", 100_000, 1), ("inward", 350, 1), ("noise5", 300, 2),
    ("noise10", 300, 3)])
def test_streamed_recommended_estimate_gives_the_whole_mesh_bits(client, streamed_meshes,
                                                                 tmp_path, mesh, tile_vertices,
                                                                 rings):
    """The default estimator streamed: its whole-mesh choices from a pass of tile statistics
    (exact medians over the tiles' files), then the tiles; every field and the crease flags are
    focal.curvature's of the whole file."""
    path = streamed_meshes[mesh]
    m = focal.read_mesh(path)
    whole = focal.curvature(m.V, m.F, m.N)
    assert whole.plan["rings"] == rings
    out = tmp_path / "fields.npz"
    manifest = fd.curvature_stream(path, tmp_path / "parts", client, output=out,
                                   tile_vertices=tile_vertices, threads=1)
    assert (manifest["tile_count"] > 1) == (tile_vertices < len(m.V))
    saved = np.load(out)
    for name in fd.FIELDS + ("crease",):
        assert saved[name].tobytes() == getattr(whole, name).tobytes(), name
    assert not np.isnan(saved["k1"]).all()
    for name in ("noise", "position_noise"):
        assert manifest["choices"][name] == whole.plan[name], name
    assert manifest["choices"]["side"] == (-1.0 if mesh == "inward" else 1.0)
    assert manifest["halo_rings"] == focal._focal_ext.estimate_reach(
        focal._estimate_options("recommended", 1, focal._curvature_options({})[2]),
        manifest["choices"])


def focal_curvature_csv(mesh, out, *args):
    """`focal curvature mesh -o out` (FOCAL_CLI, which `make test` sets), else the same writer
    from Python (the bytes of test_command_line_writes_the_whole_mesh_fields)."""
    cli = os.environ.get("FOCAL_CLI")
    if cli:
        subprocess.run([cli, "curvature", str(mesh), "-o", str(out), *args], check=True,
                       capture_output=True)
    else:
        m = focal.read_mesh(mesh)
        focal.write_fields(out, focal.curvature(m.V, m.F, m.N, estimator="paper" if args
                                                else "recommended"))


@pytest.mark.parametrize("mesh, estimator, tile_vertices", [
    ("awkward", "recommended", 400), ("inward", "recommended", 350),
    ("noise10", "recommended", 300), ("awkward", "paper", 500)])
def test_streamed_csv_parts_and_their_concatenation_are_the_whole_runs_bytes(
        client, streamed_meshes, tmp_path, mesh, estimator, tile_vertices):
    """Parts as CSV: each the header and the rows of its vertices that `focal curvature -o
    x.csv` writes for the whole mesh, and concatenated in input order, that file's bytes."""
    path = streamed_meshes[mesh]
    expected = tmp_path / "whole.csv"
    focal_curvature_csv(path, expected, *(["--paper"] if estimator == "paper" else []))
    lines = expected.read_bytes().splitlines(keepends=True)
    out = tmp_path / "fields.csv"
    manifest = fd.curvature_stream(path, tmp_path / "parts", client, output=out,
                                   tile_vertices=tile_vertices, threads=1, estimator=estimator,
                                   part_format="csv")
    assert out.read_bytes() == expected.read_bytes()
    assert lines[0].endswith(b",class,crease\n") == (estimator == "recommended")
    assert manifest["part_format"] == "csv" and manifest["tile_count"] > 3
    seen = 0
    for part in manifest["parts"]:
        ids = np.load(tmp_path / "parts" / part["ids"])
        rows = (tmp_path / "parts" / part["part"]).read_bytes()
        assert rows == b"".join([lines[0]] + [lines[1 + i] for i in ids.tolist()])
        seen += len(ids)
    assert seen == len(lines) - 1


def test_streamed_part_format_errors(client, awkward_ply, tmp_path):
    path, _ = awkward_ply
    with pytest.raises(focal.InvalidInputError, match="concatenation of csv parts is a .csv"):
        fd.curvature_stream(path, tmp_path / "p1", client, output=tmp_path / "x.npz",
                            part_format="csv")
    with pytest.raises(focal.InvalidInputError, match="part_format"):
        fd.curvature_stream(path, tmp_path / "p2", client, part_format="ply")
    r = run_cli(str(path), "--parts", str(tmp_path / "p3"), "-o", str(tmp_path / "x.csv"),
                "--part-format", "npz")
    assert r.returncode == 1 and "concatenation of npz parts is .npz" in r.stderr


@pytest.mark.parametrize("candidates", [1 << 22, 3])
def test_streamed_median_is_the_librarys(tmp_path, monkeypatch, candidates):
    """The exact median over the tiles' statistics files (a radix selection on the values' bits,
    here also down to the last 16 bits) is the value at rank size / 2 of the finite values, as
    the library's median takes it: ties, negative values, zeros of both signs, NaN and infinite
    values, an empty file."""
    from focal import stream

    monkeypatch.setattr(stream, "_CANDIDATES", candidates)
    rng = np.random.default_rng(9)
    values = np.concatenate([rng.normal(size=3000), np.full(500, 0.25), np.full(40, -0.0),
                             np.zeros(40), [np.nan] * 30, [np.inf, -np.inf],
                             np.nextafter(0.25, 1) + np.zeros(7)])
    rng.shuffle(values)
    files = []
    for k, chunk in enumerate(np.array_split(values, [0, 1000, 1001, 2500])):
        files.append(tmp_path / f"s{k}.npy")
        np.save(files[-1], np.column_stack([chunk, -chunk, np.full(len(chunk), np.nan)]))
    for column, x in ((0, values), (1, -values)):
        finite = np.sort(x[np.isfinite(x)])
        assert stream._median(files, column) == finite[finite.size // 2]
    assert np.isnan(stream._median(files, 2))


def test_streamed_halo_one_ring_short_changes_the_result(client, awkward_ply, tmp_path,
                                                          monkeypatch):
    """The halo is what makes the parts exact: short of the rings the fit reads, vertices near
    tile borders change (the check above can fail). With the file's normals the fit over 2 rings
    reads 2 rings (the reach's third is for normals from the faces), so the halo here is 1."""
    from focal import stream

    path, (V, F, N) = awkward_ply
    whole = focal.curvature(V, F, N, estimator="paper", rings=2)
    p = stream.plan(path, str(tmp_path / "plan"), focal._estimate_options(
        "paper", 1, focal._curvature_options({"rings": 2})[2]), 400)
    assert p["halo_rings"] == 3 and p["tile_count"] > 3
    p["halo_rings"] = 1
    (tmp_path / "parts").mkdir()
    differ = 0
    for t in range(p["tile_count"]):
        part = np.load(tmp_path / "parts" / stream.estimate_tile(p, t, str(tmp_path / "parts"))
                       ["part"])
        differ += int((part["k1"].view(np.int64) != whole.k1[part["ids"]].view(np.int64)).sum())
    assert differ > 0


def test_streamed_input_errors(client, awkward, awkward_ply, tmp_path):
    path, _ = awkward_ply
    V, F, _ = awkward
    no_normals = tmp_path / "no_normals.ply"
    focal.write_mesh(no_normals, V, F)
    for estimator in ("recommended", "paper"):  # the closed components' orientation
        with pytest.raises(focal.InvalidInputError, match="file's normals.*closed components"):
            fd.curvature_stream(no_normals, tmp_path / "p2", client, estimator=estimator)
    with pytest.raises(focal.InvalidInputError, match="file's normals"):
        fd.curvature_stream(path, tmp_path / "p1", client, estimator="paper", normals="area")
    ascii_ply = tmp_path / "ascii.ply"
    ascii_ply.write_text("ply\nformat ascii 1.0\nelement vertex 0\nend_header\n")
    with pytest.raises(focal.FocalIOError, match="binary PLY only"):
        fd.curvature_stream(ascii_ply, tmp_path / "p3", client, estimator="paper")
    data = bytearray(path.read_bytes())
    header_end = data.index(b"end_header\n") + len(b"end_header\n")
    record = 6 * 8  # x y z nx ny nz as double
    n = int(data[:header_end].split(b"element vertex ")[1].split(b"\n")[0])
    first_face = header_end + n * record
    bad = tmp_path / "bad_index.ply"
    bad.write_bytes(data[:first_face + 1] + np.int32(n + 5).tobytes() + data[first_face + 5:])
    with pytest.raises(focal.FocalIOError, match=f"face 0 refers to vertex.*{n} vertices"):
        fd.curvature_stream(bad, tmp_path / "p4", client, estimator="paper")
    quad = tmp_path / "quad.ply"
    quad.write_bytes(data[:first_face] + b"\x04" + data[first_face + 1:])
    with pytest.raises(focal.FocalIOError, match="face 0 has 4 corners"):
        fd.curvature_stream(quad, tmp_path / "p5", client, estimator="paper")
    truncated = tmp_path / "truncated.ply"
    truncated.write_bytes(data[:-7])
    with pytest.raises(focal.FocalIOError, match="truncated"):
        fd.curvature_stream(truncated, tmp_path / "p6", client, estimator="paper")


def test_command_line_streams_parts_and_a_manifest(tmp_path, client, awkward_ply):
    path, (V, F, N) = awkward_ply
    out = tmp_path / "fields.npz"
    r = run_cli(str(path), "--parts", str(tmp_path / "parts"), "-o", str(out), "--scheduler",
                client.scheduler.address, "--tile-vertices", "700", "--threads", "1", "--paper")
    assert r.returncode == 0, r.stderr
    whole = focal.curvature(V, F, N, estimator="paper")
    saved = np.load(out)
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)
    assert (tmp_path / "parts" / "manifest.json").exists()
    csv = tmp_path / "fields.csv"  # the default estimator, CSV parts for a CSV output
    r = run_cli(str(path), "--parts", str(tmp_path / "p3"), "-o", str(csv), "--scheduler",
                client.scheduler.address, "--tile-vertices", "700", "--threads", "1")
    assert r.returncode == 0, r.stderr
    expected = tmp_path / "whole.csv"
    focal_curvature_csv(path, expected)
    assert csv.read_bytes() == expected.read_bytes()
    assert (tmp_path / "p3" / "part-000000.csv").exists()
    no_normals = tmp_path / "no_normals.ply"
    focal.write_mesh(no_normals, V, F)
    r = run_cli(str(no_normals), "--parts", str(tmp_path / "p2"), "--scheduler",
                client.scheduler.address)
    assert r.returncode == 2 and "needs the file's normals" in r.stderr



def _dask(command, *args):
    """A `dask scheduler` or `dask worker` process (the entry points' modules, from this
    Python), as `docs/SCALE.md` starts a cluster by hand."""
    module = f"distributed.cli.dask_{command}"
    return subprocess.Popen([sys.executable, "-m", module, *args], stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL, env=dict(os.environ))


def test_command_line_on_a_scheduler_started_by_hand(tmp_path, awkward_ply):
    """`dask scheduler` and `dask worker` in processes of their own, then the command with
    --scheduler: the in-memory and the streamed runs write `focal curvature`'s CSV bytes."""
    path, _ = awkward_ply
    address_file = tmp_path / "scheduler.json"
    processes = [_dask("scheduler", "--scheduler-file", str(address_file), "--port", "0",
                       "--host", "127.0.0.1", "--no-dashboard")]
    try:
        processes.append(_dask("worker", "--scheduler-file", str(address_file), "--nworkers",
                               "2", "--nthreads", "1", "--memory-limit", "1GB",
                               "--no-dashboard", "--local-directory", str(tmp_path)))
        with Client(scheduler_file=str(address_file), timeout=60) as c:
            c.wait_for_workers(2, timeout=180)
            address = c.scheduler.address
        expected = tmp_path / "whole.csv"
        focal_curvature_csv(path, expected)
        out = tmp_path / "fields.csv"
        r = run_cli(str(path), "-o", str(out), "--scheduler", address, "--tile-vertices", "700")
        assert r.returncode == 0, r.stderr
        assert out.read_bytes() == expected.read_bytes()
        streamed = tmp_path / "streamed.csv"
        r = run_cli(str(path), "--parts", str(tmp_path / "parts"), "-o", str(streamed),
                    "--scheduler", address, "--tile-vertices", "700")
        assert r.returncode == 0, r.stderr
        assert streamed.read_bytes() == expected.read_bytes()
    finally:
        for process in reversed(processes):
            process.terminate()
            process.wait(timeout=60)


def test_command_line_starts_its_own_local_cluster(tmp_path, awkward_ply):
    """Without --scheduler the command runs on a LocalCluster of --workers processes."""
    path, _ = awkward_ply
    expected = tmp_path / "whole.csv"
    focal_curvature_csv(path, expected, "--paper")
    out = tmp_path / "fields.csv"
    r = run_cli(str(path), "-o", str(out), "--workers", "1", "--memory-limit", "1GB",
                "--tile-vertices", "700", "--paper")
    assert r.returncode == 0, r.stderr
    assert out.read_bytes() == expected.read_bytes()

def _vm_data_mb():
    with open("/proc/self/status") as f:
        return next(int(line.split()[1]) / 1024 for line in f if line.startswith("VmData:"))


def _limit_data(extra_mb):
    """Caps this process's data segment (RLIMIT_DATA: heap and private mappings, NumPy's and
    focal's arrays included) at its current size + extra_mb: an allocation beyond fails."""
    import resource

    cap = int((_vm_data_mb() + extra_mb) * 2**20)
    resource.setrlimit(resource.RLIMIT_DATA, (cap, cap))
    return os.getpid()


def _whole_estimate(path):
    m = focal.read_mesh(path)
    return float(np.nansum(focal.curvature(m.V, m.F, m.N, estimator="paper", threads=1).k1))


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="VmData, RLIMIT_DATA: Linux")
def test_a_mesh_larger_than_the_worker_memory_streams_to_the_same_bits(tmp_path):
    """A worker whose memory is capped 40 MB above its idle size cannot estimate the whole
    300K-vertex mesh (measured: it needs 60 to 150 MB more), and the streamed run, 20K-vertex
    tiles, completes in that same worker process with the whole mesh's bits. The cap is the
    kernel's (RLIMIT_DATA: an allocation beyond it fails), not Dask's memory_limit, which
    samples the resident size and restarts a worker over it (a new process, without the cap)."""
    s = focal.generate_surface("torus", 300_000)
    path = tmp_path / "torus.ply"
    focal.write_mesh(path, s.V, s.F, s.N)
    with LocalCluster(n_workers=1, threads_per_worker=1, processes=True,
                      dashboard_address=":0") as cluster, Client(cluster) as client:
        (pid,) = client.run(_limit_data, 40).values()
        with pytest.raises((MemoryError, RuntimeError)):  # bad_alloc, or a thread not started
            client.submit(_whole_estimate, str(path), retries=0).result()
        fd.curvature_stream(path, tmp_path / "parts", client, output=tmp_path / "fields.npz",
                            tile_vertices=20_000, threads=1, estimator="paper")
        assert list(client.run(os.getpid).values()) == [pid]  # the capped process ran it all
    m = focal.read_mesh(path)
    whole = focal.curvature(m.V, m.F, m.N, estimator="paper")
    saved = np.load(tmp_path / "fields.npz")
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)


@pytest.mark.parametrize("order", ["<", ">"], ids=["little-endian", "big-endian"])
def test_streamed_float_ply_with_extra_properties_reads_as_read_mesh(client, awkward, tmp_path,
                                                                      order):
    """Another writer's layout: float vertices with a colour between the normals, uint counts,
    a face property after the list, big- or little-endian: the same arrays as focal.read_mesh,
    so the same bits."""
    V, F, N = awkward
    vertex = np.zeros(len(V), [("x", order + "f4"), ("y", order + "f4"), ("z", order + "f4"),
                               ("red", "u1"), ("nx", order + "f4"), ("ny", order + "f4"),
                               ("nz", order + "f4")])
    for i, axis in enumerate("xyz"):
        vertex[axis], vertex["n" + axis] = V[:, i], N[:, i]
    face = np.zeros(len(F), [("count", order + "u4"), ("corners", order + "i4", (3,)),
                             ("flags", order + "i2")])
    face["count"], face["corners"] = 3, F
    endian = "little" if order == "<" else "big"
    header = (f"ply\nformat binary_{endian}_endian 1.0\ncomment another writer\n"
              f"element vertex {len(V)}\nproperty float x\nproperty float y\nproperty float z\n"
              "property uchar red\nproperty float nx\nproperty float ny\nproperty float nz\n"
              f"element face {len(F)}\nproperty list uint int vertex_indices\n"
              "property short flags\nend_header\n")
    path = tmp_path / "float.ply"
    path.write_bytes(header.encode() + vertex.tobytes() + face.tobytes())
    m = focal.read_mesh(path)
    whole = focal.curvature(m.V, m.F, m.N, estimator="paper")
    out = tmp_path / "fields.npz"
    fd.curvature_stream(path, tmp_path / "parts", client, output=out, tile_vertices=700,
                        threads=1, estimator="paper")
    saved = np.load(out)
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)


def test_a_worker_killed_during_a_streamed_run_gives_the_same_result(own_client, awkward_ply,
                                                                     tmp_path):
    """A task only reads files and writes its part through a rename: Dask reruns those of the
    killed worker elsewhere and the parts are the whole mesh's."""
    client = own_client
    import threading
    import time

    path, (V, F, N) = awkward_ply
    whole = focal.curvature(V, F, N, estimator="paper")
    victim = next(iter(client.run(os.getpid).values()))
    parts = tmp_path / "parts"
    killed = []

    def kill_at_the_first_part():
        deadline = time.monotonic() + 60
        while time.monotonic() < deadline and not list(parts.glob("part-*.npz")):
            time.sleep(0.005)
        os.kill(victim, signal.SIGKILL)
        killed.append(len(list(parts.glob("part-*.npz"))))

    killer = threading.Thread(target=kill_at_the_first_part)
    killer.start()
    manifest = fd.curvature_stream(path, parts, client, output=tmp_path / "fields.npz",
                                   tile_vertices=60, threads=1, estimator="paper")
    killer.join()
    assert killed and killed[0] < manifest["tile_count"]  # killed before the last part
    saved = np.load(tmp_path / "fields.npz")
    assert all(saved[n].tobytes() == getattr(whole, n).tobytes() for n in fd.FIELDS)
    assert victim not in client.run(os.getpid).values()
