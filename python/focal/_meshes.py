"""The mesh functions: files, curvature (both estimators), focal meshes, checks, vertex normals
and analytic test surfaces."""

from __future__ import annotations

import os
import warnings
from typing import Any, Optional, Sequence

import numpy as np

from . import _focal_ext as _ext
from ._clouds import _cloud_arguments, _viewpoint
from ._errors import InvalidInputError
from ._inputs import (
    _as_rows,
    _finite_positions,
    _int32,
    _mesh_arrays,
    _shape_error,
    _threads,
    _usable_normals,
    _vector,
    _whole,
)
from ._progress import _progress
from ._results import Curvature, FocalMesh, FocalMeshes, Mesh, MeshFindings, Surface


def read_mesh(path: "str | bytes | os.PathLike", *, threads: Optional[int] = None) -> Mesh:
    """Reads an OBJ, PLY (ascii or binary), OFF or STL mesh; the format comes from the extension.

    Vertex order and count are those of the file; polygons are fan-triangulated; normals are
    read when the file has them (``Mesh.N``, else None). Raises FocalIOError naming the file
    and the line, byte offset or element of the problem.
    """
    d = _ext.read_mesh(os.fsencode(path), _threads(threads))
    return Mesh(d["V"], d["F"], d["N"])


def write_mesh(
    path: "str | bytes | os.PathLike", V: Any, F: Any, N: Any = None, *, float32: bool = False
) -> None:
    """Writes V (n, 3), F (m, 3) and optionally N (n, 3) as .ply (binary), .obj or .off, chosen
    by the extension. Numbers are written so that they read back exactly; with ``float32`` as
    float32 (PLY ``float``; text: the shortest form of the float), for smaller files. The file is
    written through a temporary and renamed, so a failed write leaves nothing behind. Raises
    InvalidInputError for invalid arrays, FocalIOError on failure or for .stl."""
    Va, Fa, Na = _mesh_arrays(V, F, N)
    _ext.write_mesh(os.fsencode(path), Va, Fa, Na, bool(float32))


def write_fields(
    path: "str | os.PathLike",
    curvature: "Curvature",
    V: Any = None,
    F: Any = None,
    N: Any = None,
    *,
    ascii: bool = False,
    threads: Optional[int] = None,
    float32: bool = False,
) -> None:
    """Writes a Curvature as ``focal curvature -o`` does (the same bytes for the same estimate;
    ``float32=True`` as ``--float32``: every real number written as the float32 nearest to it,
    PLY positions and normals as ``float``, CSV numbers as the shortest text of the float).

    ``.csv``: one row per vertex, columns k1,k2,H,K,d1x..d1z,d2x..d2z,residual,class (the class
    as a word, NaN as ``nan``), and crease (0/1) when ``curvature.crease`` is not None; V, F, N
    are not needed. ``.ply``: the mesh V (n, 3), F (m, 3)
    with the fields as per-vertex properties (class as uchar codes), binary unless ``ascii``;
    the faces and normals written are those the estimate used (``curvature.F``,
    ``curvature.N``) where it reports them, else F and N as given. Written to a temporary file
    and renamed. Raises InvalidInputError for arrays that do not match, FocalIOError on failure.
    """
    path = os.fsencode(path)
    ext = os.fsdecode(os.path.splitext(path)[1]).lower()
    n = np.asarray(curvature.k1).shape[0]
    fields = {name: _vector(getattr(curvature, name), name, n, dtype) for name, dtype in (
        ("k1", np.float64), ("k2", np.float64), ("H", np.float64), ("K", np.float64),
        ("residual", np.float64), ("point_class", np.uint8), ("rays_used", np.int32),
        ("rays_excluded", np.int32))}
    if curvature.crease is not None:
        fields["crease"] = _vector(curvature.crease, "crease", n, np.uint8)
    for name in ("d1", "d2"):
        fields[name] = _as_rows(getattr(curvature, name), name, np.float64)
        if fields[name].shape[0] != n:
            raise _shape_error(name, f"({n}, 3)", fields[name].shape)
    if ext == ".csv":
        _ext.write_fields(path, fields, None, None, None, True, _threads(threads), bool(float32))
        return
    if ext != ".ply":
        raise InvalidInputError(
            f"{os.fsdecode(path)}: fields are written as .csv or .ply, not {ext!r}"
        )
    if V is None or F is None:
        raise InvalidInputError("write_fields to .ply needs the mesh: V and F")
    used_F = curvature.F if curvature.F is not None else F
    used_N = curvature.N if curvature.N is not None else N
    Va, Fa, Na = _mesh_arrays(V, used_F, used_N)
    if Va.shape[0] != n:
        raise _shape_error("V", f"({n}, 3) like the fields", Va.shape)
    _ext.write_fields(path, fields, Va, Fa, Na, not ascii, _threads(threads), bool(float32))


_PAPER_OPTIONS = {
    "method": "vertex",
    "solver": "closed-form",
    "rings": 1,
    "ray_weighting": "uniform",
    "gaussian_width": 0.0,
    "lm_initial_angles": 8,
    "lm_max_iterations": 50,
    "lm_tolerance": 1e-14,
}
_RECOMMENDED_OPTIONS = {
    "noise_for_two_rings": 0.015,
    "noise_for_three_rings": 0.035,
    "file_agreement": 2.0,
    "outlier_disagreement": 10.0,
}
_COMMON_OPTIONS = {"normals": "auto", "zero_tolerance": 1e-3, "umbilic_tolerance": 1e-2}


#: The estimators of the literature (include/focal/curvature/baselines.h), for comparison.
_BASELINES = ("meyer_2003", "cohen_steiner_morvan_2003", "lachaud_2020", "yang_2006",
              "grinspun_2006")
_ESTIMATORS = ("recommended", "paper") + _BASELINES
#: Point clouds (an input without faces): include/focal/curvature/cloud_curvature.h, CloudOptions.
_CLOUD_OPTIONS = {
    "k": 0,
    "radius": None,
    "adaptive_radius": None,
    "normal_method": "jet",
    "viewpoint": None,
    "outlier_ratio": 3.0,
    "off_surface_ratio": 10.0,
    "orient": "mst",
}
#: Options that only meshes have (the solver applies to clouds too).
_MESH_ONLY = ("normals", "method", "rings", "ray_weighting", "gaussian_width")


def _estimate_options(estimator: str, threads: Optional[int], options: dict) -> dict:
    if estimator not in _ESTIMATORS:
        raise InvalidInputError(
            f"estimator: unknown value {estimator!r} (expected one of {', '.join(_ESTIMATORS)})"
        )
    other = _PAPER_OPTIONS if estimator == "recommended" else _RECOMMENDED_OPTIONS
    given = sorted(k for k, default in other.items() if options[k] != default)
    if given:
        owner = "paper" if estimator == "recommended" else "recommended"
        raise InvalidInputError(
            f"{', '.join(given)}: option(s) of estimator={owner!r}, "
            f"but estimator={estimator!r}"
        )
    o = dict(options)
    o["estimator"] = estimator
    o["threads"] = _threads(threads)
    # As the command line's --rings (1 to 16); the other whole numbers as the C++ int holds them.
    o["rings"] = _whole(o["rings"], "rings", 1, 16)
    for name in ("lm_initial_angles", "lm_max_iterations"):
        o[name] = _int32(o[name], name)
    return o


def _cloud_options(V: Any, cloud: dict, solver: str, threads: Optional[int]) -> tuple:
    """The positions of a cloud and its keywords of curvature() as the extension reads them."""
    P, k, radius, adaptive, t = _cloud_arguments(
        V, cloud["k"], cloud["radius"], cloud["adaptive_radius"], threads
    )
    return P, {
        "k": k,
        "radius": radius,
        "adaptive_radius": adaptive,
        "normal_method": str(cloud["normal_method"]),
        "viewpoint": _viewpoint(cloud["viewpoint"]),
        "solver": solver,
        "outlier_ratio": float(cloud["outlier_ratio"]),
        "off_surface_ratio": float(cloud["off_surface_ratio"]),
        "orient": str(cloud["orient"]),
        "threads": t,
    }


def curvature(
    V: Any,
    F: Any = None,
    N: Any = None,
    *,
    estimator: str = "recommended",
    normals: str = "auto",
    device: str = "cpu",
    tile_vertices: int = 0,
    threads: Optional[int] = None,
    zero_tolerance: float = 1e-3,
    umbilic_tolerance: float = 1e-2,
    # estimator="paper" (include/focal/curvature/curvature.h, CurvatureOptions)
    method: str = "vertex",
    solver: str = "closed-form",
    rings: int = 1,
    ray_weighting: str = "uniform",
    gaussian_width: float = 0.0,
    lm_initial_angles: int = 8,
    lm_max_iterations: int = 50,
    lm_tolerance: float = 1e-14,
    # estimator="recommended" (include/focal/curvature/recommended.h, RecommendedOptions)
    noise_for_two_rings: float = 0.015,
    noise_for_three_rings: float = 0.035,
    file_agreement: float = 2.0,
    outlier_disagreement: float = 10.0,
    # point clouds, F None (include/focal/curvature/cloud_curvature.h, CloudOptions)
    k: int = 0,
    radius: Optional[float] = None,
    adaptive_radius: Optional[float] = None,
    normal_method: str = "jet",
    viewpoint: Optional[Sequence[float]] = None,
    outlier_ratio: float = 3.0,
    off_surface_ratio: float = 10.0,
    orient: str = "mst",
    progress: Any = None,
) -> Curvature:
    """Per-vertex principal curvatures and directions, H and K of a mesh or, with ``F=None``, of
    a point cloud: what ``focal curvature`` computes (the same library call, focal::curvature in
    include/focal/curvature.h, so the same numbers).

    Parameters
    ----------
    V : (n, 3) positions. F : (m, 3) triangles, counter-clockwise seen from outside, or None for
        a point cloud. N : (n, 3) outward vertex normals (need not be unit), or None.
    estimator : ``"recommended"`` (default: jets judge and improve the normals, a wider Gaussian
        neighbourhood on noisy positions; docs/METHOD.md), ``"paper"`` (the paper's method: the
        1-ring two-slit fit of the normals), or a baseline of the literature for comparison
        (meshes only): ``"meyer_2003"``, ``"cohen_steiner_morvan_2003"``, ``"lachaud_2020"``,
        ``"yang_2006"``, ``"grinspun_2006"``. Options of another estimator must keep their
        defaults (InvalidInputError otherwise).
    normals : ``"auto"`` (N when given; else Max's normals from the faces for the paper's
        estimator, jets for the recommended one), ``"file"`` (N, required), or ``"area"``,
        ``"angle"``, ``"max"``: from the faces (paper's estimator only).
    device : ``"cpu"`` or ``"cuda"`` (the paper's per-vertex fit on an NVIDIA GPU, float32;
        DeviceError without one).
    tile_vertices : > 0: estimated tile by tile (at most this many owned vertices a tile): the
        same numbers, the memory of one tile.
    threads : worker threads; None: FOCAL_NUM_THREADS if set, else all. Results do not depend
        on it.
    zero_tolerance, umbilic_tolerance : the classes (|k| x mean edge length <= zero_tolerance is
        zero; k1 - k2 <= umbilic_tolerance * max(|k1|, |k2|) is umbilic).
    method : ``"vertex"`` (two-slit fit over a ring) or ``"triangle"`` (per-triangle equation
        averaged to vertices). solver : ``"closed-form"`` or ``"levenberg-marquardt"``.
    rings : neighbourhood size in rings. ray_weighting : ``"uniform"`` or ``"gaussian"``
        (width gaussian_width; 0: mean edge length x rings). lm_* : Levenberg-Marquardt.
    noise_for_two_rings, noise_for_three_rings, file_agreement, outlier_disagreement : the
        recommended estimator's thresholds (recommended.h).
    k, radius, adaptive_radius, normal_method, viewpoint, outlier_ratio, off_surface_ratio,
    orient : point clouds only, as ``focal curvature``'s --k, --radius, --adaptive-radius,
        --cloud-normals, --viewpoint, --outlier-ratio, --off-surface-ratio, --orient; ``k=0``
        (with no radius) is the adaptive default of the command line (docs/POINTS.md).
    progress : None (a tqdm bar on a terminal when tqdm is installed, else nothing), False
        (nothing), or a callable ``progress(stage, pass_number, fraction)``, called on the
        calling thread: ``(stage, 0, 0.0)`` when a stage begins, ``(stage, 0, 1.0)`` when it
        ends, and ``(stage, k, f)`` as its k-th parallel pass advances (f of that pass done; a
        stage runs one or more passes, how many depends on the input). An exception it raises
        stops the call and is raised by it.

    Returns
    -------
    Curvature with k1, k2, H, K (n,), d1, d2 (n, 3), residual, point_class (PointClass codes),
    ``.undefined`` and what the estimator decided (for a cloud ``cloud``: its plan, and ``N`` the
    normals used). A sphere of radius r with outward normals has k1 = k2 = +1/r. The
    estimator's warnings (inward components reversed, file normals ignored...) are issued as
    Python warnings with the command line's text.

    Raises InvalidInputError for wrong shapes, indices outside V or options out of range or
    that do not apply to the input.
    """
    options = {
        "normals": normals,
        "zero_tolerance": zero_tolerance,
        "umbilic_tolerance": umbilic_tolerance,
        "method": method,
        "solver": solver,
        "rings": rings,
        "ray_weighting": ray_weighting,
        "gaussian_width": gaussian_width,
        "lm_initial_angles": lm_initial_angles,
        "lm_max_iterations": lm_max_iterations,
        "lm_tolerance": lm_tolerance,
        "noise_for_two_rings": noise_for_two_rings,
        "noise_for_three_rings": noise_for_three_rings,
        "file_agreement": file_agreement,
        "outlier_disagreement": outlier_disagreement,
    }
    cloud = {
        "k": k,
        "radius": radius,
        "adaptive_radius": adaptive_radius,
        "normal_method": normal_method,
        "viewpoint": viewpoint,
        "outlier_ratio": outlier_ratio,
        "off_surface_ratio": off_surface_ratio,
        "orient": orient,
    }
    o = _estimate_options(estimator, threads, options)
    o["device"] = str(device)
    o["tile_vertices"] = _whole(tile_vertices, "tile_vertices", 0, 2**31 - 1)
    o["progress"] = _progress(progress)
    if F is None:
        defaults = {**_PAPER_OPTIONS, **_COMMON_OPTIONS}
        given = [name for name in _MESH_ONLY if options[name] != defaults[name]]
        if given:
            raise InvalidInputError(
                f"{', '.join(given)}: option(s) of meshes, but F is None (a point cloud)"
            )
        V, o["cloud"] = _cloud_options(V, cloud, solver, threads)
        F = np.zeros((0, 3), dtype=np.int32)
    else:
        given = sorted(name for name, default in _CLOUD_OPTIONS.items() if cloud[name] != default)
        if given:
            raise InvalidInputError(f"{', '.join(given)}: option(s) of point clouds (F=None)")
    Va, Fa, Na = _mesh_arrays(V, F, N)
    _finite_positions(Va, "V")
    Na = _usable_normals(Na, "N")
    d = _ext.curvature(Va, Fa, Na, o)
    for message in d.pop("warnings"):
        warnings.warn(message, stacklevel=2)
    return Curvature(**d)


def _curvature_options(kwargs: dict) -> tuple:
    known = {**_PAPER_OPTIONS, **_RECOMMENDED_OPTIONS, **_COMMON_OPTIONS}
    unknown = sorted(set(kwargs) - set(known) - {"estimator", "threads"})
    if unknown:
        raise TypeError(f"unexpected keyword argument(s): {', '.join(unknown)}")
    options = {k: kwargs.get(k, default) for k, default in known.items()}
    return kwargs.get("estimator", "recommended"), kwargs.get("threads"), options


def focal_meshes(
    V: Any,
    F: Any,
    N: Any = None,
    *,
    max_distance: float = 0.0,
    drop_faces_at_infinity: bool = False,
    **curvature_options: Any,
) -> FocalMeshes:
    """The two focal meshes Gamma_j = S - N / k_j (paper eq. 2), as ``focal focal-mesh``: the
    curvature estimate (same keywords as ``curvature``), then the focal points on the normals
    it used.

    max_distance : focal points farther than this from their vertex are clamped to it (flag
        ``FocalPointFlag.infinite``); 0: 10 x the bounding-box diagonal.
    drop_faces_at_infinity : leave out faces with a vertex at infinity or undefined.
    """
    estimator, threads, options = _curvature_options(curvature_options)
    o = _estimate_options(estimator, threads, options)
    Va, Fa, Na = _mesh_arrays(V, F, N)
    d = _ext.focal_meshes(Va, Fa, Na, o, float(max_distance), bool(drop_faces_at_infinity))
    for g in ("gamma1", "gamma2"):
        d[g].pop("N", None)  # focal meshes carry no normals
    return FocalMeshes(FocalMesh(**d["gamma1"]), FocalMesh(**d["gamma2"]))


def check_mesh(V: Any, F: Any, N: Any = None, *, threads: Optional[int] = None) -> MeshFindings:
    """Counts what is wrong with a mesh (non-finite or unreferenced vertices, degenerate,
    duplicate or non-manifold faces, inconsistent or inward components, bad normals). Nothing is
    repaired; the estimators accept all of it and flag the vertices concerned."""
    Va, Fa, Na = _mesh_arrays(V, F, N)
    return MeshFindings(**_ext.check_mesh(Va, Fa, Na, _threads(threads)))


def vertex_normals(
    V: Any, F: Any, weighting: str = "max", *, threads: Optional[int] = None
) -> np.ndarray:
    """(n, 3) unit vertex normals from the faces, oriented like them (counter-clockwise =
    outward). ``weighting``: ``"max"`` (Max 1999, exact for vertices on a sphere; the default
    here as in the paper's estimator), ``"area"`` or ``"angle"``. NaN rows for vertices in no
    face or whose sum vanishes."""
    Va, Fa, _ = _mesh_arrays(V, F)
    return _ext.vertex_normals(Va, Fa, str(weighting), _threads(threads))


def generate_surface(
    kind: str = "sphere",
    n: int = 2000,
    *,
    triangulation: str = "regular",
    seed: int = 1,
    a: float = 0.0,
    b: float = 0.0,
    c: float = 0.0,
) -> Surface:
    """An analytic test surface with its exact truth, as ``focal generate``: kind in sphere,
    ellipsoid, torus, cylinder, saddle, monkey-saddle, helix-tube, pear; about ``n`` vertices;
    ``triangulation`` "regular" or "irregular" (random, from ``seed``); shape parameters a, b,
    c (0: each surface's default, e.g. sphere radius a = 1). See include/focal/surfaces/surfaces.h.
    """
    # The range of `focal generate --vertices`.
    vertices = _whole(n, "n", 16, 100_000_000, " vertices")
    d = _ext.generate_surface(str(kind), str(triangulation), vertices,
                              _whole(seed, "seed", 0, 2**64 - 1), float(a), float(b), float(c))
    return Surface(**d)
