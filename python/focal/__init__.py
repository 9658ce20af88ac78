"""focal: principal curvatures, principal directions, mean and Gaussian curvature and focal
meshes of triangle meshes through focal surfaces (Yu, Yin, Gu, McMillan and Gortler, "Focal
Surfaces of Discrete Geometry", SGP 2007), on NumPy arrays.

Conventions (as the C++ library, include/focal/core/mesh.h):

- ``V`` is an ``(n, 3)`` array of vertex positions, ``F`` an ``(m, 3)`` array of 0-based vertex
  indices of triangles, ``N`` an ``(n, 3)`` array of vertex normals (or ``None``).
- Normals point outward; triangles are counter-clockwise seen from outside.
- Curvature is positive where the surface bends away from the normal: a sphere of radius ``r``
  with outward normals has ``k1 = k2 = +1/r``. ``k1 >= k2``; ``d1`` belongs to ``k1``; ``d1``,
  ``d2`` are unit vectors tangent to the normal and ``(d1, d2, N)`` is right-handed.
- Row ``i`` of every per-vertex result belongs to input vertex ``i``. Vertices with no estimate
  have class ``PointClass.undefined`` and NaN in every numeric field (never zeros).

Inputs may be float32 or float64 (positions, normals) and int32 or int64 (faces), C- or
Fortran-ordered, or any array-like; each is converted at most once to the layout the library
views without copying (C-ordered float64 / int32). Results are NumPy arrays that own the
library's buffers (no copy). The GIL is released while the library computes, so Python threads
run estimates in parallel. Results do not depend on ``threads``.
"""

from __future__ import annotations

import dataclasses
import enum
import os
from typing import Any, Optional

import numpy as np

from . import _focal_ext as _ext
from ._errors import DeviceError, FocalError, FocalIOError, InvalidInputError
from ._version import __version__

_ext._set_error_types(InvalidInputError, FocalIOError, DeviceError, FocalError)

__all__ = [
    "Curvature",
    "DeviceError",
    "FocalError",
    "FocalIOError",
    "FocalMesh",
    "FocalMeshes",
    "FocalPointFlag",
    "GBuffer",
    "ImageCurvature",
    "ImageCurvatureContext",
    "InvalidInputError",
    "Mesh",
    "MeshFindings",
    "PointClass",
    "Surface",
    "check_mesh",
    "curvature",
    "focal_meshes",
    "generate_surface",
    "image_space_curvature",
    "rasterise_gbuffer",
    "read_mesh",
    "render",
    "vertex_normals",
    "write_fields",
    "write_mesh",
]

class PointClass(enum.IntEnum):
    """Class of a vertex from its principal curvatures (the codes of ``Curvature.point_class``,
    also written to PLY files by the command line)."""

    elliptic = 0  #: K > 0 and not umbilic
    hyperbolic = 1  #: K < 0
    parabolic = 2  #: exactly one principal curvature near zero
    umbilic = 3  #: k1 ~ k2, not near zero (sphere-like)
    flat = 4  #: both principal curvatures near zero
    undefined = 5  #: no estimate (too few usable rays, singular fit or invalid input there)


class FocalPointFlag(enum.IntEnum):
    """Per-vertex flag of a focal mesh (``FocalMesh.flag``)."""

    finite = 0  #: Gamma = S - N / k
    infinite = 1  #: |k| too small: clamped to max_distance along -sign(k) N
    undefined = 2  #: no curvature at the vertex: the point is the base vertex itself


# --------------------------------------------------------------------------------------------
# Input conversion: one conversion at most, with the argument's name in every message.


def _shape_error(name: str, expected: str, got: Any) -> InvalidInputError:
    return InvalidInputError(f"{name} must have shape {expected}, got shape {got}")


# DLPack device type of host memory (dlpack.h, kDLCPU).
_DLPACK_CPU = 1


def _array(a: Any, name: str) -> np.ndarray:
    """``a`` as a NumPy array without copying where its memory allows: ndarrays as they are,
    DLPack producers on the CPU (PyTorch, JAX, ...) through np.from_dlpack, anything else with
    np.asarray (``__array_interface__``, buffers, nested lists). Arrays on a GPU are an error."""
    if isinstance(a, np.ndarray):
        return a
    if hasattr(a, "__dlpack_device__"):
        device_type, device_id = a.__dlpack_device__()
        if int(device_type) != _DLPACK_CPU:
            raise InvalidInputError(
                f"{name} is in device memory (DLPack device type {int(device_type)}, id "
                f"{int(device_id)}); focal takes host arrays: copy it to the CPU first"
            )
        try:
            return np.from_dlpack(a)
        except (TypeError, BufferError, RuntimeError):
            pass  # a dtype DLPack cannot export to NumPy: asarray below
    try:
        return np.asarray(a)
    except (ValueError, TypeError) as e:
        raise InvalidInputError(f"{name} is not an array: {e}") from None


def _as_rows(a: Any, name: str, dtype: type) -> np.ndarray:
    """``a`` as a C-ordered ``(n, 3)`` array of ``dtype``: ``a`` itself when it already is one,
    else one converted copy."""
    arr = _array(a, name)
    if arr.ndim != 2 or arr.shape[1] != 3:
        raise _shape_error(name, "(n, 3)", arr.shape)
    kind = arr.dtype.kind
    if dtype is np.float64:
        if kind not in "fiu":
            raise InvalidInputError(f"{name} must hold numbers, got dtype {arr.dtype}")
    else:
        if kind not in "iu":
            raise InvalidInputError(
                f"{name} must hold integer vertex indices, got dtype {arr.dtype}"
            )
        if arr.dtype != np.int32 and arr.size > 0:
            lo, hi = int(arr.min()), int(arr.max())
            if lo < 0 or hi > np.iinfo(np.int32).max:
                bad = lo if lo < 0 else hi
                raise InvalidInputError(
                    f"{name} holds vertex index {bad}, outside [0, 2^31 - 1]"
                )
    return np.ascontiguousarray(arr, dtype=dtype)


def _mesh_arrays(V: Any, F: Any, N: Any = None):
    Va = _as_rows(V, "V", np.float64)
    Fa = _as_rows(F, "F", np.int32)
    Na = None
    if N is not None:
        Na = _as_rows(N, "N", np.float64)
        if Na.shape[0] != Va.shape[0]:
            raise _shape_error("N", f"({Va.shape[0]}, 3) like V", Na.shape)
    return Va, Fa, Na


def _threads(threads: Optional[int]) -> int:
    if threads is None:
        return 0
    t = int(threads)
    if t < 0:
        raise InvalidInputError(f"threads must be None or >= 0, got {threads}")
    return t


# --------------------------------------------------------------------------------------------
# Results.


@dataclasses.dataclass
class Mesh:
    """A triangle mesh as read from a file."""

    V: np.ndarray  #: (n, 3) float64 positions
    F: np.ndarray  #: (m, 3) int32 triangles (polygons are fan-triangulated)
    N: Optional[np.ndarray]  #: (n, 3) float64 normals as written in the file, or None


@dataclasses.dataclass
class Curvature:
    """Per-vertex curvature fields (``(n,)`` float64 unless stated).

    Outward normals; a sphere of radius r has k1 = k2 = +1/r; k1 >= k2; NaN where the vertex is
    ``undefined``.
    """

    k1: np.ndarray  #: larger principal curvature
    k2: np.ndarray  #: smaller principal curvature
    H: np.ndarray  #: mean curvature (k1 + k2) / 2
    K: np.ndarray  #: Gaussian curvature k1 k2
    d1: np.ndarray  #: (n, 3) unit principal direction of k1
    d2: np.ndarray  #: (n, 3) unit principal direction of k2; (d1, d2, normal) right-handed
    residual: np.ndarray  #: RMS residual of the fit (slope units; see curvature.h)
    point_class: np.ndarray  #: (n,) uint8 PointClass codes
    rays_used: np.ndarray  #: (n,) int32 neighbour rays in the fit
    rays_excluded: np.ndarray  #: (n,) int32 neighbours whose normal left the hemisphere
    #: (n, 3) normals the estimator used, or None when they are the N given, as given.
    N: Optional[np.ndarray] = None
    #: (m, 3) faces the estimator used when some were reversed (inward components), else None.
    F: Optional[np.ndarray] = None
    #: What the normals step fixed (counts; see estimate.h NormalsReport).
    normals_report: dict = dataclasses.field(default_factory=dict)
    #: The recommended estimator's plan: noise, position_noise, rings, gaussian, jet_rings,
    #: jet_degree, jet_iterations.
    plan: dict = dataclasses.field(default_factory=dict)
    #: Median angle (radians) of the given normals to the jet normals (NaN without N).
    file_disagreement: float = float("nan")
    #: Whether the recommended estimator used the given normals.
    file_normals_used: bool = False
    #: (n,) uint8, 1 at crease vertices (the recommended estimator's step 5: a sharp edge at the
    #: vertex; the curvature does not exist there), all 0 where it did not look (noisy
    #: positions); None for the paper's estimator.
    crease: Optional[np.ndarray] = None

    @property
    def undefined(self) -> np.ndarray:
        """(n,) bool: vertices with no estimate (their fields are NaN)."""
        return self.point_class == PointClass.undefined

    def to_dict(self) -> dict:
        """The per-vertex arrays by name (k1, k2, H, K, d1, d2, residual, point_class,
        rays_used, rays_excluded, and crease where it is not None), e.g. for ``np.savez`` or a
        pandas DataFrame."""
        names = ("k1", "k2", "H", "K", "d1", "d2", "residual", "point_class", "rays_used",
                 "rays_excluded") + (("crease",) if self.crease is not None else ())
        return {n: getattr(self, n) for n in names}


@dataclasses.dataclass
class FocalMesh:
    """One focal mesh (paper eq. 2): Gamma = S - N / k with the base mesh's connectivity."""

    V: np.ndarray  #: (n, 3) focal points, input vertex order
    F: np.ndarray  #: (k, 3) kept faces
    flag: np.ndarray  #: (n,) uint8 FocalPointFlag codes
    kept_faces: np.ndarray  #: (k,) int32 indices into the base F of the kept faces


@dataclasses.dataclass
class FocalMeshes:
    gamma1: FocalMesh  #: the focal mesh of k1 (its face normals approximate d1)
    gamma2: FocalMesh  #: the focal mesh of k2


@dataclasses.dataclass
class MeshFindings:
    """Counts of the problems of a mesh (include/focal/mesh/check.h). Boundaries and components
    are counted for information only."""

    non_finite_vertex_count: int
    repeated_index_face_count: int
    degenerate_face_count: int
    duplicate_face_count: int
    unreferenced_vertex_count: int
    non_manifold_edge_count: int
    non_manifold_vertex_count: int
    inconsistent_component_count: int
    inward_component_count: int
    non_finite_normal_count: int
    zero_normal_count: int
    non_unit_normal_count: int
    normals_against_faces_count: int
    normals_compared_count: int
    inward_normal_component_count: int
    boundary_edge_count: int
    component_count: int
    has_problems: bool  #: any problem (not boundaries or components) was counted
    summary: str  #: the non-zero problem counts, e.g. "2 non-finite vertices"; "" when none


@dataclasses.dataclass
class Surface:
    """An analytic surface triangulated, with its exact differential geometry per vertex."""

    V: np.ndarray  #: (n, 3) positions
    F: np.ndarray  #: (m, 3) triangles, outward orientation
    N: np.ndarray  #: (n, 3) exact unit outward normals
    k1: np.ndarray  #: (n,) exact principal curvatures, k1 >= k2
    k2: np.ndarray
    d1: np.ndarray  #: (n, 3) exact unit principal directions
    d2: np.ndarray
    uv: np.ndarray  #: (n, 2) parameters of each vertex


# --------------------------------------------------------------------------------------------
# Functions.


def read_mesh(path: "str | os.PathLike", *, threads: Optional[int] = None) -> Mesh:
    """Reads an OBJ, PLY (ascii or binary), OFF or STL mesh; the format comes from the extension.

    Vertex order and count are those of the file; polygons are fan-triangulated; normals are
    read when the file has them (``Mesh.N``, else None). Raises FocalIOError naming the file
    and the line, byte offset or element of the problem.
    """
    d = _ext.read_mesh(os.fspath(path), _threads(threads))
    return Mesh(d["V"], d["F"], d["N"])


def write_mesh(
    path: "str | os.PathLike", V: Any, F: Any, N: Any = None, *, float32: bool = False
) -> None:
    """Writes V (n, 3), F (m, 3) and optionally N (n, 3) as .ply (binary), .obj or .off, chosen
    by the extension. Numbers are written so that they read back exactly; with ``float32`` as
    float32 (PLY ``float``; text: the shortest form of the float), for smaller files. The file is
    written through a temporary and renamed, so a failed write leaves nothing behind. Raises
    InvalidInputError for invalid arrays, FocalIOError on failure or for .stl."""
    Va, Fa, Na = _mesh_arrays(V, F, N)
    _ext.write_mesh(os.fspath(path), Va, Fa, Na, bool(float32))


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
    path = os.fspath(path)
    ext = os.path.splitext(path)[1].lower()
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
        raise InvalidInputError(f"{path}: fields are written as .csv or .ply, not {ext!r}")
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


def _estimate_options(estimator: str, threads: Optional[int], options: dict) -> dict:
    if estimator not in ("recommended", "paper"):
        raise InvalidInputError(
            f"estimator: unknown value {estimator!r} (expected 'recommended' or 'paper')"
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
    return o


def curvature(
    V: Any,
    F: Any,
    N: Any = None,
    *,
    estimator: str = "recommended",
    normals: str = "auto",
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
) -> Curvature:
    """Per-vertex principal curvatures and directions, H and K: what ``focal curvature`` computes
    (the same library call, so the same numbers).

    Parameters
    ----------
    V : (n, 3) positions. F : (m, 3) triangles, counter-clockwise seen from outside.
    N : (n, 3) outward vertex normals (need not be unit), or None.
    estimator : ``"recommended"`` (default: jets judge and improve the normals, a wider Gaussian
        neighbourhood on noisy positions; docs/ESTIMATOR.md) or ``"paper"`` (the paper's
        method: the 1-ring two-slit fit of the normals). Options of the other estimator must
        keep their defaults (InvalidInputError otherwise).
    normals : ``"auto"`` (N when given; else Max's normals from the faces for the paper's
        estimator, jets for the recommended one), ``"file"`` (N, required), or ``"area"``,
        ``"angle"``, ``"max"``: from the faces (paper's estimator only).
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

    Returns
    -------
    Curvature with k1, k2, H, K (n,), d1, d2 (n, 3), residual, point_class (PointClass codes),
    ``.undefined`` and what the estimator decided. A sphere of radius r with outward normals has
    k1 = k2 = +1/r.

    Raises InvalidInputError for wrong shapes, indices outside V or options out of range.
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
    o = _estimate_options(estimator, threads, options)
    Va, Fa, Na = _mesh_arrays(V, F, N)
    d = _ext.curvature(Va, Fa, Na, o)
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
    d = _ext.generate_surface(str(kind), str(triangulation), int(n), int(seed), float(a),
                              float(b), float(c))
    return Surface(**d)


# --------------------------------------------------------------------------------------------
# Pictures and G-buffers (headless OpenGL through EGL; docs/RENDER.md) and the image-space
# estimator (paper section 5.1; docs/IMAGE_SPACE.md).


@dataclasses.dataclass
class GBuffer:
    """One view rasterised: per pixel the world position and the unit normal interpolated from
    the vertex normals, row 0 at the top of the image."""

    position: np.ndarray  #: (h, w, 3) float32 world positions, 0 where not covered
    normal: np.ndarray  #: (h, w, 3) float32 unit outward normals, 0 where not covered
    mask: np.ndarray  #: (h, w) uint8, 1 where a triangle covers the pixel
    eye: tuple  #: the camera's eye, world coordinates


@dataclasses.dataclass
class ImageCurvature:
    """Per-pixel curvature of a G-buffer ((h, w) float32 unless stated), in the units of its
    positions. Outward normals: a sphere of radius r has k1 = k2 = +1/r. NaN where not valid."""

    k1: np.ndarray  #: larger principal curvature
    k2: np.ndarray  #: smaller principal curvature, k1 >= k2
    H: np.ndarray  #: (k1 + k2) / 2
    K: np.ndarray  #: k1 k2
    focal_depth1: np.ndarray  #: -1 / k1: the focal point along the normal (+-inf at k1 = 0)
    focal_depth2: np.ndarray  #: -1 / k2
    d1: np.ndarray  #: (h, w, 3) unit principal direction of k1
    d2: np.ndarray  #: (h, w, 3) unit principal direction of k2; (d1, d2, normal) right-handed
    valid: np.ndarray  #: (h, w) uint8, 1 where the fields hold an estimate


def _camera_options(V: np.ndarray, azimuth, elevation, orthographic, field_of_view, margin, eye,
                    target, up, half_extent) -> dict:
    if eye is not None and target is None:
        target = V.mean(axis=0) if V.shape[0] else (0.0, 0.0, 0.0)
    return {
        "azimuth": float(azimuth),
        "elevation": float(elevation),
        "orthographic": bool(orthographic),
        "field_of_view": float(field_of_view),
        "margin": float(margin),
        "eye": None if eye is None else [float(x) for x in eye],
        "target": None if target is None else [float(x) for x in target],
        "up": [float(x) for x in up],
        "half_extent": None if half_extent is None else float(half_extent),
    }


def _normals_for_picture(Va: np.ndarray, Fa: np.ndarray, N: Any) -> np.ndarray:
    if N is None:
        return _ext.vertex_normals(Va, Fa, "max", 0)
    Na = _as_rows(N, "N", np.float64)
    if Na.shape[0] != Va.shape[0]:
        raise _shape_error("N", f"({Va.shape[0]}, 3) like V", Na.shape)
    return Na


def _vector(a: Any, name: str, n: int, dtype: type) -> np.ndarray:
    arr = _array(a, name)
    if arr.shape != (n,):
        raise _shape_error(name, f"({n},)", arr.shape)
    return np.ascontiguousarray(arr, dtype=dtype)


def render(
    V: Any,
    F: Any,
    field: Any,
    N: Any = None,
    *,
    path: "str | os.PathLike | None" = None,
    width: int = 1200,
    height: int = 900,
    colour_map: str = "diverging",
    range: Optional[tuple] = None,
    range_percentile: float = 95.0,
    title: str = "",
    directions: Any = None,
    glyph_count: int = 2500,
    focal_meshes: Optional[FocalMeshes] = None,
    splat_radius: float = 0.0,
    azimuth: float = 0.0,
    elevation: float = 0.0,
    orthographic: bool = False,
    field_of_view: float = 30.0,
    margin: float = 1.05,
    eye: Any = None,
    target: Any = None,
    up: Any = (0.0, 1.0, 0.0),
    half_extent: Optional[float] = None,
    samples: int = 4,
    threads: Optional[int] = None,
) -> np.ndarray:
    """A picture of a per-vertex field on a mesh, as ``focal render``: Lambert shading under a
    headlight, coloured per vertex, white background, title on top, colour bar (or class legend)
    on the right. Rendered with OpenGL on a headless EGL context (Mesa's llvmpipe needs no GPU).

    V (n, 3), F (m, 3); field (n,) values (H, K, k1, k2; or PointClass codes with
    ``colour_map="classes"``); N (n, 3) outward normals for the shading, None: Max's normals
    from the faces.
    colour_map : "diverging" (blue - white - red, white at 0, red positive) or "classes".
    range : (lo, hi) of the diverging map; None: [-P, P], P the range_percentile of |field|.
    directions : (n, 3) d1 or d2, drawn as short segments through about glyph_count vertices.
    focal_meshes : a FocalMeshes of this mesh: two more panels show Gamma_1 and Gamma_2.
    Point clouds (F with 0 rows, e.g. ``np.zeros((0, 3), np.int32)``) are drawn as splats, as
    ``focal render`` on a cloud: a disc per point in the plane normal to its row of N (N None, or
    a non-finite row: the disc faces the eye), shaded as faces are.
    splat_radius : the discs' radius in world units (``--splat-radius``); 0: 0.7 x each point's
    mean distance to its 8 nearest. Ignored on meshes; negative or not finite: InvalidInputError.
    Camera: fitted to the mesh's bounding sphere from (azimuth, elevation) in degrees (0, 0 looks
    along -z), perspective with field_of_view degrees or orthographic; or, with eye, a look-at
    camera from eye to target (default: the mean of V) with up.
    path : also write the picture there as PNG (written to a temporary and renamed).

    Returns the picture as an (height, width, 3) uint8 RGB array, row 0 at the top.
    Raises InvalidInputError for wrong shapes or options, DeviceError when no OpenGL context can
    be had (the message says what was tried), FocalIOError when the PNG cannot be written.
    """
    Va, Fa, _ = _mesh_arrays(V, F)
    if Fa.shape[0] == 0 and N is None:
        Na = np.full(Va.shape, np.nan)  # a cloud without normals: splats facing the eye
    else:
        Na = _normals_for_picture(Va, Fa, N)
    values = _vector(field, "field", Va.shape[0], np.float64)
    dirs = None if directions is None else _as_rows(directions, "directions", np.float64)
    gammas = None
    if focal_meshes is not None:
        gammas = tuple(
            a
            for g in (focal_meshes.gamma1, focal_meshes.gamma2)
            for a in (
                _as_rows(g.V, "focal_meshes V", np.float64),
                _as_rows(g.F, "focal_meshes F", np.int32),
                _vector(g.flag, "focal_meshes flag", Va.shape[0], np.uint8),
            )
        )
    options = _camera_options(Va, azimuth, elevation, orthographic, field_of_view, margin, eye,
                              target, up, half_extent)
    options.update(
        width=int(width),
        height=int(height),
        colour_map=str(colour_map),
        range=None if range is None else (float(range[0]), float(range[1])),
        range_percentile=float(range_percentile),
        title=str(title),
        glyph_count=int(glyph_count),
        splat_radius=float(splat_radius),
        samples=int(samples),
        threads=_threads(threads),
    )
    return _ext.render(Va, Fa, Na, values, options, dirs, gammas,
                       None if path is None else os.fspath(path))


def rasterise_gbuffer(
    V: Any,
    F: Any,
    N: Any = None,
    *,
    width: int = 512,
    height: int = 512,
    azimuth: float = 0.0,
    elevation: float = 0.0,
    orthographic: bool = False,
    field_of_view: float = 30.0,
    margin: float = 1.05,
    eye: Any = None,
    target: Any = None,
    up: Any = (0.0, 1.0, 0.0),
    half_extent: Optional[float] = None,
) -> GBuffer:
    """Rasterises the mesh into a G-buffer (the input of ``image_space_curvature``): per covered
    pixel the world position and the unit normal interpolated (perspective-correct) from N at the
    pixel centre; no multisampling. N None: Max's normals from the faces. The camera keywords are
    those of ``render``. Raises DeviceError when no OpenGL context can be had."""
    Va, Fa, _ = _mesh_arrays(V, F)
    Na = _normals_for_picture(Va, Fa, N)
    options = _camera_options(Va, azimuth, elevation, orthographic, field_of_view, margin, eye,
                              target, up, half_extent)
    options.update(width=int(width), height=int(height))
    return GBuffer(**_ext.rasterise_gbuffer(Va, Fa, Na, options))


def _pixels(a: Any, name: str, channels: int, dtype: type, shape=None) -> np.ndarray:
    arr = _array(a, name)
    expected = "(h, w, 3)" if channels == 3 else "(h, w)"
    if arr.ndim != (3 if channels == 3 else 2) or (channels == 3 and arr.shape[2] != 3):
        raise _shape_error(name, expected, arr.shape)
    if shape is not None and arr.shape[:2] != shape:
        raise _shape_error(name, f"{shape[:2]} like position", arr.shape)
    if arr.dtype.kind not in ("fiub"):
        raise InvalidInputError(f"{name} must hold numbers, got dtype {arr.dtype}")
    return np.ascontiguousarray(arr, dtype=dtype)


def image_space_curvature(
    position: Any,
    normal: Any,
    mask: Any = None,
    *,
    discontinuity_ratio: float = 4.0,
    window: int = 0,
    threads: Optional[int] = None,
    device: Optional[int] = None,
) -> ImageCurvature:
    """The paper's image-space estimator (section 5.1) on a G-buffer: every pixel solves the
    characteristic equation of the normal rays of its triplet (x, y), (x + 1, y), (x, y + 1).

    position : (h, w, 3) world positions (any units; results are in their inverse units).
    normal : (h, w, 3) **outward** normals (need not be unit): k1 = k2 = +1/r on a sphere of
        radius r seen from outside; inward normals flip the signs.
    mask : (h, w), non-zero where a surface covers the pixel; None: every pixel.
    discontinuity_ratio : a triplet edge longer than this many local pixel footprints is a depth
        discontinuity (invalid); > 1. window : average the shape operators of the
        (2 window + 1)^2 triplets around each pixel (0: none; at most 16).
    device : a CUDA device index to run on the GPU (DeviceError without one); None: the CPU.

    Computes in float32 (the G-buffer's precision): inputs are converted to float32 and copied
    once into the library's G-buffer. Pixels in the last row and column, outside the mask, across
    a discontinuity or with a normal outside the triplet's hemisphere are invalid (NaN, valid 0).
    """
    pos, nor, m = _gbuffer(position, normal, mask)
    d = _ext.image_space_curvature(pos, nor, m, float(discontinuity_ratio), int(window),
                                   _threads(threads), None if device is None else int(device))
    return ImageCurvature(**d)


def _gbuffer(position: Any, normal: Any, mask: Any) -> tuple:
    """position, normal (h, w, 3) float32 and mask (h, w) uint8 (all ones for None), checked."""
    pos = _pixels(position, "position", 3, np.float32)
    nor = _pixels(normal, "normal", 3, np.float32, pos.shape[:2])
    if mask is None:
        m = np.ones(pos.shape[:2], dtype=np.uint8)
    else:
        m = _pixels(_array(mask, "mask") != 0, "mask", 1, np.uint8, pos.shape[:2])
    return pos, nor, m


class ImageCurvatureContext:
    """``image_space_curvature`` on a CUDA device for frames of one size (a viewer, a video):
    the device buffers, a stream and pinned host buffers are allocated once, here, and kept
    until the context is dropped, where the one-shot call allocates them per frame.

    Each frame's fields are the bits of ``image_space_curvature(..., device=device)`` with the
    same options (the same kernels on the same data; docs/GPU.md). Raises DeviceError without
    the CUDA backend or the device, InvalidInputError for a size below 1 x 1 or options out of
    range, and (in ``estimate``) for a frame of another size.
    """

    def __init__(self, width: int, height: int, *, discontinuity_ratio: float = 4.0,
                 window: int = 0, device: int = 0) -> None:
        self._context = _ext.ImageCurvatureCudaContext(
            int(width), int(height), float(discontinuity_ratio), int(window), int(device))
        self.width, self.height, self.device = int(width), int(height), int(device)

    def estimate(self, position: Any, normal: Any, mask: Any = None) -> ImageCurvature:
        """One frame: position, normal (height, width, 3), mask (height, width) or None."""
        pos, nor, m = _gbuffer(position, normal, mask)
        return ImageCurvature(**self._context.estimate(pos, nor, m))


from ._clouds import cloud_curvature, cloud_normals  # noqa: E402  (point clouds, docs/POINTS.md)

__all__ += ["cloud_curvature", "cloud_normals"]
