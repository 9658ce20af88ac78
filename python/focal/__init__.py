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

from . import _focal_ext as _ext
from ._clouds import cloud_curvature, cloud_normals
from ._errors import DeviceError, FocalError, FocalIOError, InvalidInputError
from ._image_space import ImageCurvature, ImageCurvatureContext, image_space_curvature
# The private names the package's other modules (focal.stream, focal.distributed) use, here too.
from ._inputs import _array, _as_rows, _mesh_arrays, _shape_error, _threads, _vector  # noqa: F401
from ._meshes import (  # noqa: F401
    _curvature_options,
    _estimate_options,
    check_mesh,
    curvature,
    focal_meshes,
    generate_surface,
    read_mesh,
    vertex_normals,
    write_fields,
    write_mesh,
)
from ._render import GBuffer, rasterise_gbuffer, render
from ._results import (
    Curvature,
    FocalMesh,
    FocalMeshes,
    FocalPointFlag,
    Mesh,
    MeshFindings,
    PointClass,
    Surface,
)
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

# Point clouds (focal._clouds, docs/POINTS.md).
__all__ += ["cloud_curvature", "cloud_normals"]

# Denoising (focal._smoothing, docs/SMOOTH.md).
from ._smoothing import Smoothed, smooth  # noqa: E402

__all__ += ["Smoothed", "smooth"]
