"""The image-space estimator on G-buffers (paper section 5.1; docs/IMAGE_SPACE.md)."""

from __future__ import annotations

import dataclasses
from typing import Any, Optional

import numpy as np

from . import _focal_ext as _ext
from ._errors import InvalidInputError
from ._inputs import _array, _shape_error, _threads


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
