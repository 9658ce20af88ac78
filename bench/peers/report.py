#!/usr/bin/env python3
"""Merges focal's and the peers' tables and draws the plots of docs/ACCURACY.md.

  report.py --eval eval.csv --peers peers.csv --out docs/accuracy
            [--scans focal_scans.csv --peer-scans peer_scans.csv
             --scan-fields DIR (focal's coloured PLYs and the peers' .npy H fields)]

  report.py ... --hard-eval hard.csv --hard-peers hard-peers.csv

Writes OUT/merged.csv, OUT/merged.md (relative H error per case and method, best in bold),
OUT/target.md (the issue 4 point 5 count and the losses), OUT/scans.md and the PNGs; with the
hard cases (issue 16) also OUT/hard-merged.csv, OUT/hard-peers.md (the hard cases with the
peers: per case and per category), and for both suites OUT/directions.md and
OUT/directions.csv (principal direction errors of focal default and the peers that give
directions).
Everything is recomputed from the CSVs: nothing about focal's numbers is written in here.
"""
import argparse
import csv
import math
import os
import re

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from peers import PEERS, read_ply, slug  # noqa: E402

# As `at_most` in cli/eval_tables.cpp: within 0.1% (the 4 digits the tables show) or both below
# 1e-12 (exact up to rounding).
TIE = 1e-3

DEFAULT_FILE = "focal default / file normals"
DEFAULT_NONE = "focal default / no normals"


def read_rows(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def value(row, key="rel_H"):
    x = float(row[key])
    return math.inf if math.isnan(x) else x


def case_key(r):
    return (r["surface"], r["triangulation"], r["noise"])


def label(key):
    return ", ".join(key)


# focal's in-library baselines (focal/curvature/baselines.h) that read positions only; LRTC20
# comes in two rows, "/ file normals" and "/ Max normals".
BASELINES = ("MDSB03", "CSM03", "YLHP06", "GGRZ06")


def is_baseline(method):
    return method in BASELINES or method.startswith("LRTC20")


def positions_only(method):
    """Methods that never read the file's normals: Max-normal focal variants, the baselines,
    the focal default without normals and every peer (the pymeshlab filters return the same
    values with noisy and with exact normals: measured)."""
    return ("Max normals" in method or method in BASELINES or method == DEFAULT_NONE
            or method in PEERS)


def table(rows):
    """case -> method -> row, and the methods in first-seen order."""
    by_case, methods = {}, []
    for r in rows:
        by_case.setdefault(case_key(r), {})[r["method"]] = r
        if r["method"] not in methods:
            methods.append(r["method"])
    return by_case, methods


def number(x):
    return "nan" if math.isinf(x) or math.isnan(x) else f"{x:.4g}"


def merged_markdown(by_case, methods):
    out = ["| case | " + " | ".join(methods) + " |", "|---|" + "---|" * len(methods)]
    for key, row in by_case.items():
        best = min(value(row[m]) for m in methods)
        cells = [f"**{number(value(row[m]))}**" if value(row[m]) == best else number(value(row[m]))
                 for m in methods]
        out.append(f"| {label(key)} | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


def irregular_or_noisy(key):
    return key[1] == "irregular" or key[2] != "clean"


def is_focal(method):
    return method.startswith("focal")


def wins(by_case, name, cases_, rivals):
    """Cases where `name` has the lowest relative H error of name + rivals (ties count), and the
    losses as (case, best rival)."""
    won, lost = 0, []
    for k in cases_:
        best = min(rivals, key=lambda m: value(by_case[k][m]))
        mine, theirs = value(by_case[k][name]), value(by_case[k][best])
        # Both below 1e-12: exact up to double rounding (as in cross_check), a tie.
        if mine <= theirs or max(mine, theirs) < 1e-12:
            won += 1
        else:
            lost.append((k, best))
    return won, lost


def loss_table(by_case, rows, caption, rival_header):
    """A Markdown table of (case, focal default column, best rival) with the error factor; empty
    when there are no rows."""
    if not rows:
        return ""
    text = (f"{caption}\n\n| case | focal default | its rel. H | {rival_header} | its rel. H | "
            f"factor |\n|---|---|---|---|---|---|\n")
    for k, name, best in rows:
        mine, theirs = value(by_case[k][name]), value(by_case[k][best])
        text += (f"| {label(k)} | {name.split(' / ')[1]} | {number(mine)} | {best} | "
                 f"{number(theirs)} | {mine / theirs:.3g} |\n")
    return text + "\n"


def count_target(by_case, methods):
    """Issue 4 point 5: how often focal default has the lowest relative H error."""
    file_cases = [k for k in by_case if irregular_or_noisy(k)]
    # Positions-only methods see clean positions under normal noise: those rows repeat the clean
    # case, so the no-normals count leaves them out.
    none_cases = [k for k in by_case if irregular_or_noisy(k) and k[2] != "normal noise 5%"]
    file_rivals = [m for m in methods if m != DEFAULT_FILE]
    none_rivals = [m for m in methods if positions_only(m) and m != DEFAULT_NONE]
    x, file_all_losses = wins(by_case, DEFAULT_FILE, file_cases, file_rivals)
    z, none_all_losses = wins(by_case, DEFAULT_NONE, none_cases, none_rivals)
    # The same against the other libraries only (baselines and peers, no focal variant).
    xo, file_losses = wins(by_case, DEFAULT_FILE, file_cases, [m for m in file_rivals if not is_focal(m)])
    zo, none_losses = wins(by_case, DEFAULT_NONE, none_cases, [m for m in none_rivals if not is_focal(m)])
    # Without the peers (focal's other settings and its baselines only: focal eval's own view).
    xn, _ = wins(by_case, DEFAULT_FILE, file_cases, [m for m in file_rivals if m not in PEERS])
    zn, _ = wins(by_case, DEFAULT_NONE, none_cases, [m for m in none_rivals if m not in PEERS])
    y, w = len(file_cases), len(none_cases)
    text = (f"**focal default has the lowest relative H error in {x} of {y} irregular-or-noisy "
            f"cases with file normals; {z} of {w} without normals.** With file normals it is "
            f"compared with all {len(file_rivals)} other methods; without normals (the irregular "
            f"and the vertex-noise cases: under normal noise positions-only methods see the clean "
            f"case) with the {len(none_rivals)} positions-only ones: focal with Max normals, "
            f"the positions-only baselines and every peer. Ties count as wins (errors both below 1e-12 are "
            f"exact up to rounding and tie). Against the other libraries "
            f"only (focal's baselines and the peers, no other focal variant): {xo} of {y} with file "
            f"normals, {zo} of {w} without. Without the peers (focal's other settings and "
            f"baselines only): {xn} of {y} and {zn} of {w}.\n\n")
    text += loss_table(
        by_case, [(k, DEFAULT_FILE, b) for k, b in file_losses] +
        [(k, DEFAULT_NONE, b) for k, b in none_losses],
        "Losses to other libraries (counted by the script): the best of them and the factor by "
        "which focal default's error is larger.", "best other library")
    text += loss_table(
        by_case, [(k, DEFAULT_FILE, b) for k, b in file_all_losses if is_focal(b)] +
        [(k, DEFAULT_NONE, b) for k, b in none_all_losses if is_focal(b)],
        "Losses to another focal setting (the best of them; a setting a user can pick, but not "
        "the default):", "best focal setting")
    return text


def cross_check(by_case):
    """MDSB03 (C++, focal eval) and libigl's cotangent H / angle-defect K (Python, peers.py) are
    the same formulas: their errors agreeing shows that both sides measure the same vertices
    with the same metrics."""
    twin = "libigl cotangent H + angle-defect K"
    agree, total = 0, 0
    for row in by_case.values():
        if "MDSB03" not in row or twin not in row:
            continue
        total += 1
        a, b = [value(row["MDSB03"], q) for q in ("rel_H", "rel_K")], \
               [value(row[twin], q) for q in ("rel_H", "rel_K")]
        # inf: both undefined (NaN, zero truth, e.g. K on the cylinder).
        agree += all(x == y or abs(x - y) <= 1e-3 * abs(x) or max(x, y) < 1e-12
                     for x, y in zip(a, b))
    return (f"Cross-check of the two measuring sides: MDSB03 (focal eval, C++) and libigl's "
            f"cotangent H and angle-defect K (peers.py, Python) are the same formulas; their "
            f"relative H and K errors agree to 0.1% (or are both below 1e-12) in {agree} of "
            f"{total} cases.\n")


def colour(method):
    if method.startswith("focal default"):
        return "tab:red"
    if method.startswith("focal"):
        return "tab:blue"
    if is_baseline(method):
        return "tab:green"
    return "tab:orange"


def plot_surface(surface, by_case, methods, out):
    keys = [k for k in by_case if k[0] == surface]
    fig, axes = plt.subplots(1, len(keys), figsize=(3.0 * len(keys) + 3.5, 0.32 * len(methods) + 1.6),
                             sharey=True)
    y = np.arange(len(methods))[::-1]
    for ax, k in zip(axes, keys):
        x = np.array([float(by_case[k][m]["rel_H"]) for m in methods])
        x = np.where(x > 0, x, np.nan)  # exact zeros cannot sit on a log axis
        ax.scatter(x, y, c=[colour(m) for m in methods], s=28, zorder=3)
        ax.set_xscale("log")
        ax.grid(True, which="major", axis="both", alpha=0.3)
        ax.set_title(f"{k[1]}\n{k[2]}", fontsize=9)
        ax.tick_params(axis="x", labelsize=8)
    axes[0].set_yticks(y)
    axes[0].set_yticklabels(methods, fontsize=8)
    fig.suptitle(f"{surface}: relative RMS error of H at interior vertices (log scale; red: focal "
                 f"default, blue: other focal, green: baselines, orange: peers)", fontsize=10)
    fig.tight_layout()
    path = os.path.join(out, f"relH-{surface}.png")
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


HISTOGRAM_METHODS = [DEFAULT_NONE, "focal closed-form 1-ring / Max normals", "MDSB03", "CSM03",
                     "libigl principal_curvature (quadric)", "pymeshlab quadric fitting",
                     "VTK vtkCurvatures"]


def scan_fields(scan, folder):
    """H h per method of one scan: focal's from its coloured PLYs, the peers' from .npy."""
    fields = {}
    for name in HISTOGRAM_METHODS:
        ply = os.path.join(folder, f"{scan}.{slug(name)}.ply")
        npy = os.path.join(folder, f"{scan}.{slug(name)}.npy")
        if os.path.exists(ply):
            props, F = read_ply(ply)
            V = np.column_stack([props["x"], props["y"], props["z"]])
            fields[name] = (props["H"], V, F)
        elif os.path.exists(npy):
            fields[name] = (np.load(npy), None, None)
    geometry = next((f for f in fields.values() if f[1] is not None), None)
    if geometry is None:
        return {}
    from peers import mean_edge_length
    h = mean_edge_length(geometry[1], geometry[2])
    return {m: f[0][np.isfinite(f[0])] * h for m, f in fields.items()}


def plot_histograms(scan, folder, out):
    """Paper Fig. 7c-d: the distribution of the mean curvature estimates on a scan."""
    fields = scan_fields(scan, folder)
    if not fields:
        return None
    reference = fields.get(DEFAULT_NONE, next(iter(fields.values())))
    lo, hi = np.percentile(reference, [0.5, 99.5])
    span = hi - lo
    bins = np.linspace(lo - span, hi + span, 121)
    fig, axes = plt.subplots(1, 2, figsize=(13, 4.5), sharey=True)
    for ax, group in zip(axes, (HISTOGRAM_METHODS[:4], HISTOGRAM_METHODS[:1] + HISTOGRAM_METHODS[4:])):
        for m in group:
            if m in fields:
                ax.hist(np.clip(fields[m], bins[0], bins[-1]), bins=bins, histtype="step",
                        linewidth=1.4, label=m)
        ax.set_yscale("log")
        ax.set_xlabel("H x mean edge length (values outside the axis piled at its ends)")
        ax.legend(fontsize=8)
        ax.grid(alpha=0.3)
    axes[0].set_ylabel("vertices")
    axes[0].set_title(f"{scan}: focal and the paper's baselines", fontsize=10)
    axes[1].set_title(f"{scan}: focal default and peers", fontsize=10)
    fig.tight_layout()
    path = os.path.join(out, f"hist-{scan}.png")
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def scans_markdown(rows):
    out = ["| scan | method | undefined | min | 1st pct | 99th pct | max | variance | sign changes |",
           "|---|---|---|---|---|---|---|---|---|"]
    rows = sorted(rows, key=lambda r: r["scan"])  # stable: focal's methods, then the peers
    for scan in dict.fromkeys(r["scan"] for r in rows):
        mine = [r for r in rows if r["scan"] == scan]
        best_var = min(value(r, "variance_Hh") for r in mine)
        best_sign = min(value(r, "sign_change_fraction") for r in mine)
        for r in mine:
            v, s = value(r, "variance_Hh"), value(r, "sign_change_fraction")
            out.append(f"| {scan} | {r['method']} | {r['undefined']} | {number(float(r['min_Hh']))} "
                       f"| {number(float(r['p1_Hh']))} | {number(float(r['p99_Hh']))} | "
                       f"{number(float(r['max_Hh']))} | "
                       + (f"**{number(v)}**" if v == best_var else number(v)) + " | "
                       + (f"**{number(s)}**" if s == best_sign else number(s)) + " |")
    return "\n".join(out) + "\n"


def at_most(v, best):
    return v <= best * (1.0 + TIE) or (v < 1e-12 and best < 1e-12)


def lowest(row, methods, key="rel_H"):
    """The lowest value of `key` over `methods` present in the row (NaN rows do not compete) and
    its method; (inf, None) when none has a value."""
    present = [(value(row[m], key), m) for m in methods if m in row]
    return min(present, default=(math.inf, None))


def median(xs):
    """As median_of in cli/eval_tables.cpp: the element at n / 2 of the sorted values."""
    xs = sorted(xs)
    return xs[len(xs) // 2] if xs else math.nan


def category_of(by_case, k):
    return next(iter(by_case[k].values())).get("category", "standard")


def hard_report(by_case, methods):
    """Issue 16's targets on the hard cases with the peers: focal default's relative H error
    against the lowest of every other method (file normals; the other focal default row does not
    compete, as in `focal eval`) and of the other positions-only methods (no normals), first
    without the peers (focal eval's own count) and then with them."""
    peers = [m for m in methods if m in PEERS]
    focal_others = [m for m in methods if m not in PEERS and m not in (DEFAULT_FILE, DEFAULT_NONE)]
    file_all, none_all = focal_others + peers, [m for m in focal_others + peers if positions_only(m)]
    none_focal = [m for m in focal_others if positions_only(m)]
    order, per = [], {}
    for k in by_case:
        c = category_of(by_case, k)
        if c not in per:
            order.append(c)
        per.setdefault(c, []).append(k)
    head = ("| category | cases | lowest, file normals: without peers | with peers | lowest, no "
            "normals: without peers | with peers | median, file normals | median best other "
            "(with peers) | median, no normals | median best positions-only (with peers) |\n"
            "|---|---|---|---|---|---|---|---|---|---|\n")
    lines, totals, losses = [], [0] * 5, []
    for c in order:
        counts = [len(per[c]), 0, 0, 0, 0]
        mine_f, mine_n, best_f, best_n = [], [], [], []
        for k in per[c]:
            row = by_case[k]
            f, n = value(row[DEFAULT_FILE]), value(row[DEFAULT_NONE])
            bf_focal, _ = lowest(row, focal_others)
            bf, bf_name = lowest(row, file_all)
            bn_focal, _ = lowest(row, none_focal)
            bn, bn_name = lowest(row, none_all)
            counts[1] += at_most(f, bf_focal)
            counts[2] += at_most(f, bf)
            counts[3] += at_most(n, bn_focal)
            counts[4] += at_most(n, bn)
            if not at_most(f, bf) and bf_name in PEERS:
                losses.append((k, "file normals", f, bf_name, bf))
            if not at_most(n, bn) and bn_name in PEERS:
                losses.append((k, "no normals", n, bn_name, bn))
            mine_f.append(f), mine_n.append(n), best_f.append(bf), best_n.append(bn)
        totals = [t + x for t, x in zip(totals, counts)]
        lines.append(f"| {c} | " + " | ".join(str(x) for x in counts) + " | " +
                     " | ".join(number(median(x)) for x in (mine_f, best_f, mine_n, best_n)) + " |")
    n = totals[0]

    def pct(x):
        return f"{x} ({100.0 * x / n:.0f}%)" if n else str(x)
    lines.append(f"| all | {n} | " + " | ".join(pct(x) for x in totals[1:]) + " | | | | |")
    text = (f"**With the peers ({len(peers)}: " + ", ".join(peers) + f") the default has the lowest "
            f"relative H error in {totals[2]} of {n} hard cases with file normals (target 85%: "
            f"{math.ceil(0.85 * n)}) and {totals[4]} of {n} without normals (target 75%: "
            f"{math.ceil(0.75 * n)}); against focal's other settings and baselines only, "
            f"{totals[1]} and {totals[3]}.** Ties within 0.1% count as lowest, as in `focal eval`.\n\n"
            + head + "\n".join(lines) + "\n")
    if losses:
        text += ("\nCases lost to a peer (the best method of the case is a peer): focal default's "
                 "relative H error, the peer's and the factor.\n\n| case | focal default | its "
                 "rel. H | best peer | its rel. H | factor |\n|---|---|---|---|---|---|\n")
        for k, which, mine, name, theirs in losses:
            text += (f"| {category_of(by_case, k)}: {label(k)} | {which} | {number(mine)} | {name} | "
                     f"{number(theirs)} | {mine / theirs:.3g} |\n")
    return text


def hard_peers_markdown(by_case, methods):
    """Per hard case: focal default, the lowest of focal's other methods, and every peer."""
    peers = [m for m in methods if m in PEERS]
    cols = [DEFAULT_FILE, DEFAULT_NONE, "lowest other focal setting or baseline"] + peers
    out = ["| case | " + " | ".join(cols) + " |", "|---|" + "---|" * len(cols)]
    others = [m for m in methods if m not in PEERS and m not in (DEFAULT_FILE, DEFAULT_NONE)]
    for k, row in by_case.items():
        values = [value(row[DEFAULT_FILE]), value(row[DEFAULT_NONE]), lowest(row, others)[0]]
        values += [value(row[m]) if m in row else math.inf for m in peers]
        best = min(values)
        cells = [f"**{number(v)}**" if v == best else number(v) for v in values]
        out.append(f"| {category_of(by_case, k)}: {label(k)} | " + " | ".join(cells) + " |")
    return "\n".join(out) + "\n"


DIRECTION_KEY = "mean_angle_d1"


def direction_report(suites, out_csv):
    """Principal directions: focal default's mean angle between the estimated and the exact d1
    (mod pi, degrees) against every peer that gives directions, on the cases whose truth has
    scored non-umbilic vertices. Returns Markdown; writes every value to out_csv."""
    peers_with = []
    for by_case, _ in suites.values():
        for row in by_case.values():
            for m, r in row.items():
                if m in PEERS and not math.isnan(float(r[DIRECTION_KEY])) and m not in peers_with:
                    peers_with.append(m)
    cols = [DEFAULT_FILE, DEFAULT_NONE] + peers_with
    csv_rows, summary, losses = [], [], []
    for suite, (by_case, _) in suites.items():
        groups, order = {}, []
        for k, row in by_case.items():
            if any(m not in row for m in cols):
                continue
            vals = {m: float(row[m][DIRECTION_KEY]) for m in cols}
            if math.isnan(vals[DEFAULT_FILE]):
                continue  # no scored vertex off the umbilics (the spheres) or nothing defined
            csv_rows.append([suite, category_of(by_case, k), *k] + [f"{vals[m]:.4g}" for m in cols])
            g = category_of(by_case, k) if suite == "hard" else f"{k[1]}, {k[2]}"
            if g not in groups:
                order.append(g)
            groups.setdefault(g, []).append((k, vals))
        total = [0, 0, 0]
        for g in order:
            items = groups[g]
            ahead_f = ahead_n = 0
            for k, vals in items:
                best, name = min(((value_of(vals[m]), m) for m in peers_with))
                for which, mine in (("file normals", vals[DEFAULT_FILE]),
                                    ("no normals", vals[DEFAULT_NONE])):
                    ok = at_most_angle(value_of(mine), best)
                    if which == "file normals":
                        ahead_f += ok
                    else:
                        ahead_n += ok
                    if not ok:
                        losses.append((suite, category_of(by_case, k), k, which, mine, name, best))
            total = [total[0] + len(items), total[1] + ahead_f, total[2] + ahead_n]
            med = [median([value_of(v[m]) for _, v in items]) for m in cols]
            summary.append(f"| {suite} | {g} | {len(items)} | {ahead_f} | {ahead_n} | "
                           + " | ".join(number(x) for x in med) + " |")
        summary.append(f"| {suite} | **all** | {total[0]} | **{total[1]}** | **{total[2]}** |"
                       + " |" * len(cols))
    with open(out_csv, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["suite", "category", "surface", "triangulation", "noise"] + cols)
        w.writerows(csv_rows)
    text = ("| suite | group | cases | default ahead of every peer, file normals | no normals | "
            + " | ".join(f"median: {m}" for m in cols) + " |\n|---|---|---|---|---|"
            + "---|" * len(cols) + "\n" + "\n".join(summary) + "\n")
    if losses:
        text += ("\nCases where a peer's directions are better: focal default's mean angle, the "
                 "best peer's, the factor (angles both below 1e-5 degrees tie: exact up to "
                 "rounding).\n\n| suite | case | focal default | its angle | best "
                 "peer | its angle | factor |\n|---|---|---|---|---|---|---|\n")
        for suite, c, k, which, mine, name, best in losses:
            factor = mine / best if best > 0 else math.inf
            case = label(k) if suite == "standard" else f"{c}: {label(k)}"
            text += (f"| {suite} | {case} | {which} | {number(mine)} | {name} | "
                     f"{number(best)} | {factor:.3g} |\n")
    return text


# Angles below 1e-5 degrees are exact up to rounding: acos of a cosine within one double
# rounding of 1 is already about 1e-6 degrees.
EXACT_ANGLE = 1e-5


def at_most_angle(v, best):
    return v <= best * (1.0 + TIE) or (v < EXACT_ANGLE and best < EXACT_ANGLE)


def value_of(x):
    return math.inf if math.isnan(x) else x


def merge_csvs(focal_csv, peers_csv, out):
    """focal's rows, then the peers' (same columns), written to `out`; returns them."""
    rows = read_rows(focal_csv) + read_rows(peers_csv)
    with open(out, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0].keys()))
        w.writeheader()
        w.writerows(rows)
    return rows


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--eval", required=True)
    p.add_argument("--peers", required=True)
    p.add_argument("--out", required=True)
    p.add_argument("--scans")
    p.add_argument("--peer-scans")
    p.add_argument("--scan-fields")
    p.add_argument("--hard-eval")
    p.add_argument("--hard-peers")
    a = p.parse_args()
    rows = merge_csvs(a.eval, a.peers, os.path.join(a.out, "merged.csv"))
    by_case, methods = table(rows)
    with open(os.path.join(a.out, "merged.md"), "w") as f:
        f.write(merged_markdown(by_case, methods))
    with open(os.path.join(a.out, "target.md"), "w") as f:
        f.write(count_target(by_case, methods) + "\n" + cross_check(by_case))
    for surface in dict.fromkeys(k[0] for k in by_case):
        plot_surface(surface, by_case, methods, a.out)
    suites = {"standard": (by_case, methods)}
    if a.hard_eval and a.hard_peers:
        hard_rows = merge_csvs(a.hard_eval, a.hard_peers, os.path.join(a.out, "hard-merged.csv"))
        hard_by_case, hard_methods = table(hard_rows)
        with open(os.path.join(a.out, "hard-peers.md"), "w") as f:
            f.write(hard_report(hard_by_case, hard_methods) + "\n" + cross_check(hard_by_case)
                    + "\n" + hard_peers_markdown(hard_by_case, hard_methods))
        suites["hard"] = (hard_by_case, hard_methods)
    with open(os.path.join(a.out, "directions.md"), "w") as f:
        f.write(direction_report(suites, os.path.join(a.out, "directions.csv")))
    if a.scans and a.peer_scans:
        scan_rows = read_rows(a.scans) + read_rows(a.peer_scans)
        with open(os.path.join(a.out, "scans.md"), "w") as f:
            f.write(scans_markdown(scan_rows))
        if a.scan_fields:
            for scan in dict.fromkeys(r["scan"] for r in scan_rows):
                plot_histograms(scan, a.scan_fields, a.out)


if __name__ == "__main__":
    main()
