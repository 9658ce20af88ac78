#!/usr/bin/env python3
"""The baselines (focal/curvature/baselines.h) beside focal's default, by category, from the CSV
of `focal eval`: medians over the 8 surfaces of the relative H error and of the median d1 angle,
and in how many cases each baseline beats the default. Markdown on stdout.

    scripts/baseline_medians.py docs/accuracy/eval.csv
"""
import csv
import statistics
import sys

DEFAULTS = ["focal default / file normals", "focal default / no normals"]
BASELINES = ["MDSB03", "CSM03", "LRTC20 / file normals", "LRTC20 / Max normals", "YLHP06",
             "GGRZ06"]


def main(path):
    by_case = {}
    for r in csv.DictReader(open(path)):
        by_case.setdefault((r["triangulation"], r["noise"]), {}).setdefault(
            r["surface"], {})[r["method"]] = r
    methods = DEFAULTS + BASELINES
    for metric, title in (("rel_H", "Median relative RMS error of H"),
                          ("median_angle_d1", "Median of the median d1 angle (degrees)")):
        print(f"{title} over the 8 surfaces:\n")
        print("| triangulation, noise | " + " | ".join(methods) + " |")
        print("|---" * (len(methods) + 1) + "|")
        for (tri, noise), surfaces in by_case.items():
            cells = [statistics.median(float(s[m][metric]) for s in surfaces.values())
                     for m in methods]
            best = min(cells)
            print(f"| {tri}, {noise} | " + " | ".join(
                (f"**{c:.3g}**" if c == best else f"{c:.3g}") for c in cells) + " |")
        print()
    cases = [s for surfaces in by_case.values() for s in surfaces.values()]
    print("Cases (of %d) where the baseline's relative H error is below focal default's, with the "
          "file's normals / without normals (a baseline that reads the file's normals is not "
          "compared with the default without them):\n" % len(cases))
    print("| baseline | below default / file normals | below default / no normals |")
    print("|---|---|---|")
    for m in BASELINES:
        below = [str(sum(float(c[m]["rel_H"]) < float(c[d]["rel_H"]) for c in cases))
                 for d in DEFAULTS]
        if "file normals" in m:
            below[1] = "-"
        print(f"| {m} | {below[0]} | {below[1]} |")
    print()


if __name__ == "__main__":
    main(sys.argv[1])
