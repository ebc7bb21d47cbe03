#!/usr/bin/env python3
"""Combines the per-session lines of coverage.py runs (their standard output, JSON lines) into
figures per material and overall, as coverage.py prints them for one run: so a campaign can be run
in parts (seeds 1–12, then 13–24) and counted as one. Sessions are independent (each material and
seed has a seed of its own), so they simply pool; the normalised errors' RMS, mean and spread pool
through their moments, weighted by each session's pairs. Prints JSON lines and a Markdown table.

    bench/uncertainty/combine.py part1.log part2.log
"""

import json
import math
import sys


def sessions_of(paths):
    """{material: [session row, ...]} from the logs' per-session lines ("<material> seed <n>")."""
    out = {}
    for path in paths:
        with open(path, encoding="utf-8") as fh:
            for line in fh:
                if not line.startswith("{"):
                    continue
                row = json.loads(line)
                if " seed " in row.get("run", ""):
                    out.setdefault(row["run"].split(" seed ")[0], []).append(row)
    return out


def pooled(label, rows):
    """The figures of a set of sessions (coverage weighted by pairs; SE between sessions)."""
    pairs = sum(r["pairs"] for r in rows)
    cov = sum(r["coverage_all_bands"] * r["pairs"] for r in rows) / pairs
    readings = sum(r["readings"] for r in rows)
    cov552 = sum(r["coverage_552nm"] * r["readings"] for r in rows) / readings
    m2 = sum((r["z_sd"] ** 2 + r["z_mean"] ** 2) * r["pairs"] for r in rows) / pairs
    m1 = sum(r["z_mean"] * r["pairs"] for r in rows) / pairs
    per = [r["coverage_all_bands"] for r in rows]
    mean = sum(per) / len(per)
    sd = math.sqrt(sum((c - mean) ** 2 for c in per) / (len(per) - 1)) if len(per) > 1 else 0.0
    return {"run": label, "sessions": len(rows), "readings": readings, "pairs": pairs,
            "coverage_all_bands": round(cov, 4), "coverage_552nm": round(cov552, 4),
            "se_binomial": round(math.sqrt(cov * (1 - cov) / pairs), 4),
            "se_sessions": round(sd / math.sqrt(len(per)), 4),
            "session_coverage_range": [min(per), max(per)],
            "z_rms": round(math.sqrt(m2), 3), "z_mean": round(m1, 3),
            "z_sd": round(math.sqrt(max(m2 - m1 * m1, 0.0)), 3),
            "median_rel_U": round(sorted(r["median_rel_U"] for r in rows)[len(rows) // 2], 4)}


def main():
    by_material = sessions_of(sys.argv[1:])
    rows = [pooled(m, s) for m, s in by_material.items()]
    rows.append(pooled("all", [r for s in by_material.values() for r in s]))
    for row in rows:
        print(json.dumps(row))
    print("| material | sessions | reading-bands | coverage (k = 2) | SE (sessions) | "
          "session range | at 552 nm | z RMS | z mean | median U / f |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in rows:
        lo, hi = r["session_coverage_range"]
        print(f"| {r['run']} | {r['sessions']} | {r['pairs']:,} | "
              f"{100 * r['coverage_all_bands']:.1f} % | {100 * r['se_sessions']:.1f} | "
              f"{100 * lo:.1f}–{100 * hi:.1f} % | {100 * r['coverage_552nm']:.1f} % | "
              f"{r['z_rms']:.2f} | {r['z_mean']:+.2f} | {100 * r['median_rel_U']:.1f} % |")


if __name__ == "__main__":
    main()
