"""Pictures and G-buffers: headless OpenGL through EGL (docs/RENDER.md)."""

from __future__ import annotations

import dataclasses
import os
from typing import Any, Optional

import numpy as np

from . import _focal_ext as _ext
from ._inputs import _as_rows, _int32, _mesh_arrays, _shape_error, _threads, _vector
from ._results import FocalMeshes


@dataclasses.dataclass
class GBuffer:
    """One view rasterised: per pixel the world position and the unit normal interpolated from
    the vertex normals, row 0 at the top of the image."""

    position: np.ndarray  #: (h, w, 3) float32 world positions, 0 where not covered
    normal: np.ndarray  #: (h, w, 3) float32 unit outward normals, 0 where not covered
    mask: np.ndarray  #: (h, w) uint8, 1 where a triangle covers the pixel
    eye: tuple  #: the camera's eye, world coordinates


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
        width=_int32(width, "width"),
        height=_int32(height, "height"),
        colour_map=str(colour_map),
        range=None if range is None else (float(range[0]), float(range[1])),
        range_percentile=float(range_percentile),
        title=str(title),
        glyph_count=_int32(glyph_count, "glyph_count"),
        splat_radius=float(splat_radius),
        samples=_int32(samples, "samples"),
        threads=_threads(threads),
    )
    return _ext.render(Va, Fa, Na, values, options, dirs, gammas,
                       None if path is None else os.fsencode(path))


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
    options.update(width=_int32(width, "width"), height=_int32(height, "height"))
    return GBuffer(**_ext.rasterise_gbuffer(Va, Fa, Na, options))
