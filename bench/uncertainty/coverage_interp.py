#!/usr/bin/env python3
"""Do interpolated values' k = 2 intervals hold the truth as often as they claim? (issue 37,
deliverable 6; docs/uncertainty.md, "Interpolated values").

For each material and seed: brdf-sim with the material and its error sources on, brdfd with the
matching [uncertainty] terms (the same as coverage.py, whose helpers this script uses), a plan run
to completion, then one InterpolateBatch with uncertainties at random directions (θi, θo uniform
in [0, --theta-max], φ in [0, 180]) while the rig is still up, and every OK answer compared, band
by band, with `brdf-sim truth` at its direction. Prints per run and over all: the fraction of
(direction, band) pairs whose interval y ± k·u holds the truth with u the combined uncertainty,
the same with the measurement part alone and with the interpolation term scaled by 0.25, 0.5 and
0.75, the normalised errors' spread, and the median k·u against the median actual error (the
goal: intervals at most 2× the error, coverage 93–97 %); then each material pooled over its seeds
(with its lowest and highest session) and all sessions pooled. --expect-coverage and
--expect-ratio make it a test (exit 1 when the pooled figures miss; 77 when nothing is built);
--dump keeps each session's answers, uncertainties and truth as .npz. --export-grid STEPS
counts the same for a grid export with uncertainty (Data.Export, include_uncertainty) instead of
the batch: its cells' centres (θi, θo ≤ --theta-max) are the directions, each cell's value and u
(the .npy and its u and u_measurement arrays) the answer, with --fill's chain behind them; with
--fill chain the cells are also counted by kind, "interpolated" (the chosen method's or the
Delaunay fallback's: u_measurement finite) and "model" (u_measurement NaN), each with the cells
whose u is not estimated (NaN: model cells beyond the calibration's reach), which no coverage
counts.

    bench/uncertainty/coverage_interp.py --materials paint clay --seeds 1 2 --directions 2000

Needs a build with brdf-sim, brdfd and the Python stubs (BRDF_BUILD_DIR, default build/).
"""

import argparse
import json
import os
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import coverage  # noqa: E402  pylint: disable=wrong-import-position
from coverage import live_rig, BrdfClient, names  # noqa: E402  pylint: disable=wrong-import-position


def iso_truth(sim, material, d):
    """brdf-sim's truth at an isotropic direction (θi, θo, φ): φi = 0, φo = φ."""
    return coverage.truth(sim, material, (d[0], 0.0, d[1], d[2]))


def grid_answers(client, session_id, steps, method, fill, theta_max):
    """A grid export with uncertainty as answers: (directions, ok, y, u, u_meas) over the cells
    whose θi and θo are at most theta_max."""
    with tempfile.TemporaryDirectory() as work:
        path = os.path.join(work, "g.npy")
        client.export(session_id, "grid", path, method=method, fill=fill, step_theta_i=steps[0],
                      step_theta_o=steps[1], step_phi=steps[2], uncertainty=True, progress=False)
        y, u, u_meas = (np.load(os.path.join(work, name))
                        for name in ("g.npy", "g.u.npy", "g.u_measurement.npy"))
    ti, to, ph = (s / 2 + s * np.arange(n) for s, n in zip(steps, y.shape[:3]))
    dirs = np.stack(np.meshgrid(ti, to, ph, indexing="ij"), axis=-1).reshape(-1, 3)
    y, u, u_meas = (a.reshape(-1, a.shape[-1]) for a in (y, u, u_meas))
    keep = (dirs[:, 0] <= theta_max) & (dirs[:, 1] <= theta_max)
    ok = np.isfinite(y[:, 0]) & keep
    return dirs, ok, y, u, u_meas


def interpolate_session(sim, daemon, material, seed, plan, errors, directions, method,
                        grid=None):
    """The batch's answers at `directions` once the plan completed: (ok, y, u, u_meas, wl);
    with `grid` (steps, fill, theta_max) the grid export's instead: (dirs, ok, y, u, u_meas)."""
    rig = live_rig.LiveRig(sim, daemon, seed=seed, sim_args=coverage.sim_flags(material, errors),
                           extra_config=coverage.budget_config(errors))
    rig.sample_extra = f"white_reflectance_uncertainty = {0.99 * errors['white_error']}\n"
    rig.start()
    try:
        client = BrdfClient(rig.address, rig.operator_token)
        client.wait_ready(10)

        def act(prompt):
            what = coverage.PROMPT_ACTIONS.get(names.prompt_kind_name(prompt.kind))
            if what:
                rig.set_mounted(what)

        s = client.submit_plan(plan, start_now=True)
        final = client.wait(s.session_id, on_prompt=act, timeout=600, stop_states=("paused",))
        if names.state_name(final.state) != "completed":
            raise RuntimeError(f"session ended {names.state_name(final.state)}")
        if grid is not None:
            answers = grid_answers(client, s.session_id, grid[0], method, grid[1], grid[2])
            client.close()
            return answers
        batch = client.interpolate_batch(s.session_id, directions, method=method,
                                         uncertainty=True, progress=False)
        client.close()
    finally:
        rig.stop()
        rig.cleanup()
    return batch.ok, batch.spectra, batch.u_combined, batch.u_measurement, batch.wavelengths


def summarise(label, y, u, u_meas, t, k):
    ok = np.isfinite(y) & np.isfinite(u) & (u > 0) & np.isfinite(t)
    err = np.abs(y - t)
    row = {"run": label, "answers": int(y.shape[0]),
           "coverage": float((err <= k * u)[ok].mean()),
           "coverage_measurement_only": float((err <= k * u_meas)[ok & np.isfinite(u_meas)].mean()),
           "z_sd": float(np.std(((y - t) / u)[ok])),
           "median_kU": float(np.median((k * u)[ok])), "median_error": float(np.median(err[ok])),
           "median_rel_kU": float(np.median((k * u / np.abs(t))[ok & (t != 0)]))}
    row["kU_over_error"] = row["median_kU"] / row["median_error"] if row["median_error"] else None
    u_int = np.sqrt(np.maximum(u * u - u_meas * u_meas, 0.0))
    for scale in (0.25, 0.5, 0.75):
        scaled = np.hypot(u_meas, scale * u_int)
        row[f"coverage_interp_x{scale}"] = float((err <= k * scaled)[ok].mean())
    print(json.dumps(row), flush=True)
    return (err <= k * u)[ok], ((y - t) / u)[ok], (k * u)[ok], err[ok]


def by_kind(material, seed, y, u, u_meas, t, k, kinds):
    """A chain's cells split by kind (interpolated: u_measurement finite; model: NaN), each
    summarised, with the count of its cells whose u is not estimated (NaN)."""
    model = ~np.isfinite(u_meas[:, 0])
    for kind, sel in (("interpolated", ~model), ("model", model)):
        estimated = sel & np.isfinite(u[:, 0])
        print(json.dumps({"run": f"{material} seed {seed} {kind} cells", "cells": int(sel.sum()),
                          "not_estimated": int((sel & ~estimated).sum())}), flush=True)
        if estimated.any():
            kinds.setdefault((material, kind), []).append(summarise(
                f"{material} seed {seed} {kind} cells ({int(estimated.sum())} estimated)",
                y[estimated], u[estimated], u_meas[estimated], t[estimated], k))


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", maxsplit=1)[0])
    p.add_argument("--materials", nargs="+", default=["paint", "glossy", "clay", "gold",
                                                      "blue-plastic"])
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2])
    p.add_argument("--plan", default=os.path.join(coverage.ROOT, "examples", "plans",
                                                  "demo.json"))
    p.add_argument("--directions", type=int, default=2000)
    p.add_argument("--theta-max", type=float, default=80.0)
    p.add_argument("--method", default="octant")
    p.add_argument("--export-grid", metavar="STEPS",
                   help="count a grid export's cells instead: its steps θi,θo,φ (e.g. 10,10,20)")
    p.add_argument("--fill", default="chain", help="--export-grid's fill: chain or none")
    p.add_argument("--k", type=float, default=2.0)
    p.add_argument("--expect-coverage", nargs=2, type=float, metavar=("LO", "HI"),
                   help="fail unless the pooled coverage lies in [LO, HI] (the test's short form)")
    p.add_argument("--expect-ratio", type=float, metavar="MAX",
                   help="fail unless the pooled median k·u / median |error| is at most MAX")
    p.add_argument("--dump", help="a folder to write each run's directions, answers, "
                                  "uncertainties and truth to (.npz)")
    args = p.parse_args()
    errors = dict(coverage.ERRORS)
    sim, daemon = live_rig.binaries()
    if not sim or not daemon:
        print("build brdf-sim and brdfd first (BRDF_BUILD_DIR); skipped", file=sys.stderr)
        sys.exit(77)
    with open(args.plan, encoding="utf-8") as fh:
        plan = json.load(fh)
    print(json.dumps({"errors": errors, "k": args.k, "plan": os.path.basename(args.plan),
                      "directions": args.directions, "method": args.method,
                      "theta_max": args.theta_max}))
    parts = []
    by_material = {}
    kinds = {}
    for entry in args.materials:
        material, path = coverage.material_file(entry)
        for seed in args.seeds:
            rng = np.random.default_rng(seed)
            dirs = np.column_stack([rng.uniform(0, args.theta_max, args.directions),
                                    rng.uniform(0, args.theta_max, args.directions),
                                    rng.uniform(0, 180, args.directions)])
            if args.export_grid:
                steps = [float(x) for x in args.export_grid.split(",")]
                dirs, ok, y, u, u_meas = interpolate_session(
                    sim, daemon, path, seed, plan, errors, None, args.method,
                    grid=(steps, args.fill, args.theta_max))
            else:
                ok, y, u, u_meas, _ = interpolate_session(sim, daemon, path, seed, plan, errors,
                                                          dirs, args.method)
            t = np.full_like(y, np.nan)
            for i in np.flatnonzero(ok):
                t[i] = iso_truth(sim, path, dirs[i])
            if args.dump:
                os.makedirs(args.dump, exist_ok=True)
                np.savez(os.path.join(args.dump, f"{material}-{seed}.npz"), directions=dirs[ok],
                         y=y[ok], u=u[ok], u_measurement=u_meas[ok], truth=t[ok])
            parts.append(summarise(f"{material} seed {seed} ({int(ok.sum())} ok)",
                                   y[ok], u[ok], u_meas[ok], t[ok], args.k))
            by_material.setdefault(material, []).append(parts[-1])
            if args.export_grid and args.fill == "chain":
                by_kind(material, seed, y[ok], u[ok], u_meas[ok], t[ok], args.k, kinds)
    for material, runs in by_material.items():
        pooled(material, runs)
    for (material, kind), runs in kinds.items():
        pooled(f"{material} {kind} cells", runs)
    for kind in ("interpolated", "model"):
        runs = [r for (m, k), rs in kinds.items() if k == kind for r in rs]
        if runs:
            pooled(f"all {kind} cells", runs)
    row = pooled("all", parts)
    return check(args, row)


def pooled(label, runs):
    """One line over several runs: coverage pooled and per run (min, max), the interval ratio."""
    inside, z, ku, err = (np.concatenate([r[i] for r in runs]) for i in range(4))
    per_run = [float(r[0].mean()) for r in runs]
    row = {"run": label, "sessions": len(runs), "pairs": int(inside.size),
           "coverage": float(inside.mean()), "coverage_min": min(per_run),
           "coverage_max": max(per_run), "z_sd": float(np.std(z)),
           "median_kU": float(np.median(ku)), "median_error": float(np.median(err)),
           "kU_over_error": float(np.median(ku) / np.median(err))}
    print(json.dumps(row), flush=True)
    return row


def check(args, row):
    """The failures of the --expect options, each printed; 1 when any."""
    failures = []
    if args.expect_coverage and not args.expect_coverage[0] <= row["coverage"] <= \
            args.expect_coverage[1]:
        failures.append(f"coverage {row['coverage']:.3f} outside {args.expect_coverage}")
    if args.expect_ratio is not None and not row["kU_over_error"] <= args.expect_ratio:
        failures.append(f"median k·u / median |error| {row['kU_over_error']:.2f} above "
                        f"{args.expect_ratio}")
    for failure in failures:
        print("FAILED: " + failure, file=sys.stderr)
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
