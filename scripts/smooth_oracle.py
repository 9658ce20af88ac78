#!/usr/bin/env python3
"""How close focal.smooth can come to the best peer: an oracle sweep of its settings and the
variance and bias floor of the local quadric fit.

sweep: per case of scripts/smooth_eval.py (surface, noise) and seed, focal.smooth over rings x
  iterations x robust, the lowest RMS distance to the truth any setting reaches (chosen with the
  truth, per seed, as the peers' best iteration count is), against focal's defaults and the best
  trimesh peer at its best iteration count. Prints a Markdown table; --settings CSV writes every
  setting's RMS (for choosing a rule on some seeds and checking it on others). robust off is
  tried up to 6 rings (wider fits cost the most and are robust on by default).
model: the linear model of the passes on the clean mesh. A pass moves vertex i along its normal
  to the height c0 = w_i . z of the least-squares quadric over its rings, w_i the first row of
  (X^T X)^-1 X^T of its design X (tangent coordinates in the true frame). The noise's normal
  component e then becomes S e, S the matrix of the rows w_i: one pass leaves a standard deviation
  sigma * sqrt(h_i), h_i = |w_i|^2 the centre's leverage; the clean surface itself moves by the
  bias b_i = w_i . z_true (the quadric's truncation error over the ring's radius), and k passes
  leave S^k e + sum_j<k S^j b. Prints per rings and degree the leverage, the one-pass bias and
  the best pass count's RMS for each noise level.
rule: focal's defaults against wider rings where the defaults take the noisy meshes' rings.

Usage: PYTHONPATH=build/release/python:scripts python3 scripts/smooth_oracle.py sweep --seeds 1 2 3
       PYTHONPATH=build/release/python:scripts python3 scripts/smooth_oracle.py model
       PYTHONPATH=build/release/python:scripts python3 scripts/smooth_oracle.py rule --seeds 4 5 6
(numpy, scipy and trimesh: bench/peers/requirements.txt).
"""
import argparse
import math
import sys

import numpy as np
import scipy.sparse as sp

import focal
import smooth_eval as se

RINGS = [2, 3, 4, 5, 6, 8]
ITERATIONS = [1, 2, 3, 5, 8, 12, 16, 20]
# 10 rings only for few passes: more diverge (the sphere grows by an edge in 20 passes).
WIDE = {10: [1, 2, 3]}


def settings(rings_swept):
    for rings in rings_swept:
        for it in ITERATIONS:
            yield rings, it
    for rings, its in WIDE.items():
        if rings not in rings_swept:
            for it in its:
                yield rings, it


def best_peer(V, F, sd, crease, V0, h):
    best = None
    for p in ("Laplacian", "Taubin", "HC"):
        for k in se.PEER_ITERATIONS:
            P, N = se.peer(p, V, F, k)
            m = se.metrics(P, N, sd, crease, V0, h)
            if best is None or m[0] < best[0]:
                best = (m[0], f"{p} ({k})")
    return best


def chosen_cases(args):
    """The cases of smooth_eval.py on args.surfaces (all if none), each with its noisy inputs:
    (surface, noise label, clean V, F, signed distance, crease distance, mean edge, a generator
    of (seed, noisy V) over args.seeds)."""
    for name, V0, F, sd, crease in se.cases():
        if args.surfaces and name not in args.surfaces:
            continue
        h = se.edge_length(V0, F)
        for label, how, level in se.NOISES:
            inputs = ((seed, se.noisy(V0, F, how, level, h, np.random.default_rng(seed)))
                      for seed in args.seeds)
            yield name, label, V0, F, sd, crease, h, inputs


def sweep(args):
    out = open(args.settings, "w") if args.settings else None
    if out:
        out.write("surface,noise,seed,keep_creases,rings,iterations,robust,rms,mean_signed\n")
    print("| surface | noise | input | focal default (passes) | focal oracle (rings, passes, "
          "robust) | signed | best peer | 0.6 x peer | oracle / peer |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, label, V0, F, sd, crease, h, inputs in chosen_cases(args):
        creases = crease is not None
        rows = []
        for seed, V in inputs:
            inp = math.sqrt(np.mean((sd(V) / h) ** 2))
            d = focal.smooth(V, F, keep_creases=creases, threads=args.threads)
            default = se.metrics(d.V, d.N, sd, crease, V0, h)[0]
            best = None
            for rings, it in settings(args.rings):
                for robust in (True, False) if rings <= 6 else (True,):
                    r = focal.smooth(V, F, iterations=it, rings=rings, robust=robust,
                                     keep_creases=creases, threads=args.threads)
                    m = se.metrics(r.V, r.N, sd, crease, V0, h)
                    if out:
                        out.write(f"{name},{label},{seed},{int(creases)},{rings},{it},"
                                  f"{int(robust)},{m[0]:.5f},{m[2]:+.5f}\n")
                    if best is None or m[0] < best[0]:
                        best = (m[0], m[2], f"{rings}, {it}, {'on' if robust else 'off'}")
            peer = best_peer(V, F, sd, crease, V0, h)
            rows.append((inp, default, d.iterations, best, peer))
        inp = np.mean([r[0] for r in rows])
        default = np.mean([r[1] for r in rows])
        oracle = np.mean([r[3][0] for r in rows])
        signed = np.mean([r[3][1] for r in rows])
        peer = np.mean([r[4][0] for r in rows])
        passes = "/".join(str(r[2]) for r in rows)
        which = " / ".join(r[3][2] for r in rows)
        peers = " / ".join(r[4][1] for r in rows)
        print(f"| {name} | {label} | {inp:.3f} | {default:.3f} ({passes}) | {oracle:.3f} "
              f"({which}) | {signed:+.3f} | {peer:.3f} {peers} | {0.6 * peer:.3f} | "
              f"{oracle / peer:.2f} |")
        sys.stdout.flush()
        if out:
            out.flush()


def rule(args):
    """focal's defaults against the same with `--wider` more rings where the defaults take at
    least `--from-rings` (a rule from the measured noise: the default rings follow it)."""
    print("| surface | noise | default (rings; passes) | RMS | signed | normal | wider (rings; "
          "passes) | RMS | signed | normal |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for name, label, V0, F, sd, crease, h, inputs in chosen_cases(args):
        creases = crease is not None
        cols = {"default": [], "wider": []}
        for _, V in inputs:
            d = focal.smooth(V, F, keep_creases=creases, threads=args.threads)
            w = d
            if d.rings >= args.from_rings:
                w = focal.smooth(V, F, rings=d.rings + args.wider, keep_creases=creases,
                                 threads=args.threads)
            for key, r in (("default", d), ("wider", w)):
                cols[key].append(se.metrics(r.V, r.N, sd, crease, V0, h) +
                                 (f"{r.rings}; {r.iterations}",))
        cells = []
        for key in ("default", "wider"):
            a = cols[key]
            cells.append(f"{'/'.join(c[4] for c in a)} | {np.mean([c[0] for c in a]):.4f} | "
                         f"{np.mean([c[2] for c in a]):+.4f} | "
                         f"{np.mean([c[3] for c in a]):.2f}")
        print(f"| {name} | {label} | {' | '.join(cells)} |")
        sys.stdout.flush()


# --- the linear model ------------------------------------------------------------------------

def ring_matrix(F, n, rings):
    """Boolean CSR: row i holds the vertices within `rings` edges of i (i itself included)."""
    e = np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]])
    A = sp.coo_matrix((np.ones(len(e)), (e[:, 0], e[:, 1])), shape=(n, n))
    A = ((A + A.T + sp.identity(n)) > 0).astype(np.float64).tocsr()
    R = A.copy()
    for _ in range(rings - 1):
        R = ((R @ A) > 0).astype(np.float64).tocsr()
    R.sort_indices()
    return R


def monomials(x, y, degree):
    return np.stack([x ** (d - k) * y ** k for d in range(degree + 1) for k in range(d + 1)],
                    axis=1)


def pass_operator(V, Nt, R, degree):
    """S (CSR: row i = the weights w_i of the centre height), leverage h_i = |w_i|^2 and the
    one-pass bias b_i = w_i . z_true, all on the clean mesh in its true frames."""
    n = len(V)
    data, lever, bias = [], np.zeros(n), np.zeros(n)
    for i in range(n):
        idx = R.indices[R.indptr[i]:R.indptr[i + 1]]
        nz = Nt[i]
        t = np.cross(nz, [1.0, 0.0, 0.0] if abs(nz[0]) < 0.9 else [0.0, 1.0, 0.0])
        t /= np.linalg.norm(t)
        u = np.cross(nz, t)
        d = V[idx] - V[i]
        s = np.sqrt((d ** 2).sum(axis=1).max())
        X = monomials(d @ t / s, d @ u / s, degree)
        w = np.linalg.pinv(X)[0]  # the centre height's row of (X^T X)^-1 X^T
        data.append(w)
        lever[i] = w @ w
        bias[i] = w @ (d @ nz)
    S = sp.csr_matrix((np.concatenate(data), R.indices, R.indptr), shape=(n, n))
    return S, lever, bias


def model(args):
    print("| surface | degree | rings | points | leverage h (mean) | sqrt(h) | one-pass bias RMS |"
          " per noise: best passes and RMS (noise part, bias part) |")
    print("|---|---|---|---|---|---|---|---|")
    rng = np.random.default_rng(1)
    for name, V0, F, sd, crease in se.cases():
        if crease is not None or (args.surfaces and name not in args.surfaces):
            continue
        h = se.edge_length(V0, F)
        Nt = se.true_normals(sd, V0)
        samples = rng.normal(size=(len(V0), 8))
        for degree in args.degrees:
            for rings in args.rings:
                R = ring_matrix(F, len(V0), rings)
                if R.getnnz(axis=1).min() < 2 * se_coefficients(degree):
                    continue
                S, lever, bias = pass_operator(V0, Nt, R, degree)
                cells = []
                for label, sigma in (("0.1", 0.1), ("0.3", 0.3), ("0.5", 0.5),
                                     ("u1.0", 1.0 / math.sqrt(3.0))):
                    e, b, best = samples * sigma * h, np.zeros(len(V0)), None
                    for k in range(1, args.max_passes + 1):
                        b = S @ b + bias
                        e = S @ e
                        noise = math.sqrt(np.mean(e ** 2)) / h
                        off = math.sqrt(np.mean(b ** 2)) / h
                        total = math.hypot(noise, off)
                        if best is None or total < best[0]:
                            best = (total, k, noise, off)
                    cells.append(f"{label}: {best[1]} -> {best[0]:.3f} ({best[2]:.3f}, "
                                 f"{best[3]:.3f})")
                print(f"| {name} | {degree} | {rings} | {R.getnnz(axis=1).mean():.0f} | "
                      f"{lever.mean():.4f} | {math.sqrt(lever.mean()):.3f} | "
                      f"{math.sqrt(np.mean(bias ** 2)) / h:.4f} | {'; '.join(cells)} |")
                sys.stdout.flush()


def se_coefficients(degree):
    return (degree + 1) * (degree + 2) // 2


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = ap.add_subparsers(dest="what", required=True)
    s = sub.add_parser("sweep")
    s.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3])
    s.add_argument("--surfaces", nargs="*", default=None)
    s.add_argument("--settings", help="CSV of every setting's RMS")
    s.add_argument("--threads", type=int, default=1)
    s.add_argument("--rings", type=int, nargs="+", default=RINGS,
                   help="rings swept (with 10 rings at 1-3 passes)")
    r = sub.add_parser("rule")
    r.add_argument("--seeds", type=int, nargs="+", default=[4, 5, 6])
    r.add_argument("--surfaces", nargs="*", default=None)
    r.add_argument("--wider", type=int, default=1)
    r.add_argument("--from-rings", type=int, default=4)
    r.add_argument("--threads", type=int, default=1)
    m = sub.add_parser("model")
    m.add_argument("--surfaces", nargs="*", default=None)
    m.add_argument("--degrees", type=int, nargs="+", default=[2, 4])
    m.add_argument("--rings", type=int, nargs="+", default=[2, 3, 4, 5, 6, 8, 10, 12])
    m.add_argument("--max-passes", type=int, default=60)
    args = ap.parse_args()
    {"sweep": sweep, "rule": rule, "model": model}[args.what](args)


if __name__ == "__main__":
    main()
