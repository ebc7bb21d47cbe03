#!/usr/bin/env python3
"""A fit's χ²/dof on simulated sessions (issue 37, deliverable 4; docs/uncertainty.md, "Fits").

For each material and seed: brdf-sim with the material and the error sources of coverage.py,
brdfd with the matching [uncertainty] terms, a plan run to completion, the session exported by
the daemon as a readings CSV of the BRDF (its u_<λ> columns from each reading's budget), and
`brdf-export fit --readings` run on that file. Prints, per run, the Cook-Torrance (GGX) and
Lambert χ²/dof and the fitted α ± u(α); and, for comparison, the χ²/dof when the same file's u
columns are replaced by the budgets' independent parts (the shared terms left out of the weights). A material the model can represent should give χ²/dof near
(or, since the weights are the combined u with the shared white-standard term, a little below) 1;
one it cannot, well above.

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


def export_session(sim, daemon, material, seed, plan, errors, csv_path):
    """Runs one session and has brdfd export its readings CSV of the BRDF to csv_path; returns
    each sample reading's independent part of u (its budget's), by id."""
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
    finally:
        rig.stop()
        rig.cleanup()
    return independent


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


def fit(export_tool, csv_path, out_path):
    """χ²/dof of both models and α ± u(α), from brdf-export fit's standard error."""
    err = subprocess.run([export_tool, "--quiet", "fit", "--readings", csv_path, "-o", out_path],
                         check=True, capture_output=True, text=True).stderr
    chi = re.findall(r"χ²/dof = ([0-9.e+-]+)", err)
    alpha = re.search(r"α = ([0-9.e+-]+) ± ([0-9.e+-]+|nan)", err)
    return {"weighted": "weighted by their uncertainties" in err,
            "lambert_chi2_dof": float(chi[0]) if len(chi) > 0 else None,
            "ct_chi2_dof": float(chi[1]) if len(chi) > 1 else None,
            "ct_alpha": alpha.group(1) if alpha else None,
            "ct_alpha_u": alpha.group(2) if alpha else None}


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
            path = material if material.endswith(".toml") else os.path.join(
                coverage.ROOT, "deploy", "materials", material + ".toml")
            for seed in args.seeds:
                label = os.path.basename(material).removesuffix(".toml")
                csv_path = os.path.join(work, f"{label}-{seed}.csv")
                independent = export_session(sim, daemon, path, seed, plan, errors, csv_path)
                row = fit(export_tool, csv_path, os.path.join(work, f"{label}-{seed}-fit.csv"))
                ind_path = os.path.join(work, f"{label}-{seed}-independent.csv")
                with_independent_u(csv_path, independent, ind_path)
                ind = fit(export_tool, ind_path, os.path.join(work, f"{label}-{seed}-fit-ind.csv"))
                row["ct_chi2_dof_independent_u"] = ind["ct_chi2_dof"]
                row["lambert_chi2_dof_independent_u"] = ind["lambert_chi2_dof"]
                print(json.dumps({"material": label, "seed": seed, **row}), flush=True)


if __name__ == "__main__":
    main()
