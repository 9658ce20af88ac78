#!/usr/bin/env python3
"""Curvature estimators of other libraries ("peers"), measured like `focal eval`.

  peers.py signs DIR                 each peer's native and normalised H on the exported unit
                                     sphere (truth +1): the sign conventions, checked
  peers.py directions DIR            which peers give principal directions; the one taken as d1
                                     checked on the exported torus
  peers.py accuracy DIR --csv OUT    every peer on every case exported by `focal eval --export DIR`,
                                     metrics and CSV columns as focal eval's
  peers.py scan MESH... --csv OUT [--fields DIR]
                                     smoothness of H on scanned meshes as `focal eval --scan`
  peers.py timing MESH --focal BIN [--trueform] [--cgal CGAL_PEER] [--only NAME...]
                                     median of 5 runs per peer, ratio to focal's normals +
                                     curvature; focal's whole process too

report.py merges the CSVs into the tables of docs/ACCURACY.md and draws the plots.

Every peer's output is brought to focal's convention: outward normals, a sphere of radius r has
k1 = k2 = H = +1/r and K = +1/r^2 (README "Conventions"). The factors are in PEERS below and
`signs` checks them on the exported sphere.
"""
import argparse
import csv
import math
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time

import numpy as np

# --------------------------------------------------------------------------------------------
# Meshes


def read_ply(path):
    """Vertex properties (dict name -> array) and faces of a PLY as focal writes it."""
    with open(path, "rb") as f:
        header = []
        while True:
            line = f.readline().decode("ascii").strip()
            header.append(line)
            if line == "end_header":
                break
        body = f.read()
    fmt = header[1].split()[1]
    if fmt != "binary_little_endian":
        raise SystemExit(f"{path}: only binary little endian PLY is read here, not {fmt}")
    types = {"double": "<f8", "float": "<f4", "uchar": "u1", "int": "<i4", "float64": "<f8",
             "float32": "<f4", "uint8": "u1", "int32": "<i4"}
    elements, current = [], None
    for line in header:
        words = line.split()
        if words[:1] == ["element"]:
            current = [words[1], int(words[2]), []]
            elements.append(current)
        elif words[:1] == ["property"] and words[1] != "list":
            current[2].append((words[2], types[words[1]]))
    (vname, nv, vprops), (fname, nf, _) = elements[0], elements[1]
    assert vname == "vertex" and fname == "face", path
    vertices = np.frombuffer(body, dtype=np.dtype(vprops), count=nv)
    offset = vertices.nbytes
    # focal writes faces as `list uchar int`: 1 + 12 bytes each, all triangles.
    faces = np.frombuffer(body, dtype=np.dtype([("n", "u1"), ("i", "<i4", 3)]), count=nf,
                          offset=offset)
    if np.any(faces["n"] != 3):
        raise SystemExit(f"{path}: non-triangle faces")
    return {k: vertices[k].astype(float) for k, _ in vprops}, faces["i"].astype(np.int64)


def read_case(folder, slug):
    props, F = read_ply(os.path.join(folder, slug + ".ply"))
    V = np.column_stack([props["x"], props["y"], props["z"]])
    N = np.column_stack([props["nx"], props["ny"], props["nz"]])
    truth = np.genfromtxt(os.path.join(folder, slug + ".truth.csv"), delimiter=",", names=True)
    return V, F, N, truth


def read_scan(path):
    import trimesh
    m = trimesh.load(path, process=False, force="mesh")
    return np.asarray(m.vertices, float), np.asarray(m.faces, np.int64)


def face_edge_lengths(V, F):
    return np.linalg.norm(V[F[:, [1, 2, 0]]] - V[F], axis=2).ravel()


def mean_edge_length(V, F):
    """As focal::mean_edge_length: each edge once per incident face."""
    lengths = face_edge_lengths(V, F)
    return float(lengths[np.isfinite(lengths)].mean())


def vertex_areas(V, F):
    """Sum of the incident triangle areas per vertex (the 1-ring area)."""
    area = 0.5 * np.linalg.norm(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]), axis=1)
    A = np.zeros(len(V))
    np.add.at(A, F.ravel(), np.repeat(area, 3))
    return A


# --------------------------------------------------------------------------------------------
# Peers. Each returns a dict with some of H, K, k1, k2 (per vertex, focal's convention).


def principal(H, K):
    d = np.sqrt(np.maximum(H * H - K, 0))
    return H + d, H - d


def igl_quadric(V, F, N):
    import igl
    # libigl's quadric fit (Panozzo et al. 2010) with its defaults: radius 5, k-ring
    # neighbourhood. PV1 >= PV2; +1/r on a sphere (see `signs`).
    # PD1 is the direction of PV1 (the larger): focal's d1 (checked by `directions`).
    d1, _, k1, k2, _ = igl.principal_curvature(V, F)
    return {"k1": k1, "k2": k2, "H": 0.5 * (k1 + k2), "K": k1 * k2, "d1": d1}


def igl_cotangent(V, F, N):
    import igl
    import scipy.sparse as sp
    # -M^-1 L V is the mean curvature normal 2 H n (L the cotangent matrix, M the mixed Voronoi
    # mass matrix; libigl tutorial 203); H from its component along the area-weighted normal.
    L = igl.cotmatrix(V, F)
    M = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    n = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    HN = -(sp.diags(1.0 / M) @ (L @ V))
    H = 0.5 * np.sum(HN * n, axis=1)
    K = igl.gaussian_curvature(V, F) / M  # angle defect, integrated: divided by the Voronoi area
    k1, k2 = principal(H, K)
    return {"H": H, "K": K, "k1": k1, "k2": k2}


def trimesh_measures(V, F, N):
    import trimesh
    import trimesh.curvature as tc
    # Cohen-Steiner/Morvan curvature *measures* integrated over the ball of radius r around each
    # vertex; divided by pi r^2, the area of the surface inside the ball for small r (exact on a
    # sphere), they are densities. r = 2 mean edge lengths.
    m = trimesh.Trimesh(V, F, process=False)
    r = 2.0 * mean_edge_length(V, F)
    area = math.pi * r * r
    return {"H": tc.discrete_mean_curvature_measure(m, V, r) / area,
            "K": tc.discrete_gaussian_curvature_measure(m, V, r) / area}


def vtk_curvatures(V, F, N):
    import pyvista as pv
    cells = np.hstack([np.full((len(F), 1), 3), F]).ravel()
    mesh = pv.PolyData(V, cells)
    out = {"H": mesh.curvature("mean"), "K": mesh.curvature("gaussian"),
           "k1": mesh.curvature("maximum"), "k2": mesh.curvature("minimum")}
    return out


def meshlab_run(V, F, N, call, directions=False):
    import pymeshlab as ml
    ms = ml.MeshSet()
    ms.add_mesh(ml.Mesh(vertex_matrix=V, face_matrix=F, v_normals_matrix=N))
    call(ms)
    m = ms.current_mesh()
    if m.vertex_number() != len(V):
        raise RuntimeError("pymeshlab changed the vertex count")
    if directions:
        return (m.vertex_scalar_array().copy(), m.vertex_curvature_principal_dir1_matrix().copy(),
                m.vertex_curvature_principal_dir2_matrix().copy())
    return m.vertex_scalar_array().copy()


def meshlab_principal(method):
    def run(V, F, N):
        # The filter leaves one scalar per vertex ("quality"): one run per quantity. autoclean
        # off keeps the vertex order.
        def value(colour):
            return meshlab_run(V, F, N, lambda ms: ms.compute_curvature_principal_directions_per_vertex(
                method=method, curvcolormethod=colour, autoclean=False), directions=True)
        (a, pd1, pd2), (b, _, _) = value("Max Curvature"), value("Min Curvature")
        k1, k2 = np.maximum(a, b), np.minimum(a, b)
        # Measured (and checked by `directions`): the "Min Curvature" scalar b is the larger one
        # in focal's convention at most vertices, and the direction that belongs to b is vcg's
        # PD1 for Taubin and quadric fitting, PD2 for normal cycles. Focal's d1 is the direction
        # of the larger of a and b.
        of_b, of_a = (pd2, pd1) if method == "Normal Cycles" else (pd1, pd2)
        d1 = np.where((b >= a)[:, None], of_b, of_a)
        if method == "Normal Cycles":
            # Measured: vcg's normal cycle tensor is not divided by an area; its eigenvalues are
            # k times 2/3 of the 1-ring area (0.6668 on the regular sphere, see `signs`).
            A = (2.0 / 3.0) * vertex_areas(V, F)
            k1, k2 = k1 / A, k2 / A
        return {"k1": k1, "k2": k2, "H": 0.5 * (k1 + k2), "K": k1 * k2, "d1": d1}
    return run


def meshlab_apss(V, F, N):
    # APSS's "Mean" is k1 + k2 (2.0 on the unit sphere, 1.0 on the unit cylinder): halved. Its
    # K1 / K2 outputs abort the process (double free in pymeshlab 2025.7), so H and K only.
    def value(kind):
        return meshlab_run(V, F, N, lambda ms: ms.compute_curvature_and_color_apss_per_vertex(
            curvaturetype=kind))
    return {"H": 0.5 * value("Mean"), "K": value("Gauss")}


def trueform_principal(V, F, N):
    import trueform as tf
    # trueform's principal curvatures over the k = 2 ring (its tutorial's setting): k0 >= k1 and
    # +1 on the sphere (see `signs`); d0 is the direction of k0, focal's d1.
    mesh = tf.Mesh(np.ascontiguousarray(F, dtype=np.int32), np.ascontiguousarray(V))
    k1, k2, d1, _ = (np.asarray(x, dtype=np.float64)
                     for x in tf.principal_curvatures(mesh, k=2, directions=True))
    return {"k1": k1, "k2": k2, "H": 0.5 * (k1 + k2), "K": k1 * k2, "d1": d1}


CGAL_K = 24  # nearest vertices of CGAL's jet fit (with the vertex itself: about its 2-ring)


def cgal_jets(V, F, N):
    import igl
    # CGAL 5.5's Monge_via_jet_fitting (degree-2 jet, degree-2 Monge form) over the CGAL_K
    # nearest vertices, bench/points/cgal_peer.cpp, built by scripts/accuracy.sh; the binary's
    # path in FOCAL_CGAL_PEER. The fit reads positions only; the area-weighted normal of the faces
    # only orients its Monge form (comply_wrt_given_normal). The binary negates CGAL's sign
    # (a sphere with outward normals has CGAL k = -1/r) into focal's.
    binary = os.environ.get("FOCAL_CGAL_PEER", "")
    if not os.access(binary, os.X_OK):
        raise RuntimeError("FOCAL_CGAL_PEER is not an executable cgal_peer")
    n = igl.per_vertex_normals(V, F, igl.PER_VERTEX_NORMALS_WEIGHTING_TYPE_AREA)
    with tempfile.TemporaryDirectory() as tmp:
        xyz, out = os.path.join(tmp, "in.xyz"), os.path.join(tmp, "out.csv")
        np.savetxt(xyz, np.hstack([V, n]), fmt="%.17g")
        subprocess.run([binary, xyz, str(CGAL_K), out], check=True, capture_output=True)
        r = np.genfromtxt(out, delimiter=",", names=True)
    k1, k2 = r["k1"], r["k2"]
    return {"k1": k1, "k2": k2, "H": 0.5 * (k1 + k2), "K": k1 * k2,
            "d1": np.column_stack([r["d1x"], r["d1y"], r["d1z"]])}


# Display name -> function; NATIVE and FACTOR below document the conventions.
PEERS = {
    "libigl principal_curvature (quadric)": igl_quadric,
    "libigl cotangent H + angle-defect K": igl_cotangent,
    "pymeshlab Taubin": meshlab_principal("Taubin approximation"),
    "pymeshlab normal cycles": meshlab_principal("Normal Cycles"),
    "pymeshlab quadric fitting": meshlab_principal("Quadric Fitting"),
    "pymeshlab APSS": meshlab_apss,
    "trimesh ball measures / pi r^2": trimesh_measures,
    "VTK vtkCurvatures": vtk_curvatures,
    "trueform principal_curvatures(k=2)": trueform_principal,
    f"CGAL jet fitting (k = {CGAL_K})": cgal_jets,
}


def available_peers():
    """PEERS without CGAL's jets when no cgal_peer binary is given (FOCAL_CGAL_PEER)."""
    return {name: peer for name, peer in PEERS.items()
            if peer is not cgal_jets or os.access(os.environ.get("FOCAL_CGAL_PEER", ""), os.X_OK)}

# --------------------------------------------------------------------------------------------
# Metrics, as src/evaluation.cpp


def rms_pair(estimate, exact):
    error = float(np.sum((estimate - exact) ** 2))
    truth = float(np.sum(exact ** 2))
    return error, truth


def umbilic_gap(truth):
    """As focal's evaluation: directions are scored where k1 - k2 > 0.2 max |k| of the surface."""
    return 0.2 * float(np.max(np.maximum(np.abs(truth["k1"]), np.abs(truth["k2"]))))


def line_angles(d, exact):
    """Angles in degrees between the lines of d and exact (mod pi), as focal's
    line_angle_degrees; a zero or non-finite direction counts as 90 degrees."""
    norms = np.linalg.norm(d, axis=1) * np.linalg.norm(exact, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        c = np.minimum(1.0, np.abs(np.sum(d * exact, axis=1)) / norms)
    c = np.where(np.isfinite(c), c, 0.0)
    return np.degrees(np.arccos(c))


def measure(fields, truth, at):
    """ErrorMetrics of focal::evaluate over the vertex indices `at`."""
    m = {"vertices": int(len(at))}
    present = [q for q in ("k1", "k2", "H", "K") if q in fields]
    ok = np.ones(len(at), bool)
    for q in present:
        ok &= np.isfinite(fields[q][at])
    m["undefined"] = int(np.sum(~ok))
    idx = at[ok]
    n = len(idx)
    for q in ("H", "K", "k1", "k2"):
        if q not in fields:
            m["rel_" + q] = m["rms_" + q] = math.nan
            continue
        error, t = rms_pair(fields[q][idx], truth[q][idx])
        m["rel_" + q] = math.sqrt(error / t) if t > 1e-18 * (error + 1.0) else math.nan
        m["rms_" + q] = math.sqrt(error / n) if n > 0 else math.nan
    m["variance_H"] = float(np.var(fields["H"][idx])) if n > 0 else math.nan
    m["median_angle_d1"] = m["mean_angle_d1"] = math.nan
    if "d1" in fields:
        scored = idx[truth["k1"][idx] - truth["k2"][idx] > umbilic_gap(truth)]
        if len(scored):
            exact = np.column_stack([truth["d1x"], truth["d1y"], truth["d1z"]])[scored]
            angles = np.sort(line_angles(np.asarray(fields["d1"], float)[scored], exact))
            # focal's median: the element at n / 2 of the sorted angles (nth_element).
            m["median_angle_d1"] = float(angles[len(angles) // 2])
            m["mean_angle_d1"] = float(angles.mean())
    return m


COLUMNS = ["surface", "triangulation", "noise", "method", "vertices", "undefined", "rel_H",
           "rel_K", "rel_k1", "rel_k2", "rms_H", "rms_K", "rms_k1", "rms_k2", "median_angle_d1",
           "mean_angle_d1", "variance_H", "boundary_vertices", "boundary_rel_H", "category"]


def fmt(x):
    if isinstance(x, str):
        return x
    if isinstance(x, (int, np.integer)):
        return str(int(x))
    return "nan" if math.isnan(x) else f"{x:.4g}"


def cases(folder):
    with open(os.path.join(folder, "cases.csv")) as f:
        return list(csv.DictReader(f))


def cmd_accuracy(args):
    rows, seconds = [], {}
    for case in cases(args.dir):
        V, F, N, truth = read_case(args.dir, case["slug"])
        interior = np.flatnonzero(truth["interior"] == 1)
        near = np.flatnonzero(truth["interior"] == 0)
        for name, peer in available_peers().items():
            start = time.perf_counter()
            fields = peer(V, F, N)
            seconds[name] = seconds.get(name, 0) + time.perf_counter() - start
            m, b = measure(fields, truth, interior), measure(fields, truth, near)
            m.update(surface=case["surface"], triangulation=case["triangulation"],
                     noise=case["noise"], method=name, boundary_vertices=b["vertices"],
                     boundary_rel_H=b["rel_H"], category=case.get("category", "standard"))
            rows.append(m)
        print(f"  {case['slug']}", file=sys.stderr)
    write_csv(args.csv, COLUMNS, rows)
    for name, s in seconds.items():
        print(f"  {name}: {s:.1f} s over all cases", file=sys.stderr)


def cmd_signs(args):
    """Native H of each peer on the exported unit sphere (outward normals, truth H = +1)."""
    V, F, N, truth = read_case(args.dir, "sphere-irregular-clean")
    print("| peer | native output on the unit sphere (truth H = +1, K = +1) | factor applied |"
          " normalised median H |\n|---|---|---|---|")
    bad = []
    for name, peer in available_peers().items():
        fields = peer(V, F, N)
        H = float(np.median(fields["H"]))
        print(f"| {name} | {NATIVE[name]} | {FACTOR[name]} | {H:.4g} |")
        if not 0.9 < H < 1.1:
            bad.append(name)
    if bad:
        raise SystemExit("sign or scale check failed for: " + ", ".join(bad))


# What each peer returns natively on the unit sphere with outward-oriented (counter-clockwise)
# faces, measured with pymeshlab 2025.7.post1, libigl 2.6.3, trimesh 5.2.0, VTK 9.7.2, trueform 0.10.7,
# CGAL 5.5.
NATIVE = {
    "libigl principal_curvature (quadric)": "PV1 = PV2 = +1",
    "libigl cotangent H + angle-defect K": "-M^-1 L V = 2 H n (+2 along the outward normal); "
                                           "gaussian_curvature = integrated angle defect",
    "pymeshlab Taubin": "Max/Min Curvature = +1",
    "pymeshlab normal cycles": "Max/Min = +k x (2/3) 1-ring area (not a density)",
    "pymeshlab quadric fitting": "Max/Min Curvature = +1",
    "pymeshlab APSS": "Mean = k1 + k2 = +2, Gauss = +1",
    "trimesh ball measures / pi r^2": "+H pi r^2 and +K pi r^2 (integrated over the ball)",
    "VTK vtkCurvatures": "Mean = +1, Gauss = +1",
    "trueform principal_curvatures(k=2)": "k0 = k1 = +1 (k0 the larger)",
    f"CGAL jet fitting (k = {CGAL_K})": "Monge coefficients k = -1 (z along the outward normal)",
}
FACTOR = {
    "libigl principal_curvature (quadric)": "none",
    "libigl cotangent H + angle-defect K": "H = <-M^-1 L V, n> / 2; K / Voronoi area",
    "pymeshlab Taubin": "none",
    "pymeshlab normal cycles": "1 / ((2/3) 1-ring area)",
    "pymeshlab quadric fitting": "none",
    "pymeshlab APSS": "H = Mean / 2",
    "trimesh ball measures / pi r^2": "1 / (pi r^2), r = 2 mean edge lengths",
    "VTK vtkCurvatures": "none",
    "trueform principal_curvatures(k=2)": "none",
    f"CGAL jet fitting (k = {CGAL_K})": "-1 (in cgal_peer), k1 and k2 swapped",
}


def cmd_directions(args):
    """Which peers give principal directions, and a check that the direction taken as d1 is the
    one of k1: its median angle to the exact d1 on the exported torus is below 10 degrees."""
    V, F, N, truth = read_case(args.dir, "torus-irregular-clean")
    interior = np.flatnonzero(truth["interior"] == 1)
    print("| peer | gives directions | taken as focal's d1 | median angle to the exact d1 on "
          "the irregular torus (degrees) |\n|---|---|---|---|")
    bad = []
    for name, peer in available_peers().items():
        fields = peer(V, F, N)
        if "d1" not in fields:
            print(f"| {name} | no | | |")
            continue
        angle = measure(fields, truth, interior)["median_angle_d1"]
        print(f"| {name} | yes | {D1_SOURCE[name]} | {angle:.3g} |")
        if not angle < 10:
            bad.append(name)
    if bad:
        raise SystemExit("direction check failed for: " + ", ".join(bad))


D1_SOURCE = {
    "libigl principal_curvature (quadric)": "PD1 (of PV1, the larger)",
    "pymeshlab Taubin": "PD1 where Min >= Max Curvature, else PD2",
    "pymeshlab normal cycles": "PD2 where Min >= Max Curvature, else PD1",
    "pymeshlab quadric fitting": "PD1 where Min >= Max Curvature, else PD2",
    "trueform principal_curvatures(k=2)": "d0 (of k0, the larger)",
    f"CGAL jet fitting (k = {CGAL_K})": "minimal_principal_direction (of CGAL's k2 = -focal's k1)",
}

# --------------------------------------------------------------------------------------------
# Scans (paper Fig. 7), as focal::field_smoothness


def smoothness(V, F, H):
    h = mean_edge_length(V, F)
    ok = np.isfinite(H)
    x = H[ok] * h
    edges = np.unique(np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1),
                      axis=0)
    both = ok[edges[:, 0]] & ok[edges[:, 1]]
    # As focal::field_smoothness: |H h| <= 1e-9 (kSignZero) is round-off and has no sign.
    sign = np.where(H * h > 1e-9, 1, np.where(H * h < -1e-9, -1, 0))
    changes = int(np.sum(sign[edges[both, 0]] * sign[edges[both, 1]] < 0))
    n_edges = int(np.sum(both))
    nan = math.nan
    return {"vertices": len(H), "undefined": int(np.sum(~ok)), "edge_length": h,
            "min_Hh": x.min() if len(x) else nan, "max_Hh": x.max() if len(x) else nan,
            "p1_Hh": np.percentile(x, 1) if len(x) else nan,
            "p99_Hh": np.percentile(x, 99) if len(x) else nan,
            "variance_Hh": float(np.var(x)) if len(x) else nan, "edges": n_edges,
            "sign_changes": changes, "sign_change_fraction": changes / n_edges if n_edges else nan}


SCAN_COLUMNS = ["scan", "method", "vertices", "undefined", "edge_length", "min_Hh", "max_Hh",
                "p1_Hh", "p99_Hh", "variance_Hh", "edges", "sign_changes", "sign_change_fraction"]


def cmd_scan(args):
    rows = []
    for path in args.meshes:
        V, F = read_scan(path)
        name = os.path.splitext(os.path.basename(path))[0]
        N = np.zeros_like(V)  # scans carry no normals; no peer here uses given normals
        for method, peer in available_peers().items():
            H = np.asarray(peer(V, F, N)["H"], float)
            r = smoothness(V, F, H)
            r.update(scan=name, method=method)
            rows.append(r)
            if args.fields:
                os.makedirs(args.fields, exist_ok=True)
                np.save(os.path.join(args.fields, f"{name}.{slug(method)}.npy"), H)
        print(f"  {name}", file=sys.stderr)
    write_csv(args.csv, SCAN_COLUMNS, rows)


def write_csv(path, columns, rows):
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(columns)
        for r in rows:
            w.writerow([fmt(r[c]) for c in columns])


def slug(name):
    return re.sub(r"[^a-z0-9]+", "-", name.lower()).strip("-")


# --------------------------------------------------------------------------------------------
# Timing (issue 5)


def focal_run(focal, mesh, *flags):
    """focal's compute (the normals + curvature stage times of `focal -v curvature [flags]`, ms)
    and its whole process (wall ms: read, check, compute, write)."""
    start = time.perf_counter()
    out = subprocess.run([focal, "-v", "curvature", mesh, "-o", "/tmp/focal-peers-timing.ply",
                          *flags], capture_output=True, text=True, check=True).stderr
    whole = 1000 * (time.perf_counter() - start)
    stages = dict(re.findall(r"^\s+(normals|curvature):\s+([0-9.]+) ms", out, re.M))
    if set(stages) != {"normals", "curvature"}:
        raise SystemExit("focal -v printed no normals/curvature stage lines:\n" + out)
    return float(stages["normals"]) + float(stages["curvature"]), whole


def trueform_curvatures(V, F, N):
    """trueform's principal curvatures over the k = 2 ring (bench/python/bench.py checks its
    accuracy and sign; timed here only)."""
    import trueform as tf
    mesh = tf.Mesh(np.ascontiguousarray(F, dtype=np.int32), np.ascontiguousarray(V))
    return tf.principal_curvatures(mesh, k=2)


def cgal_jets_ms(cgal_peer, V, N, k=16):
    """CGAL 5.5 Monge_via_jet_fitting (bench/points/cgal_peer: kd-tree, k nearest neighbours,
    degree-2 jet) on the vertices with the file's normals: its fit seconds (ms), and the whole
    process (ms), which reads the points as text."""
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        xyz = os.path.join(d, "points.xyz")
        np.savetxt(xyz, np.column_stack([V, N]), fmt="%.17g")
        start = time.perf_counter()
        out = subprocess.run([cgal_peer, xyz, str(k), os.path.join(d, "out.csv")],
                             capture_output=True, text=True, check=True).stdout
        whole = 1000 * (time.perf_counter() - start)
    return 1000 * float(out.split()[1]), whole


def cmd_timing(args):
    V, F = read_scan(args.mesh)
    N = np.zeros_like(V)
    runs = range(args.runs)
    # The paper's fit (--paper: closed form, 1-ring) is the fast path; the recommended estimator
    # (the default) rates jet, Max and file normals and adds the triangle pass.
    threads = ["--threads", str(args.threads)] if args.threads else []
    paper = [focal_run(args.focal, args.mesh, "--paper", *threads) for _ in runs]
    default = [focal_run(args.focal, args.mesh, *threads) for _ in runs]
    focal = statistics.median(t for t, _ in paper)
    focal_default = statistics.median(t for t, _ in default)
    print(f"Curvature of {os.path.basename(args.mesh)} ({len(V)} vertices), median of {args.runs} "
          f"runs. Compute: mesh in memory (focal: the `normals:` + `curvature:` stage times of "
          f"`focal -v curvature`, {args.threads or os.cpu_count()} threads; the peers as their "
          f"libraries run, in one Python process on NumPy arrays). Whole process: focal's "
          f"command end to end (read, check, compute, write binary PLY).\n")
    print("| method | compute ms | ratio to focal --paper | ratio to focal default | "
          "whole process ms |\n|---|---|---|---|---|")

    def row(name, t, whole="-"):
        print(f"| {name} | {t:.1f} | {t / focal:.2f} | {t / focal_default:.2f} | {whole} |",
              flush=True)

    row("focal curvature --paper (normals + curvature)", focal,
        f"{statistics.median(w for _, w in paper):.0f}")
    row("focal curvature, default: recommended (normals + curvature)", focal_default,
        f"{statistics.median(w for _, w in default):.0f}")
    # Timed without directions (trueform_curvatures) and CGAL through its own binary (--cgal).
    peers = {n: p for n, p in PEERS.items() if p not in (cgal_jets, trueform_principal)}
    if args.trueform:
        peers["trueform principal_curvatures (k = 2)"] = trueform_curvatures
    for name, peer in peers.items():
        if args.only and not any(word in name for word in args.only):
            continue
        times = []
        for _ in runs:
            start = time.perf_counter()
            peer(V, F, N)
            times.append(1000 * (time.perf_counter() - start))
        row(name, statistics.median(times))
    if args.cgal:
        props, _ = read_ply(args.mesh)
        normals = np.column_stack([props["nx"], props["ny"], props["nz"]])
        results = [cgal_jets_ms(args.cgal, V, normals) for _ in runs]
        row("CGAL 5.5 Monge_via_jet_fitting (k = 16, file normals)",
            statistics.median(t for t, _ in results),
            f"{statistics.median(w for _, w in results):.0f} (reads text)")


# --------------------------------------------------------------------------------------------


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    a = sub.add_parser("accuracy")
    a.add_argument("dir")
    a.add_argument("--csv", required=True)
    s = sub.add_parser("signs")
    s.add_argument("dir")
    d = sub.add_parser("directions")
    d.add_argument("dir")
    c = sub.add_parser("scan")
    c.add_argument("meshes", nargs="+")
    c.add_argument("--csv", required=True)
    c.add_argument("--fields", help="save each peer's H per scan as DIR/<scan>.<peer>.npy")
    t = sub.add_parser("timing")
    t.add_argument("mesh")
    t.add_argument("--focal", default="build/release/cli/focal")
    t.add_argument("--runs", type=int, default=5)
    t.add_argument("--threads", type=int, default=0, help="focal's --threads (0: all)")
    t.add_argument("--only", nargs="+", help="only the peers whose name contains one of these")
    t.add_argument("--trueform", action="store_true", help="also trueform (bench/python)")
    t.add_argument("--cgal", help="also CGAL 5.5 jets: bench/points/cgal_peer (build_peers.sh)")
    args = p.parse_args()
    {"accuracy": cmd_accuracy, "signs": cmd_signs, "directions": cmd_directions, "scan": cmd_scan,
     "timing": cmd_timing}[args.command](args)


if __name__ == "__main__":
    main()
