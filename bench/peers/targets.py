#!/usr/bin/env python3
"""The speed targets of issue 36 as ratios from one run, focal and trueform interleaved.

  targets.py mesh MESH --focal BIN [--runs 5] [--threads 2]
      focal's default and --paper (whole `focal -v curvature MESH -o OUT.ply` processes, and the
      default's compute: its check + normals + curvature stages), trueform's whole process
      (`targets.py trueform-run`) and trueform's curvature call alone (in this process, the mesh
      in memory); one of each per round, medians over the rounds; then the ratios and targets:
        trueform whole / focal default whole  >= 1.5
        focal default whole / focal --paper whole  <= 2
        focal default compute / trueform curvature call  <= 1
  targets.py trueform-run MESH OUT
      one trueform process, end to end: NumPy reads the binary PLY (peers.read_ply),
      trueform's principal curvatures and directions over the k = 2 ring, then the positions,
      k1, k2, d1, d2 (float) and the faces written as binary PLY.

Needs numpy and trueform (bench/peers/.venv, bench/peers/setup.sh).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from peers import read_ply, trueform_curvatures  # noqa: E402

STAGES = ("read", "check", "normals", "curvature", "write")


def focal_stages(focal, mesh, out, *flags):
    """Whole-process wall ms of `focal -v curvature MESH -o OUT [flags]` and its -v stage ms (a
    stage it does not report counts as 0)."""
    start = time.perf_counter()
    log = subprocess.run([focal, "-v", "curvature", mesh, "-o", out, *flags],
                         capture_output=True, text=True, check=True).stderr
    whole = 1000 * (time.perf_counter() - start)
    found = dict(re.findall(r"^\s+(\w+):\s+([0-9.]+) ms$", log, re.M))
    return whole, {s: float(found.get(s, 0.0)) for s in STAGES}


def write_fields_ply(path, V, F, fields):
    """Positions (double), the named float fields and the triangles as binary PLY."""
    names = list(fields)
    header = ["ply", "format binary_little_endian 1.0", f"element vertex {len(V)}"]
    header += [f"property double {c}" for c in "xyz"]
    header += [f"property float {n}" for n in names]
    header += [f"element face {len(F)}", "property list uchar int vertex_indices", "end_header"]
    vertex = np.empty(len(V), dtype=[("p", "<f8", 3)] + [(n, "<f4") for n in names])
    vertex["p"] = V
    for n in names:
        vertex[n] = fields[n]
    face = np.empty(len(F), dtype=[("n", "u1"), ("i", "<i4", 3)])
    face["n"] = 3
    face["i"] = F
    with open(path, "wb") as f:
        f.write(("\n".join(header) + "\n").encode("ascii"))
        vertex.tofile(f)
        face.tofile(f)


def cmd_trueform_run(args):
    import trueform as tf
    props, F = read_ply(args.mesh)
    V = np.column_stack([props["x"], props["y"], props["z"]])
    mesh = tf.Mesh(np.ascontiguousarray(F, dtype=np.int32), np.ascontiguousarray(V))
    k1, k2, d1, d2 = (np.asarray(x) for x in tf.principal_curvatures(mesh, k=2, directions=True))
    fields = {"k1": k1, "k2": k2}
    for name, d in (("d1", d1), ("d2", d2)):
        for c, axis in enumerate("xyz"):
            fields[name + axis] = d[:, c]
    write_fields_ply(args.out, V, F, fields)


def cmd_mesh(args):
    threads = ["--threads", str(args.threads)]
    props, F = read_ply(args.mesh)
    V = np.column_stack([props["x"], props["y"], props["z"]])
    out = f"/tmp/focal-targets-{os.getpid()}"
    rounds = {"default": [], "paper": [], "compute": [], "tf_whole": [], "tf_call": []}
    for _ in range(args.runs):
        whole, stages = focal_stages(args.focal, args.mesh, out + ".ply", *threads)
        rounds["default"].append(whole)
        rounds["compute"].append(stages["check"] + stages["normals"] + stages["curvature"])
        rounds["paper"].append(focal_stages(args.focal, args.mesh, out + ".ply", "--paper",
                                            *threads)[0])
        start = time.perf_counter()
        subprocess.run([sys.executable, os.path.abspath(__file__), "trueform-run", args.mesh,
                        out + "-tf.ply"], check=True)
        rounds["tf_whole"].append(1000 * (time.perf_counter() - start))
        start = time.perf_counter()
        trueform_curvatures(V, F, None)
        rounds["tf_call"].append(1000 * (time.perf_counter() - start))
    for suffix in (".ply", "-tf.ply"):
        if os.path.exists(out + suffix):
            os.remove(out + suffix)
    m = {k: statistics.median(v) for k, v in rounds.items()}
    print(f"Targets of issue 36 on {os.path.basename(args.mesh)} ({len(V)} vertices), "
          f"focal --threads {args.threads}; medians of {args.runs} interleaved rounds (ms, "
          f"ranges in brackets).\n")
    print("| measure | median ms | range |\n|---|---:|---|")
    labels = {"default": "focal default, whole process", "paper": "focal --paper, whole process",
              "compute": "focal default compute (check + normals + curvature stages)",
              "tf_whole": "trueform, whole process (targets.py trueform-run)",
              "tf_call": "trueform principal_curvatures(k=2) call"}
    for key, label in labels.items():
        print(f"| {label} | {m[key]:.0f} | {min(rounds[key]):.0f}-{max(rounds[key]):.0f} |")
    print("\n| ratio | value | target | holds |\n|---|---:|---|---|")
    for name, value, target, holds in (
            ("trueform whole / focal default whole", m["tf_whole"] / m["default"], ">= 1.5",
             m["tf_whole"] / m["default"] >= 1.5),
            ("focal default whole / focal --paper whole", m["default"] / m["paper"], "<= 2",
             m["default"] / m["paper"] <= 2.0),
            ("focal default compute / trueform call", m["compute"] / m["tf_call"], "<= 1",
             m["compute"] / m["tf_call"] <= 1.0)):
        print(f"| {name} | {value:.2f} | {target} | {'yes' if holds else 'no'} |")


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    sub = p.add_subparsers(dest="command", required=True)
    m = sub.add_parser("mesh")
    m.add_argument("mesh")
    m.add_argument("--focal", default="build/release/cli/focal")
    m.add_argument("--runs", type=int, default=5)
    m.add_argument("--threads", type=int, default=2)
    t = sub.add_parser("trueform-run")
    t.add_argument("mesh")
    t.add_argument("out")
    args = p.parse_args()
    {"mesh": cmd_mesh, "trueform-run": cmd_trueform_run}[args.command](args)


if __name__ == "__main__":
    main()
