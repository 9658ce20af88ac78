"""The result types of the mesh functions: vertex classes, meshes, curvature fields, focal
meshes, mesh findings and analytic surfaces."""

from __future__ import annotations

import dataclasses
import enum
from typing import Optional

import numpy as np


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
    #: Vertices with more than 1024 vertices within the rings the estimate gathered (a polygon
    #: of thousands of corners): undefined, or fitted on their 1-ring (see the warning).
    crowded_count: int = 0
    #: Point clouds (focal.curvature with F=None): the plan: normals_estimated, spacing (the mean
    #: spacing), noise, k (neighbours of the fit), corrected, outlier_count. None for meshes.
    cloud: Optional[dict] = None

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
