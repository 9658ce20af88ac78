"""Point clouds: curvature and normals of points without connectivity.

``focal.cloud_curvature(points, normals=None)`` takes what Open3D, trimesh or a scanner
gives (``np.asarray(pcd.points)``, ``np.asarray(pcd.normals)``; ``trimesh.PointCloud.vertices``)
and returns the same ``Curvature`` as ``focal.curvature`` on a mesh. ``focal.read_mesh`` reads a
cloud file (PLY/OBJ without faces, PCL's .pcd, LAS, .xyz .xyzn .xyzrgb .pts .txt .csv text)
with ``F`` of shape ``(0, 3)``.
See docs/POINTS.md.
"""

from __future__ import annotations

from typing import Any, Optional, Sequence

import numpy as np

from . import _focal_ext as _ext
from ._errors import InvalidInputError
from ._inputs import _as_rows, _finite_positions, _shape_error, _threads, _usable_normals, _whole
from ._results import Curvature


def _cloud_arguments(
    points: Any,
    k: int,
    radius: Optional[float],
    adaptive_radius: Optional[float],
    threads: Optional[int],
):
    P = _as_rows(points, "points", np.float64)
    if P.shape[0] == 0:
        raise InvalidInputError("no points (no vertices), nothing to compute")
    # The range of the command line's --k.
    k = _whole(k, "k", 0, 1024, " (0: chosen from the cloud)")
    r = 0.0 if radius is None else float(radius)
    if radius is not None and not r > 0.0:
        raise InvalidInputError(f"radius must be None or > 0, got {radius}")
    a = 0.0 if adaptive_radius is None else float(adaptive_radius)
    if adaptive_radius is not None and not (a > 0.0 and np.isfinite(a)):
        raise InvalidInputError(
            f"adaptive_radius must be None or finite and > 0, got {adaptive_radius}"
        )
    return P, int(k), r, a, _threads(threads)


def _viewpoint(viewpoint: Optional[Sequence[float]]):
    return None if viewpoint is None else [float(x) for x in viewpoint]


def cloud_curvature(
    points: Any,
    normals: Any = None,
    *,
    k: int = 0,
    radius: Optional[float] = None,
    adaptive_radius: Optional[float] = None,
    normal_method: str = "jet",
    viewpoint: Optional[Sequence[float]] = None,
    solver: str = "closed-form",
    outlier_ratio: float = 3.0,
    off_surface_ratio: float = 10.0,
    orient: str = "mst",
    threads: Optional[int] = None,
) -> Curvature:
    """Principal curvatures and directions, H and K of a point cloud, by the two-slit fit of the
    normal rays of each point's neighbours (include/focal/curvature/cloud_curvature.h).

    Parameters
    ----------
    points : (n, 3) positions. normals : (n, 3) outward normals (need not be unit), or None:
        estimated (PCA, oriented by a minimum spanning tree or towards ``viewpoint``, then a
        quadratic jet; ``normal_method="pca"`` stops after PCA).
    k : neighbours per point, the k nearest; 0 (the default, as ``focal curvature``): chosen
        from the cloud (16, or 64 where the positions are noisy; the cloud's normals where they
        agree with jets; include/focal/curvature/cloud_curvature.h, docs/POINTS.md).
        radius : the neighbours within this distance instead (at most 1024, the nearest).
    adaptive_radius : c: the neighbours within c times the local spacing instead (the median,
        over the point and its k nearest, of their distances to their k-th nearest; docs/POINTS.md).
    viewpoint : (x, y, z) the scanner position: estimated normals face it.
    orient : how estimated normals get their side: ``"mst"`` (a minimum spanning tree, or the
        viewpoint when given), ``"global"`` (the tree, then the winding number: closed surfaces
        with thin or touching parts; docs/POINTS.md, "Orientation") or ``"viewpoint"``.
    solver : ``"closed-form"`` or ``"levenberg-marquardt"`` (the paper's).
    outlier_ratio : points farther from their 16 nearest than this many times their neighbours'
        median of the same are left out (NaN, ``undefined``); 0 keeps every point (the library
        default 3; docs/notes/points-log.md, "Outliers").
    off_surface_ratio : then points farther from the plane of their 16 nearest than this many
        times those neighbours' RMS distance to it are left out too; 0 keeps them (the library
        default 10; docs/notes/points-log.md, "Near-surface outliers").
    threads : worker threads; None: FOCAL_NUM_THREADS if set, else all. Results do not depend
        on it.

    Returns
    -------
    Curvature (as focal.curvature) with ``N`` the unit normals used. A sphere of radius r with
    outward normals has k1 = k2 = +1/r. NaN and ``undefined`` where a point has no normal or
    fewer than two usable neighbours.
    """
    P, k, r, a, t = _cloud_arguments(points, k, radius, adaptive_radius, threads)
    N = None
    if normals is not None:
        N = _as_rows(normals, "normals", np.float64)
        if N.shape[0] != P.shape[0]:
            raise _shape_error("normals", f"({P.shape[0]}, 3) like points", N.shape)
        N = _usable_normals(N, "normals")
    _finite_positions(P, "points")
    d = _ext.cloud_curvature(
        P, N, k, r, a, normal_method, _viewpoint(viewpoint), solver, float(outlier_ratio),
        float(off_surface_ratio), str(orient), t
    )
    return Curvature(**d)


def cloud_normals(
    points: Any,
    *,
    k: int = 0,
    radius: Optional[float] = None,
    adaptive_radius: Optional[float] = None,
    normal_method: str = "jet",
    viewpoint: Optional[Sequence[float]] = None,
    orient: str = "mst",
    threads: Optional[int] = None,
) -> np.ndarray:
    """(n, 3) unit normals of a point cloud, estimated and consistently oriented, as
    ``focal normals`` and cloud_curvature estimate them (k=0: the default's plan, jets over 16
    neighbours or 64 on noisy positions, NaN rows for the outliers it leaves out; k, radius or
    adaptive_radius: PCA then jets over those; include/focal/curvature/cloud_curvature.h,
    estimate_cloud_normals). NaN rows where a point has fewer than two neighbours. ``orient``
    as cloud_curvature's."""
    P, k, r, a, t = _cloud_arguments(points, k, radius, adaptive_radius, threads)
    return _ext.cloud_normals(P, k, r, a, normal_method, _viewpoint(viewpoint), str(orient), t)
