#!/usr/bin/env python3
"""daemon_bench.sh's table (docs/adaptive.md, "The benchmark through the daemon"): joins the
sessions' rows and their errors from one or more work directories, gives each row its ratios to
its material's grid and the goal, and writes PREFIX.csv and PREFIX.txt (a Markdown table, each
adaptive row's goal, a verdict per material).

A work directory holds (daemon_bench.sh writes them):
  meta.txt    one line: when, commit, brdf-sim seed, time scale, directions, load at the start
  rows.tsv    material, label, budget readings, readings, rig s, prompts, wall s, session, stop
  errors.tsv  material, label, err, peak, retro, fallback (share)

The goal (issue 38): an adaptive session reaches the grid's error (error ÷ grid ≤ 1) with at most
20 % of its sample readings and 25 % of its rig time; and, at equal readings, at most half the
grid's error. The sessions here have fewer readings than the grid, so an error ≤ ½ the grid's
shows the second; a larger one does not disprove it (that needs a budget of 100 %).

    daemon_bench_table.py --work /tmp/run-a --work /tmp/run-b --out /tmp/table [--smoke]
"""

import argparse
import csv
import math
import os
import sys


def read_tsv(path, width):
    if not os.path.isfile(path):
        return []
    rows = [line.rstrip("\n").split("\t") for line in open(path, encoding="utf-8")]
    return [r for r in rows if len(r) == width]


def hms(seconds):
    s = round(float(seconds))
    return f"{s // 3600}:{s % 3600 // 60:02d}:{s % 60:02d}"


def goal_of(e_ratio, r_ratio, t_ratio):
    """(reached, half, text) of one adaptive row."""
    reached = e_ratio <= 1 and r_ratio <= 0.20 and t_ratio <= 0.25
    half = e_ratio <= 0.5
    short = [w for w, bad in (("error", e_ratio > 1), ("readings", r_ratio > 0.20),
                              ("rig time", t_ratio > 0.25)) if bad]
    text = ("grid's error at <= 20 % readings and <= 25 % rig time: "
            + ("yes" if reached else "no (" + ", ".join(short) + ")")
            + "; half the grid's error: " + ("yes" if half else "no"))
    return reached, half, text


def build_table(rows, errors):
    """The table's rows (dicts) and a verdict per material: [reached, half, best error ratio]."""
    errs = {(e[0], e[1]): tuple(float(x) for x in e[2:]) for e in errors}
    grid = {r[0]: r for r in rows if r[1] == "grid"}
    table, verdicts, seen = [], {}, set()
    for r in rows:
        m, label, budget, readings, rig, prompts, wall, session, stop = r
        if (m, label) in seen or (m, label) not in errs or m not in grid:
            continue  # a repeated row, or one whose session was not judged
        seen.add((m, label))
        err, peak, retro, fallback = errs[(m, label)]
        g = grid[m]
        e_ratio = err / errs[(m, "grid")][0]
        r_ratio, t_ratio = int(readings) / int(g[3]), float(rig) / float(g[4])
        goal = ""
        if label != "grid":
            reached, half, goal = goal_of(e_ratio, r_ratio, t_ratio)
            v = verdicts.setdefault(m, [False, False, math.inf])
            v[0], v[1], v[2] = v[0] or reached, v[1] or half, min(v[2], e_ratio)
        table.append({"material": m, "plan": label, "budget_readings": budget,
                      "readings": readings, "rig_time_s": f"{float(rig):.0f}",
                      "rig_time": hms(rig), "prompts": prompts, "error": f"{err:.4f}",
                      "peak_error": f"{peak:.4f}", "retro_error": f"{retro:.4f}",
                      "fallback_pct": f"{100 * fallback:.1f}", "error_over_grid": f"{e_ratio:.3f}",
                      "readings_over_grid": f"{r_ratio:.3f}",
                      "rig_time_over_grid": f"{t_ratio:.3f}", "goal": goal, "session": session,
                      "wall_s": wall, "stop": stop})
    return table, verdicts


def summary(table, verdicts, heads, load_end):
    lines = heads + [f"# load at the end: {load_end}", "",
                     "| material | plan | readings (÷ grid) | rig time (÷ grid) | prompts | "
                     "error (÷ grid) | peak error | retro | fb % | wall s |",
                     "|---|---|---|---|---|---|---|---|---|---|"]
    for t in table:
        lines.append(f"| {t['material']} | {t['plan']} | {t['readings']} "
                     f"({t['readings_over_grid']}) | {t['rig_time']} ({t['rig_time_over_grid']}) "
                     f"| {t['prompts']} | {t['error']} ({t['error_over_grid']}) | "
                     f"{t['peak_error']} | {t['retro_error']} | {t['fallback_pct']} | "
                     f"{t['wall_s']} |")
    lines.append("")
    lines += [f"{t['material']} {t['plan']}: {t['goal']}; stop: {t['stop']}"
              for t in table if t["goal"]]
    lines.append("")
    for m, (reached, half, best) in verdicts.items():
        lines.append(f"{m}: the grid's error at <= 20 % readings and <= 25 % rig time "
                     f"{'REACHED' if reached else 'not reached'}; half the grid's error "
                     f"{'REACHED' if half else 'not reached'} (best error ÷ grid {best:.3f})")
    return "\n".join(lines) + "\n"


def smoke_ok(table):
    """The smoke form's check: a grid and an adapt50 row, errors finite and below 0.5 (the paint
    is smooth: 0.25 in both on 2026-12-06), rig times above 0, the adaptive readings within their
    budget."""
    return (len(table) == 2 and [t["plan"] for t in table] == ["grid", "adapt50"]
            and all(math.isfinite(float(t["error"])) and float(t["error"]) < 0.5 for t in table)
            and all(float(t["rig_time_s"]) > 0 for t in table)
            and 0 < int(table[1]["readings"]) <= int(table[1]["budget_readings"]))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", maxsplit=1)[0])
    p.add_argument("--work", action="append", required=True, help="a work directory (repeat)")
    p.add_argument("--out", required=True, help="writes OUT.csv and OUT.txt")
    p.add_argument("--smoke", action="store_true", help="check the smoke form's table")
    a = p.parse_args()
    rows, errors, heads = [], [], []
    for w in a.work:
        rows += read_tsv(os.path.join(w, "rows.tsv"), 9)
        errors += read_tsv(os.path.join(w, "errors.tsv"), 6)
        meta = os.path.join(w, "meta.txt")
        if os.path.isfile(meta):
            heads.append("# " + open(meta, encoding="utf-8").read().strip())
    table, verdicts = build_table(rows, errors)
    if not table:
        sys.exit(f"daemon_bench_table: no judged session in {', '.join(a.work)} (rows.tsv and "
                 "errors.tsv)")
    with open(a.out + ".csv", "w", newline="", encoding="utf-8") as f:
        writer = csv.DictWriter(f, fieldnames=list(table[0]))
        writer.writeheader()
        writer.writerows(table)
    with open("/proc/loadavg", encoding="utf-8") as f:
        load_end = " ".join(f.read().split()[:3])
    text = summary(table, verdicts, heads, load_end)
    with open(a.out + ".txt", "w", encoding="utf-8") as f:
        f.write(text)
    print(text, end="")
    print(f"written: {a.out}.csv, {a.out}.txt")
    if a.smoke:
        ok = smoke_ok(table)
        print("smoke:", "ok" if ok else "FAILED (want a grid and an adapt50 row, errors finite "
              "and below 0.5 on the paint, rig times > 0, the adaptive readings within the budget)")
        sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
