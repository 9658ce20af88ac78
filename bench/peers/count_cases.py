#!/usr/bin/env python3
"""Counts, case by case, where focal default has the lowest relative H error, as issue 32 counts
them, from the merged CSVs that report.py writes (merged.csv, hard-merged.csv):

  count_cases.py --standard merged.csv --hard hard-merged.csv [--label "seed 1"]

- file normals: focal default / file normals against every other method (the other focal
  default row excepted), focal's settings, baselines and peers;
- no normals: focal default / no normals against the other positions-only methods;
- outliers: focal default / no normals against the best peer on each outlier case.
Ties within 0.1% count as lowest (report.py's at_most). Prints Markdown: the counts and every
lost case with the winner and both errors.
"""
import argparse
import math

from report import (DEFAULT_FILE, DEFAULT_NONE, PEERS, at_most, category_of, label, lowest,
                    positions_only, read_rows, table, value)


def count(by_case, methods, cases, name, rivals_of):
    won, lost = 0, []
    for k in cases:
        row = by_case[k]
        mine = value(row[name])
        best, best_name = lowest(row, rivals_of(methods))
        if at_most(mine, best):
            won += 1
        else:
            lost.append((k, mine, best_name, best))
    return won, lost


def file_rivals(methods):
    return [m for m in methods if m not in (DEFAULT_FILE, DEFAULT_NONE)]


def none_rivals(methods):
    return [m for m in methods if positions_only(m) and m != DEFAULT_NONE]


def peers_only(methods):
    return [m for m in methods if m in PEERS]


def report(title, by_case, methods, cases, rows):
    out = [f"### {title}", "", "| setting | lowest | of |", "|---|---|---|"]
    losses = []
    for setting, name, rivals, subset in rows:
        subset = [k for k in cases if subset(k)]
        won, lost = count(by_case, methods, subset, name, rivals)
        out.append(f"| {setting} | {won} | {len(subset)} |")
        losses += [(setting, *x) for x in lost]
    if losses:
        out += ["", "| setting | case | focal default | winner | its rel. H | factor |",
                "|---|---|---|---|---|---|"]
        for setting, k, mine, best_name, best in losses:
            factor = mine / best if best > 0 else math.inf
            out.append(f"| {setting} | {category_of(by_case, k)}: {label(k)} | {mine:.4g} | "
                       f"{best_name} | {best:.4g} | {factor:.3g} |")
    return "\n".join(out) + "\n"


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--standard", required=True)
    p.add_argument("--hard", required=True)
    p.add_argument("--label", default="")
    a = p.parse_args()
    std, std_methods = table(read_rows(a.standard))
    hard, hard_methods = table(read_rows(a.hard))
    every = lambda k: True  # noqa: E731
    # Under normal noise positions-only methods see the clean case: left out without normals,
    # as report.py's count_target does.
    not_normal_noise = lambda k: not k[2].startswith("normal noise")  # noqa: E731
    irregular_or_noisy = lambda k: k[1] == "irregular" or k[2] != "clean"  # noqa: E731
    suffix = f" ({a.label})" if a.label else ""
    print(report("Hard suite" + suffix, hard, hard_methods, list(hard), [
        ("file normals", DEFAULT_FILE, file_rivals, every),
        ("no normals", DEFAULT_NONE, none_rivals, every),
        ("outliers, no normals, against the best peer", DEFAULT_NONE, peers_only,
         lambda k: category_of(hard, k) == "outliers")]))
    print(report("Standard suite" + suffix, std, std_methods, list(std), [
        ("file normals, all cases", DEFAULT_FILE, file_rivals, every),
        ("file normals, irregular or noisy", DEFAULT_FILE, file_rivals, irregular_or_noisy),
        ("no normals, all cases but normal noise", DEFAULT_NONE, none_rivals, not_normal_noise),
        ("no normals, irregular or vertex noise", DEFAULT_NONE, none_rivals,
         lambda k: irregular_or_noisy(k) and not_normal_noise(k))]))


if __name__ == "__main__":
    main()
