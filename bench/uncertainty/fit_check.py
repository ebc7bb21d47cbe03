#!/usr/bin/env python3
"""A fit's χ²/dof on simulated sessions (issue 37, deliverable 4; docs/uncertainty.md, "Fits").

For each material and seed: brdf-sim with the material and the error sources of coverage.py,
brdfd with the matching [uncertainty] terms, a plan run to completion, the session exported by
the daemon as a readings CSV of the BRDF (its u_<λ> columns from each reading's budget), and
`brdf-export fit` run three ways on the same session: on brdfd's database (`--db`: generalised
least squares with each reading's budget, its independent part and its shared components —
white standard, reference reading, dark, instrument — correlated; the "gls" figures), on that CSV
(`--readings`: weighted by the combined u as if independent), and on the CSV with its u columns
replaced by the budgets' independent parts. Prints, per run, the Cook-Torrance (GGX) and Lambert
χ²/dof of each, the fitted α and F0 ± u, and kd and ks at 550 nm ± u (GLS) with the material's
truth where it is the fit's own model (ggx-plastic). A material the model can represent should
give a GLS χ²/dof near 1; one it cannot, well above.

    bench/uncertainty/fit_check.py --materials bench/uncertainty/ggx-plastic.toml gold \
        retro-coating --seeds 1 2

A material is a name in deploy/materials/ or a path to a .toml file; ggx-plastic.toml (here) has
exactly the fit's model.

Needs a build with brdf-sim, brdfd, brdf-export and the Python stubs (BRDF_BUILD_DIR, default
build/). The default plan crosses the specular direction in plane (β every 11.25° at δ = 22.5°
and 45°), which examples/plans/demo.json does not.
"""

import argparse
import csv
import io
import json
import math
import os
import re
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)

import coverage  # noqa: E402  pylint: disable=wrong-import-position
from coverage import live_rig, BrdfClient, names  # noqa: E402  pylint: disable=wrong-import-position

PLAN = {"name": "fit check", "sampleDescription": "in-plane specular crossings",
        "sampleRotation": {"delta": {"start": 0, "stop": 45, "step": 22.5},
                           "alpha": {"start": 0, "stop": 40, "step": 20},
                           "beta": {"step": 11.25}},
        "reference": {"perDetectorPosition": True, "everyMinutes": 30},
        "dark": {"withEachReference": True},
        "measurement": {"integrationMs": 0, "averages": 1}}


def export_session(sim, daemon, material, seed, plan, errors, csv_path, on_database):
    """Runs one session and has brdfd export its readings CSV of the BRDF to csv_path; calls
    on_database(path, session id) once brdfd has stopped; returns each sample reading's
    independent part of u (its budget's), by id, and what on_database returned."""
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
        final = client.wait(s.session_id, on_prompt=act, timeout=1200, stop_states=("paused",))
        if names.state_name(final.state) != "completed":
            raise RuntimeError(f"session ended {names.state_name(final.state)}: "
                               f"{rig.log('brdfd')}")
        client.export(s.session_id, "csv", csv_path, quantity="brdf")
        data = client.load_readings(s.session_id).of_kind("sample")
        independent = {int(i): b.independent for i, b in zip(data.ids, data.budgets)
                       if b is not None}
        client.close()
        rig.stop()
        from_database = on_database(os.path.join(rig.dir, "brdfd.db"), s.session_id)
    finally:
        rig.stop()
        rig.cleanup()
    return independent, from_database


def with_independent_u(csv_path, independent, out_path):
    """The readings CSV with its u_<λ> columns replaced by the budgets' independent parts: a
    comparison of weights (the file brdfd writes carries the combined u)."""
    with open(csv_path, encoding="utf-8", newline="") as f:
        lines = f.read().splitlines()
    out, first_u = [], None
    for line in lines:
        if line.startswith("#"):
            out.append(line)
            continue
        row = next(csv.reader([line]))
        if first_u is None:
            first_u = next(i for i, h in enumerate(row) if h.startswith("u_"))
        elif int(row[0]) in independent:
            row[first_u:] = [repr(float(v)) for v in independent[int(row[0])]]
        buf = io.StringIO()
        csv.writer(buf, lineterminator="").writerow(row)
        out.append(buf.getvalue())
    with open(out_path, "w", encoding="utf-8") as f:
        f.write("\n".join(out) + "\n")


def at_550(out_path):
    """kd ± u and ks ± u at the band nearest 550 nm of a fit report CSV."""
    with open(out_path, encoding="utf-8") as f:
        rows = list(csv.DictReader(line for line in f if not line.startswith("#")))
    row = min(rows, key=lambda r: abs(float(r["wavelength_nm"]) - 550))
    return {"ct_kd_550": f'{float(row["ct_kd"]):.4f} ± {float(row["ct_kd_u"]):.4f}',
            "ct_ks_550": f'{float(row["ct_ks"]):.4f} ± {float(row["ct_ks_u"]):.4f}'}


def fit(export_tool, source_args, out_path):
    """χ²/dof of both models, how the fit weighted, α ± u(α) and F0 ± u(F0), from brdf-export
    fit's standard error; kd and ks at 550 nm from its report."""
    err = subprocess.run([export_tool, "--quiet", "fit", *source_args, "-o", out_path],
                         check=True, capture_output=True, text=True).stderr
    chi = re.findall(r"χ²/dof = ([0-9.e+-]+)", err)
    alpha = re.search(r"α = ([0-9.e+-]+) ± ([0-9.e+-]+|nan)", err)
    f0 = re.search(r"F0 = ([0-9.e+-]+) ± ([0-9.e+-]+|nan)", err)
    weighting = re.search(r"weighted by their uncertainties: ([^)]*)\)", err)
    return {"weighting": weighting.group(1) if weighting else "unweighted",
            "lambert_chi2_dof": float(chi[0]) if len(chi) > 0 else None,
            "ct_chi2_dof": float(chi[1]) if len(chi) > 1 else None,
            "ct_alpha": f"{alpha.group(1)} ± {alpha.group(2)}" if alpha else None,
            "ct_f0": f"{f0.group(1)} ± {f0.group(2)}" if f0 else None,
            **at_550(out_path)}


# The truth where the material is the fit's own model: kd(550) from the albedo bump
# 0.25 + 0.45 exp(−((λ − 610)/90)²), ks 1, α 0.2, F0 0.04 (ggx-plastic.toml).
TRUTH = {"ggx-plastic": {"alpha": 0.2, "f0": 0.04, "ks": 1.0,
                         "kd_550": 0.25 + 0.45 * math.exp(-((550 - 610) / 90) ** 2)}}


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", maxsplit=1)[0])
    p.add_argument("--materials", nargs="+",
                   default=[os.path.join(HERE, "ggx-plastic.toml"), "gold", "retro-coating"])
    p.add_argument("--seeds", nargs="+", type=int, default=[1])
    p.add_argument("--plan", help="a plan JSON file (default: the in-plane crossing plan above)")
    args = p.parse_args()
    sim, daemon = live_rig.binaries()
    export_tool = os.path.join(live_rig.build_dir(), "tools", "brdf-export", "brdf-export")
    if not sim or not daemon or not os.access(export_tool, os.X_OK):
        sys.exit("build brdf-sim, brdfd and brdf-export first (BRDF_BUILD_DIR)")
    plan = PLAN
    if args.plan:
        with open(args.plan, encoding="utf-8") as fh:
            plan = json.load(fh)
    errors = coverage.ERRORS
    print(json.dumps({"errors": errors, "plan": plan["name"]}), flush=True)
    with tempfile.TemporaryDirectory() as work:
        for material in args.materials:
            label, path = coverage.material_file(material)
            for seed in args.seeds:
                csv_path = os.path.join(work, f"{label}-{seed}.csv")
                gls_out = os.path.join(work, f"{label}-{seed}-fit-gls.csv")
                independent, gls = export_session(
                    sim, daemon, path, seed, plan, errors, csv_path,
                    lambda db, sid, out=gls_out: fit(
                        export_tool, ["--db", db, "--session", str(sid)], out))
                row = {"gls": gls,
                       "combined_u": fit(export_tool, ["--readings", csv_path],
                                         os.path.join(work, f"{label}-{seed}-fit.csv"))}
                ind_path = os.path.join(work, f"{label}-{seed}-independent.csv")
                with_independent_u(csv_path, independent, ind_path)
                row["independent_u"] = fit(export_tool, ["--readings", ind_path],
                                           os.path.join(work, f"{label}-{seed}-fit-ind.csv"))
                if label in TRUTH:
                    row["truth"] = TRUTH[label]
                print(json.dumps({"material": label, "seed": seed, **row}), flush=True)


if __name__ == "__main__":
    main()
