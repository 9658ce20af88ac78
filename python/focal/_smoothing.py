"""focal.smooth: meshes and point clouds denoised onto the surface fitted around each point
(include/focal/smoothing/smooth.h, docs/SMOOTH.md)."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, List, Optional

import numpy as np

from . import _focal_ext as _ext
from ._errors import InvalidInputError
from ._inputs import _as_rows, _mesh_arrays, _shape_error, _threads


@dataclass
class Smoothed:
    """What focal.smooth returns: the smoothed positions ``V`` (n, 3, one row per input row, in
    order), the fitted surfaces' unit normals ``N`` (NaN rows where no fit was possible), the
    passes kept, the measured position noise (median fit residual in mean edge lengths or
    spacings) of the input and after each kept pass, the fits' rings (meshes) or neighbours
    (clouds), the points moved back as outliers, the crease points (their count and (n,) flags)
    and the points left unfitted."""

    V: np.ndarray
    N: np.ndarray
    iterations: int = 0
    noise: List[float] = field(default_factory=list)
    rings: int = 0
    neighbours: int = 0
    outliers_moved: int = 0
    crease_points: int = 0
    crease: Optional[np.ndarray] = None
    unfitted: int = 0


def smooth(
    V: Any,
    F: Any = None,
    N: Any = None,
    *,
    iterations: int = 0,
    rings: int = 0,
    k: int = 0,
    keep_creases: bool = False,
    crease_angle: float = 60.0,
    robust: bool = True,
    threads: Optional[int] = None,
) -> Smoothed:
    """A mesh (``F`` (m, 3) faces) or, with ``F=None``, a point cloud denoised: each point moved
    along its normal onto the quadric fitted over its neighbourhood (``rings`` for meshes, ``k``
    nearest for clouds; 0 = chosen from the measured noise), points far off the others'
    surface left out (``robust``) and moved back, ``iterations`` passes (0 = until the noise
    stops falling). ``keep_creases`` fits the two sides of a crease (normals more than
    ``crease_angle`` degrees apart) separately. ``N`` only decides the side of the returned
    normals."""
    if F is None:
        Va = _as_rows(V, "V", np.float64)
        Fa = None
        Na = None
        if N is not None:
            Na = _as_rows(N, "N", np.float64)
            if Na.shape[0] != Va.shape[0]:
                raise _shape_error("N", f"({Va.shape[0]}, 3) like V", Na.shape)
    else:
        Va, Fa, Na = _mesh_arrays(V, F, N)
    for name, value in (("iterations", iterations), ("rings", rings), ("k", k)):
        if int(value) < 0:
            raise InvalidInputError(f"{name} must be >= 0, got {value}")
    d = _ext.smooth(Va, Fa, Na, int(iterations), int(rings), int(k), bool(keep_creases),
                    float(crease_angle), bool(robust), _threads(threads))
    return Smoothed(**d)
