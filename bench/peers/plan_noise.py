#!/usr/bin/env python3
"""A NumPy copy of the recommended plan's position-noise measure (noise_at in
src/curvature/recommended_plan.cpp), for diagnosing meshes where it reads truncation as noise
(docs/notes/estimator-log.md, "Why the plan reads truncation as noise there"):

  plan_noise.py MESH.ply [...]     # each with its truth MESH.csv (focal generate --truth)

Per mesh, over every (n / 800)-th vertex: the cubic height jets' residuals over the 2- and
3-ring (unweighted, per degree of freedom, in the frame of the area-weighted normal) in mean
edges, their ratio (the plan finds no noise where it is at least 2.25), the position noise of
noise_at's formula, the rings' RMS radius times the exact |k|max, r2 / (rho2^4 |k|max^3) and the
median dihedral angle. Needs the peers' venv (trimesh, SciPy).
"""
import sys

import numpy as np
import scipy.sparse as sp
import trimesh


def k_rings(mesh, k):
    n = len(mesh.vertices)
    e = mesh.edges_unique
    A = sp.coo_matrix((np.ones(2 * len(e)), (np.r_[e[:, 0], e[:, 1]], np.r_[e[:, 1], e[:, 0]])),
                      shape=(n, n)).tocsr()
    R = sp.identity(n, format="csr")
    for _ in range(k):
        R = ((R + R @ A) > 0).astype(float)
    return R.tolil().rows


def jet_residual(V, n, ring, i):
    a = np.cross(n, [1.0, 0.0, 0.0])
    a = a if np.linalg.norm(a) > 0.1 else np.cross(n, [0.0, 1.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(n, a)
    P = V[ring] - V[i]
    x, y, z = P @ a, P @ b, P @ n
    s = np.sqrt((x * x + y * y).mean())
    x, y = x / s, y / s
    M = np.c_[np.ones_like(x), x, y, x * x, x * y, y * y, x**3, x * x * y, x * y * y, y**3]
    if len(x) <= M.shape[1]:
        return np.nan
    c, *_ = np.linalg.lstsq(M, z, rcond=None)
    r = z - M @ c
    return np.sqrt(r @ r / (len(x) - M.shape[1]))


def main():
    for path in sys.argv[1:]:
        mesh = trimesh.load(path, process=False)
        V, N = mesh.vertices, mesh.vertex_normals
        h = mesh.edges_unique_length.mean()
        truth = np.loadtxt(path.rsplit(".", 1)[0] + ".csv", delimiter=",", skiprows=1)
        k = np.maximum(abs(truth[:, 0]), abs(truth[:, 1]))
        idx = np.arange(0, len(V), max(1, len(V) // 800))
        rings = {r: k_rings(mesh, r) for r in (2, 3)}
        res = {r: np.array([jet_residual(V, N[i], rings[r][i], i) for i in idx]) for r in (2, 3)}
        rho = {r: np.array([np.sqrt(((V[rings[r][i]] - V[i]) ** 2).sum(1).mean()) for i in idx])
               for r in (2, 3)}
        r2, r3 = res[2], res[3]
        truncation = np.maximum(0.0, r3**2 - r2**2) / (1.5**4 - 1.0)
        noise = np.sqrt(np.maximum(0.0, r2**2 - truncation))
        law = r2 / (rho[2] ** 4 * k[idx] ** 3)
        print(f"{path}: {len(V)} v, r2 {np.nanmedian(r2) / h:.3f} h, r3 {np.nanmedian(r3) / h:.3f} h, "
              f"r3/r2 {np.nanmedian(r3 / r2):.2f}, noise {np.nanmedian(noise) / h:.3f} h, "
              f"rho2 k {np.median(rho[2] * k[idx]):.2f}, rho3 k {np.median(rho[3] * k[idx]):.2f}, "
              f"r2/(rho2^4 k^3) {np.nanmedian(law):.4f}, "
              f"dihedral {np.median(np.degrees(mesh.face_adjacency_angles)):.1f} deg")


if __name__ == "__main__":
    main()
