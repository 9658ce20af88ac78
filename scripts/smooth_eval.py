#!/usr/bin/env python3
"""focal.smooth against trimesh's Laplacian, Taubin and HC smoothing on noisy analytic meshes.

Prints a Markdown table (docs/SMOOTH.md): per surface and noise, the distance of the smoothed
vertices to the true surface (RMS and max, in mean edge lengths), the mean signed distance
(shrinkage: negative is inward) and the RMS angle between each method's vertex normals and the
true normals (degrees; vertices within 2 edges of a crease left out). focal runs with its
defaults (and with keep_creases on the creased solids); each peer at the iteration count, of
1 to 300, that gives it the lowest RMS distance on that case (chosen with the truth, which a
user does not have: the peers' best case). Peers' normals: trimesh's area-weighted vertex
normals of the smoothed mesh.

Usage: PYTHONPATH=build/release/python python3 scripts/smooth_eval.py [--seeds N] > table.md
(needs numpy, scipy and trimesh: bench/peers/requirements.txt).
"""
import argparse
import math
import sys

import numpy as np

import focal

try:
    import trimesh
    import trimesh.smoothing as tsm
except ImportError:  # pragma: no cover
    sys.exit("smooth_eval.py needs trimesh and scipy (bench/peers/requirements.txt)")

PEER_ITERATIONS = [1, 2, 3, 5, 8, 12, 20, 30, 50, 80, 120, 200, 300]


# --- meshes with exact signed distances ------------------------------------------------------

def outward(V, F):
    """F with every face turned outward (the solids here are star-shaped about the origin)."""
    n = np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]])
    c = V[F].mean(axis=1)
    flip = np.einsum("ij,ij->i", n, c) < 0
    F = F.copy()
    F[flip] = F[flip][:, [0, 2, 1]]
    return F


def cube_mesh(n):
    index, P, faces = {}, [], []

    def vertex(c):
        c = tuple(c)
        if c not in index:
            index[c] = len(P)
            P.append([2.0 * x / n - 1.0 for x in c])
        return index[c]

    for axis in range(3):
        u, w = (axis + 1) % 3, (axis + 2) % 3
        for side in (0, n):
            for a in range(n):
                for b in range(n):
                    ids = []
                    for da, db in ((0, 0), (1, 0), (0, 1), (1, 1)):
                        c = [0, 0, 0]
                        c[axis], c[u], c[w] = side, a + da, b + db
                        ids.append(vertex(c))
                    i00, i10, i01, i11 = ids
                    faces += [[i00, i10, i11], [i00, i11, i01]]
    V = np.array(P)
    return V, outward(V, np.array(faces, dtype=np.int32))


def capped_cylinder_mesh(m):
    """Radius 1, z in [-1, 1]; caps of m rings of 6j vertices, the side a grid of 6m columns."""
    N = 6 * m
    rows = max(2, round(2.0 / (2 * math.pi / N)))
    P, faces = [], []
    side = np.zeros((rows + 1, N), dtype=np.int64)
    for r in range(rows + 1):
        z = -1.0 + 2.0 * r / rows
        for k in range(N):
            t = 2 * math.pi * k / N
            side[r, k] = len(P)
            P.append([math.cos(t), math.sin(t), z])
    for r in range(rows):
        for k in range(N):
            a, b = side[r, k], side[r, (k + 1) % N]
            c, d = side[r + 1, k], side[r + 1, (k + 1) % N]
            faces += [[a, b, d], [a, d, c]]
    for z, rim in ((-1.0, side[0]), (1.0, side[rows])):
        rings = [[len(P)]]
        P.append([0.0, 0.0, z])
        for j in range(1, m):
            ring = []
            for k in range(6 * j):
                t = 2 * math.pi * k / (6 * j)
                ring.append(len(P))
                P.append([j / m * math.cos(t), j / m * math.sin(t), z])
            rings.append(ring)
        rings.append(list(rim))
        for inner, outer in zip(rings[:-1], rings[1:]):
            if len(inner) == 1:
                faces += [[inner[0], outer[k], outer[(k + 1) % len(outer)]] for k in range(len(outer))]
                continue
            i = j = 0
            ni, no = len(inner), len(outer)
            while i < ni or j < no:
                ti = (i + 1) / ni
                to = (j + 1) / no
                if j < no and (i >= ni or to <= ti):
                    faces.append([inner[i % ni], outer[j % no], outer[(j + 1) % no]])
                    j += 1
                else:
                    faces.append([inner[i % ni], outer[j % no], inner[(i + 1) % ni]])
                    i += 1
    V = np.array(P)
    return V, outward(V, np.array(faces, dtype=np.int32))


def sd_sphere(p):
    return np.linalg.norm(p, axis=1) - 1.0


def sd_torus(p):
    return np.hypot(np.hypot(p[:, 0], p[:, 1]) - 1.0, p[:, 2]) - 0.4


AXES = np.array([1.0, 0.8, 0.6])


def sd_ellipsoid(p):
    """Exact signed distance: the closest point x = a^2 p / (a^2 + t), t from Newton with
    bisection on sum (a p / (a^2 + t))^2 = 1."""
    a2 = AXES ** 2
    q = np.abs(p)
    hi = np.full(len(p), 10.0)
    lo = np.full(len(p), -a2.min() * (1 - 1e-12))
    t = np.zeros(len(p))
    for _ in range(200):
        g = (((AXES * q) / (a2 + t[:, None])) ** 2).sum(axis=1) - 1.0
        hi = np.where(g < 0, t, hi)
        lo = np.where(g > 0, t, lo)
        t = 0.5 * (lo + hi)
    x = a2 * q / (a2 + t[:, None])
    inside = ((q / AXES) ** 2).sum(axis=1) < 1.0
    d = np.linalg.norm(q - x, axis=1)
    return np.where(inside, -d, d)


def sd_capped_cylinder(p):
    dx = np.hypot(p[:, 0], p[:, 1]) - 1.0
    dz = np.abs(p[:, 2]) - 1.0
    return np.minimum(np.maximum(dx, dz), 0.0) + np.hypot(np.maximum(dx, 0), np.maximum(dz, 0))


def sd_cube(p):
    q = np.abs(p) - 1.0
    return np.minimum(q.max(axis=1), 0.0) + np.linalg.norm(np.maximum(q, 0.0), axis=1)


def crease_distance_cube(p):
    s = np.sort(np.abs(np.abs(p) - 1.0), axis=1)
    return np.hypot(s[:, 0], s[:, 1])


def crease_distance_capped(p):
    return np.hypot(np.hypot(p[:, 0], p[:, 1]) - 1.0, np.abs(p[:, 2]) - 1.0)


def true_normals(sd, p, eps=1e-6):
    g = np.stack([(sd(p + eps * e) - sd(p - eps * e)) / (2 * eps) for e in np.eye(3)], axis=1)
    return g / np.linalg.norm(g, axis=1, keepdims=True)


def edge_length(V, F):
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    return float(np.linalg.norm(V[e[:, 0]] - V[e[:, 1]], axis=1).mean())


def cases():
    for kind in ("sphere", "torus", "ellipsoid"):
        s = focal.generate_surface(kind, 4000, triangulation="irregular", seed=1)
        sd = {"sphere": sd_sphere, "torus": sd_torus, "ellipsoid": sd_ellipsoid}[kind]
        yield kind, s.V, s.F, sd, None
    V, F = capped_cylinder_mesh(14)
    yield "capped cylinder", V, F, sd_capped_cylinder, crease_distance_capped
    V, F = cube_mesh(24)
    yield "cube", V, F, sd_cube, crease_distance_cube


NOISES = [("Gaussian 0.1", "normal", 0.1), ("Gaussian 0.3", "normal", 0.3),
          ("Gaussian 0.5", "normal", 0.5), ("uniform 1.0", "uniform", 1.0),
          ("spikes + Gaussian 0.1", "spikes", 0.1)]


def noisy(V, F, how, level, h, rng):
    if how == "normal":
        return V + rng.normal(0.0, level * h, V.shape)
    if how == "uniform":
        return V + rng.uniform(-level * h, level * h, V.shape)
    # 0.5% of the vertices 2 edges along their normal, in or out, on top of Gaussian noise.
    N = trimesh.Trimesh(V, F, process=False).vertex_normals
    out = V + rng.normal(0.0, level * h, V.shape)
    k = max(1, len(V) // 200)
    idx = rng.choice(len(V), k, replace=False)
    out[idx] += 2.0 * h * rng.choice([-1.0, 1.0], k)[:, None] * N[idx]
    return out


def metrics(P, N, sd, crease, V0, h):
    d = sd(P) / h
    n_true = true_normals(sd, P)
    ok = np.all(np.isfinite(N), axis=1)
    if crease is not None:
        ok &= crease(V0) > 2.0 * h
    cos = np.clip(np.abs(np.einsum("ij,ij->i", N[ok], n_true[ok])), -1, 1)
    angle = np.degrees(np.arccos(cos))
    return math.sqrt(np.mean(d ** 2)), float(np.abs(d).max()), float(d.mean()), \
        math.sqrt(np.mean(angle ** 2))


def peer(name, V, F, k):
    m = trimesh.Trimesh(vertices=V.copy(), faces=F.copy(), process=False)
    if name == "Laplacian":
        tsm.filter_laplacian(m, iterations=k)
    elif name == "Taubin":
        tsm.filter_taubin(m, iterations=k)
    else:
        tsm.filter_humphrey(m, iterations=k)
    return np.asarray(m.vertices), np.asarray(m.vertex_normals)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=1, help="noise seeds per case (averaged)")
    args = ap.parse_args()
    print("| surface | noise | input RMS | method | RMS | max | mean signed | normal RMS (deg) |")
    print("|---|---|---|---|---|---|---|---|")
    for name, V0, F, sd, crease in cases():
        h = edge_length(V0, F)
        for label, how, level in NOISES:
            rows = {}
            inputs = []
            for seed in range(1, args.seeds + 1):
                rng = np.random.default_rng(seed)
                V = noisy(V0, F, how, level, h, rng)
                inputs.append(math.sqrt(np.mean((sd(V) / h) ** 2)))
                runs = {"focal": focal.smooth(V, F)}
                if crease is not None:
                    runs["focal --keep-creases"] = focal.smooth(V, F, keep_creases=True)
                for method, r in runs.items():
                    rows.setdefault(method, []).append(metrics(r.V, r.N, sd, crease, V0, h) +
                                                       (r.iterations,))
                for p in ("Laplacian", "Taubin", "HC"):
                    best = None
                    for k in PEER_ITERATIONS:
                        P, N = peer(p, V, F, k)
                        m = metrics(P, N, sd, crease, V0, h) + (k,)
                        if best is None or m[0] < best[0]:
                            best = m
                    rows.setdefault(f"trimesh {p}", []).append(best)
            for method, values in rows.items():
                a = np.array(values)
                its = "/".join(str(int(x)) for x in a[:, 4])
                print(f"| {name} | {label} | {np.mean(inputs):.3f} | {method} ({its}) | "
                      f"{a[:, 0].mean():.3f} | {a[:, 1].mean():.2f} | {a[:, 2].mean():+.3f} | "
                      f"{a[:, 3].mean():.1f} |")
            sys.stdout.flush()


if __name__ == "__main__":
    main()
