"""focal.cloud_curvature and focal.cloud_normals against analytic truth (docs/POINTS.md)."""

import numpy as np
import pytest

import focal


def sphere_points(n=2000, radius=2.0, seed=1):
    """Random points on a sphere with their exact outward normals."""
    rng = np.random.default_rng(seed)
    N = rng.normal(size=(n, 3))
    N /= np.linalg.norm(N, axis=1, keepdims=True)
    return radius * N, N


def test_sphere_exact_with_exact_normals():
    P, N = sphere_points()
    c = focal.cloud_curvature(P, N)
    # Every normal ray passes through the centre: exact to rounding.
    np.testing.assert_allclose(c.k1, 0.5, atol=1e-12)
    np.testing.assert_allclose(c.k2, 0.5, atol=1e-12)
    assert not c.undefined.any()
    assert c.N.shape == (2000, 3)


def test_sphere_without_normals_is_oriented_outward_and_close():
    P, N = sphere_points(n=5000, seed=2)
    c = focal.cloud_curvature(P.astype(np.float32))  # any float dtype, converted once
    assert (np.einsum("ij,ij->i", c.N, N) > 0.99).all()
    # Jet normals over 16 neighbours of random (not Poisson-disk) samples: measured max |H - 0.5|
    # 0.00057 here; bound 0.005 (1% of H, a margin of about 9).
    assert np.nanmax(np.abs(c.H - 0.5)) < 0.005


def test_cloud_normals_viewpoint_and_options():
    P, N = sphere_points(n=1000, seed=3)
    inward = focal.cloud_normals(P, viewpoint=(0, 0, 0))
    assert (np.einsum("ij,ij->i", inward, N) < 0).all()
    outward = focal.cloud_normals(P, k=24, normal_method="pca")
    assert (np.einsum("ij,ij->i", outward, N) > 0.9).all()


def two_touching_spheres(seed=1):
    """Two spheres of radius 8 touching at the origin, about one point per unit area."""
    P1, N1 = sphere_points(n=800, radius=8.0, seed=seed)
    P2, N2 = sphere_points(n=800, radius=8.0, seed=seed + 10)
    return np.vstack([P1 - [8.0, 0, 0], P2 + [8.0, 0, 0]]), np.vstack([N1, N2])


def test_cloud_normals_orient_global_mends_touching_spheres():
    P, N = two_touching_spheres()
    flipped = lambda M: int((~(np.einsum("ij,ij->i", M, N) > 0)).sum())
    # The tree crosses where the spheres touch and turns one of them inside out; the winding
    # number sets it right but near the contact (docs/POINTS.md, "Orientation"). Measured on
    # these random samples, seeds 1-3: mst 797-800 flipped, global 24-62 (seed 1: 62); bound
    # 80 (5%).
    assert flipped(focal.cloud_normals(P, orient="mst")) >= 700
    assert flipped(focal.cloud_normals(P, orient="global")) <= 80
    # The same for the curvature's normals, and bits for any thread count.
    c = focal.cloud_curvature(P, orient="global", threads=1)
    assert flipped(c.N) <= 80
    np.testing.assert_array_equal(c.N, focal.cloud_curvature(P, orient="global", threads=2).N)
    assert flipped(focal.curvature(P, orient="global").N) <= 80  # the front door's plan
    with pytest.raises(focal.InvalidInputError, match="orient"):
        focal.cloud_normals(P, orient="up")
    with pytest.raises(focal.InvalidInputError, match="viewpoint"):
        focal.cloud_normals(P, orient="viewpoint")


def test_same_result_for_any_thread_count():
    P, _ = sphere_points(n=3000, seed=4)
    a = focal.cloud_curvature(P, threads=1)
    b = focal.cloud_curvature(P, threads=2)
    np.testing.assert_array_equal(a.k1, b.k1)


def test_invalid_input():
    P, N = sphere_points(n=100)
    with pytest.raises(focal.InvalidInputError, match="normals"):
        focal.cloud_curvature(P, N[:10])
    with pytest.raises(focal.InvalidInputError, match="points"):
        focal.cloud_curvature(P[:, :2])
    with pytest.raises(focal.InvalidInputError, match="radius"):
        focal.cloud_curvature(P, radius=-1.0)
    with pytest.raises(focal.InvalidInputError, match="normal_method"):
        focal.cloud_curvature(P, normal_method="svd")
    with pytest.raises(focal.InvalidInputError, match="viewpoint"):
        focal.cloud_normals(P, viewpoint=(1, 2))


def test_outliers_are_left_out():
    P, N = sphere_points(n=2000, seed=5)
    far = np.array([[0.0, 0.0, 5.0], [4.0, -3.0, 1.0]])  # isolated, far off the sphere
    c = focal.cloud_curvature(np.vstack([P, far]), np.vstack([N, [[0, 0, 1], [1, 0, 0]]]))
    assert c.undefined[-2:].all() and np.isnan(c.H[-2:]).all()
    np.testing.assert_allclose(c.H[:-2], 0.5, atol=1e-12)  # exact normals: exact, as without
    kept = focal.cloud_curvature(np.vstack([P, far]), outlier_ratio=0, off_surface_ratio=0)
    assert not np.isnan(kept.H[-2:]).any()
    with pytest.raises(focal.InvalidInputError, match="outlier_ratio"):
        focal.cloud_curvature(P, outlier_ratio=0.5)
    with pytest.raises(focal.InvalidInputError, match="off_surface_ratio"):
        focal.cloud_curvature(P, off_surface_ratio=0.5)


def test_near_surface_outliers_are_left_out():
    """Points 2 and 2.5 mean spacings (0.079) off a sphere, the statistical test off: the
    off-surface test leaves them out and no point of the sphere (docs/notes/points-log.md, "Near-surface
    outliers")."""
    P, N = sphere_points(n=2000, seed=5)
    near = np.array([[0.0, 0.0, 2.2], [0.0, 0.0, -1.8], [2.16, 0.0, 0.0]])
    c = focal.cloud_curvature(np.vstack([P, near]), outlier_ratio=0)
    assert np.isnan(c.H[-3:]).all() and not np.isnan(c.H[:-3]).any()
    kept = focal.cloud_curvature(np.vstack([P, near]), outlier_ratio=0, off_surface_ratio=0)
    assert not np.isnan(kept.H[-3:]).any()


def test_read_mesh_of_a_cloud_has_no_faces(tmp_path):
    P, N = sphere_points(n=500)
    path = tmp_path / "cloud.xyz"
    np.savetxt(path, np.hstack([P, N]))
    mesh = focal.read_mesh(path)
    assert mesh.F.shape == (0, 3)
    np.testing.assert_allclose(mesh.V, P, rtol=1e-15)
    c = focal.cloud_curvature(mesh.V, mesh.N)
    np.testing.assert_allclose(c.H, 0.5, atol=1e-9)


def test_read_mesh_of_a_binary_pcd(tmp_path):
    # PCL's binary layout: little-endian float32 records, fields in the header's order.
    P, N = sphere_points(n=300, seed=3)
    records = np.hstack([P, N]).astype("<f4")
    header = (f"VERSION 0.7\nFIELDS x y z normal_x normal_y normal_z\nSIZE 4 4 4 4 4 4\n"
              f"TYPE F F F F F F\nCOUNT 1 1 1 1 1 1\nWIDTH {len(P)}\nHEIGHT 1\n"
              f"POINTS {len(P)}\nDATA binary\n")
    path = tmp_path / "cloud.pcd"
    path.write_bytes(header.encode() + records.tobytes())
    mesh = focal.read_mesh(path)
    assert mesh.F.shape == (0, 3)
    np.testing.assert_array_equal(mesh.V, records[:, :3].astype(float))
    np.testing.assert_array_equal(mesh.N, records[:, 3:].astype(float))


def test_adaptive_radius():
    P, N = sphere_points(n=2000, seed=6)
    c = focal.cloud_curvature(P, N, adaptive_radius=1.2)
    np.testing.assert_allclose(c.H, 0.5, atol=1e-12)  # exact normals: exact, as with k
    n = focal.cloud_normals(P, adaptive_radius=1.2)
    assert (np.einsum("ij,ij->i", n, N) > 0.9).all()
    with pytest.raises(focal.InvalidInputError, match="adaptive_radius"):
        focal.cloud_curvature(P, adaptive_radius=-1.0)
    with pytest.raises(focal.InvalidInputError, match="adaptive_radius"):
        focal.cloud_normals(P, adaptive_radius=float("nan"))
