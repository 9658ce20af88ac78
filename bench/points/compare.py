#!/usr/bin/env python3
"""Accuracy of focal's cloud curvature against peers on analytic point clouds (docs/POINTS.md).

For every analytic surface and case (exact normals, no normals, position noise, normal noise)
it writes a cloud with `focal generate --cloud` (Poisson-disk samples with exact truth) and
measures the relative RMS error of H, sqrt(mean (H - H_true)^2) / max |k_true|, of
  - focal: `focal curvature CLOUD.xyz` (the cloud default: adaptive, 16 or 64 neighbours),
  - CGAL 5.5 Monge_via_jet_fitting over the K nearest (bench/points/cgal_peer.cpp; normals
    jet_estimate_normals + mst_orient_normals when the cloud has none),
  - PCL 1.13 NormalEstimation + PrincipalCurvaturesEstimation over the K nearest
    (bench/points/pcl_peer.cpp): unsigned pc1, pc2, compared as they are (H = (pc1 + pc2) / 2);
  - focal's mesh path: `focal curvature` (recommended estimator) on the irregular triangulation
    of the same points (the same vertices, noise and seeds).
Prints a Markdown table and the fraction of cases where focal's cloud default has the lowest
error. Points without an estimate (NaN) are counted apart, not in the RMS.

Usage: compare.py FOCAL CGAL_PEER PCL_PEER [POINTS=5000] [K=16] [SEED=1]
"""

import os
import subprocess
import sys
import tempfile

import numpy as np

SURFACES = ["sphere", "ellipsoid", "torus", "cylinder", "saddle", "monkey-saddle", "helix-tube",
            "pear"]
CASES = {
    "exact normals": [],
    "no normals": ["--no-normals"],
    "position noise 0.1, no normals": ["--position-noise", "0.1", "--no-normals"],
    "normal noise 0.05": ["--normal-noise", "0.05"],
}


def read_column(path, name):
    with open(path) as f:
        header = f.readline().strip().split(",")
    col = header.index(name)
    return np.genfromtxt(path, delimiter=",", skip_header=1, usecols=col)


def h_error(H, truth_k1, truth_k2):
    H_true = 0.5 * (truth_k1 + truth_k2)
    scale = np.nanmax(np.abs(np.concatenate([truth_k1, truth_k2])))
    ok = np.isfinite(H) & np.isfinite(H_true)
    return np.sqrt(np.mean((H[ok] - H_true[ok]) ** 2)) / scale, int(np.sum(~np.isfinite(H)))


def run(*args):
    subprocess.run([str(a) for a in args], check=True, stdout=subprocess.DEVNULL)


def main():
    focal, cgal, pcl = sys.argv[1], sys.argv[2], sys.argv[3]
    points = int(sys.argv[4]) if len(sys.argv) > 4 else 5000
    k = int(sys.argv[5]) if len(sys.argv) > 5 else 16
    seed = sys.argv[6] if len(sys.argv) > 6 else "1"
    wins, peer_wins, cases = 0, 0, 0
    print(f"| surface | case | focal cloud (default) | CGAL jet (k={k}) | PCL (k={k}) | focal mesh |")
    print("|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for surface in SURFACES:
            for case, flags in CASES.items():
                common = [surface, "--vertices", points, "--seed", seed, *flags]
                cloud, truth = os.path.join(tmp, "c.xyz"), os.path.join(tmp, "t.csv")
                mesh = os.path.join(tmp, "m.ply")
                run(focal, "generate", *common, "--cloud", "-o", cloud, "--truth", truth, "--force")
                run(focal, "generate", *common, "--triangulation", "irregular", "-o", mesh, "--force")
                k1, k2 = read_column(truth, "k1"), read_column(truth, "k2")
                out = os.path.join(tmp, "out.csv")
                errors = []
                run(focal, "curvature", cloud, "-o", out, "--force")
                errors.append(h_error(read_column(out, "H"), k1, k2))
                run(cgal, cloud, k, out)
                errors.append(h_error(read_column(out, "H"), k1, k2))
                run(pcl, cloud, k, out)
                errors.append(h_error(read_column(out, "H"), k1, k2))
                run(focal, "curvature", mesh, "-o", out, "--force")
                errors.append(h_error(read_column(out, "H"), k1, k2))
                best = min(e for e, _ in errors)
                cases += 1
                wins += errors[0][0] == best
                peer_wins += errors[0][0] <= min(e for e, _ in errors[1:3])
                cells = [f"{e:.4f}" + (f" ({n} NaN)" if n else "") for e, n in errors]
                cells = [f"**{c}**" if e == best else c for c, (e, _) in zip(cells, errors)]
                print(f"| {surface} | {case} | " + " | ".join(cells) + " |", flush=True)
    print(f"\nfocal's cloud default lowest of all four in {wins} of {cases} cases, "
          f"at most the peers' (CGAL, PCL) in {peer_wins} of {cases}")


if __name__ == "__main__":
    main()
