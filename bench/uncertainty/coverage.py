#!/usr/bin/env python3
"""Does a reading's k = 2 interval hold the truth as often as it claims? (issue 37, the simulator
check; docs/uncertainty.md, "Checking it against the simulator").

For each material and seed: brdf-sim with the material and its error sources switched on
(docs/simulator-errors.md), brdfd configured with the matching [uncertainty] terms, a plan run to
completion (the operator's actions done on the simulator's control unit), the stored budgets read
back through brdf_client, and every sample reading's BRDF compared, band by band, with
`brdf-sim truth` at the reading's directions. Prints the fraction of (reading, band) pairs and of
readings (at 552 nm) whose interval f ± k·u_c holds the truth, per session, per material and over
all, with the standard errors of those fractions, the normalised errors (f − truth) / u_c (RMS,
mean, spread), each component's share of the budget's variance and the terms not estimated. The
goal is 95 % ± 2 % at k = 2. Each material's sessions take seeds of their own (sim_seed), so the
session-wide draws (white standard, wavelength shift) are independent across all sessions.

    bench/uncertainty/coverage.py --materials paint glossy clay gold blue-plastic retro-coating \
        --seeds $(seq 1 12) --json campaign.json
    bench/uncertainty/coverage.py --materials paint clay --seeds 1 2 3 --sources white_error

A material is a name in deploy/materials/ or a path to a .toml file (docs/materials.md), named
in the output by its file name (coverage_interp.py and fit_check.py take the same).
`--sources` switches on only the named error sources (in the simulator and the budget alike) to
tell which term is over- or under-stated; the `--expect-*` flags make it a test (the ctest
`uncertainty_coverage_short`, bench/uncertainty/CMakeLists.txt). Exit 77: brdf-sim or brdfd not
built. Needs a build with brdf-sim, brdfd and the Python stubs (BRDF_BUILD_DIR, default build/).
"""

import argparse
import json
import math
import os
import subprocess
import sys
import zlib

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import live_rig  # noqa: E402  pylint: disable=wrong-import-position
from brdf_client import BrdfClient, names  # noqa: E402  pylint: disable=wrong-import-position

PROMPT_ACTIONS = {"mount_white": "white", "close_shutter": "dark", "mount_sample": "sample"}

# The error sources, as brdf-sim flags, and the budget's matching terms (docs/uncertainty.md,
# "Checking it against the simulator"). white_error is relative; u(ρw) = ρw · white_error.
# brdf-sim's stray light is a fraction of a perfect diffuser's light; as a fraction of the white's
# signal it is s / ρw at normal incidence (the default reference pose). The detector's shot and
# read noise are always on (the budget's meter noise model has the simulator's defaults).
ERRORS = {"gain_noise": 0.002, "white_error": 0.005, "wavelength_shift_sigma": 1.0,
          "stray_light": 0.0002, "lamp_drift": -0.002, "pose_jitter": 0.1}
SOURCES = tuple(ERRORS)
RHO_W = 0.99


def sim_flags(material, errors):
    return ["--material", material, "--gain-noise", str(errors["gain_noise"]),
            "--white-error", str(errors["white_error"]),
            "--wavelength-shift-sigma", str(errors["wavelength_shift_sigma"]),
            "--stray-light", str(errors["stray_light"]),
            "--lamp-drift", str(errors["lamp_drift"]),
            "--pose-jitter", str(errors["pose_jitter"])]


def budget_config(errors):
    return f"""
[uncertainty]
enabled = true
wavelength_nm = {errors["wavelength_shift_sigma"]}
stray_light = {errors["stray_light"] / RHO_W}
stage_repeatability_deg = {errors["pose_jitter"]}
lamp_drift_per_hour = {errors["lamp_drift"]}
meter_gain_repeatability = {errors["gain_noise"]}
"""


def material_file(material):
    """(label, path) of a --materials entry: a name in deploy/materials/ or a path to a .toml
    file (a material written elsewhere), labelled by its file name without .toml."""
    if material.endswith(".toml"):
        return os.path.basename(material).removesuffix(".toml"), os.path.abspath(material)
    return material, os.path.join(ROOT, "deploy", "materials", material + ".toml")


def sim_seed(material, seed):
    """brdf-sim's seed for a material's session `seed`: distinct per material, so that the
    session-wide draws (white standard, wavelength shift) are independent across materials too."""
    return seed * 1000 + zlib.crc32(material.encode()) % 1000


def truth(sim, material, d):
    out = subprocess.run([sim, "--material", material, "truth", "--theta-i", repr(d[0]),
                          "--phi-i", repr(d[1]), "--theta-o", repr(d[2]), "--phi-o", repr(d[3]),
                          "--json"], check=True, capture_output=True, text=True).stdout
    return np.array(json.loads(out)["brdf"], dtype=float)


def run_session(sim, daemon, material, seed, plan, errors):
    """One session's sample readings: a dict of f, u, truth (n, m), the budgets, wavelengths and
    directions (n, 4: θi φi θo φo)."""
    rig = live_rig.LiveRig(sim, daemon, seed=seed, sim_args=sim_flags(material, errors),
                           extra_config=budget_config(errors))
    rig.sample_extra = f"white_reflectance_uncertainty = {RHO_W * errors['white_error']}\n"
    rig.start()
    try:
        client = BrdfClient(rig.address, rig.operator_token)
        client.wait_ready(10)

        def act(prompt):
            what = PROMPT_ACTIONS.get(names.prompt_kind_name(prompt.kind))
            if what:
                rig.set_mounted(what)

        s = client.submit_plan(plan, start_now=True)
        final = client.wait(s.session_id, on_prompt=act, timeout=600, stop_states=("paused",))
        if names.state_name(final.state) != "completed":
            raise RuntimeError(f"session ended {names.state_name(final.state)}: "
                               f"{rig.log('brdfd')}")
        data = client.load_readings(s.session_id).of_kind("sample")
        client.close()
    finally:
        rig.stop()
        rig.cleanup()
    keep = np.array([b is not None for b in data.budgets], dtype=bool)
    data = data.select(keep)
    return {"f": np.array([b.value for b in data.budgets]),
            "u": np.asarray(data.brdf_uncertainty),
            "t": np.array([truth(sim, material, d) for d in data.directions]),
            "budgets": list(data.budgets), "wl": np.asarray(data.wavelengths),
            "directions": np.asarray(data.directions)}


def component_shares(budgets, ok):
    """Each component's share of the combined variance, Σ uⱼ² / Σ u_c² over the session's
    (reading, band) pairs, and the not-estimated terms named (counted by name)."""
    total = sum(float(np.sum((b.combined ** 2)[ok[i]])) for i, b in enumerate(budgets))
    shares, missing = {}, {}
    for i, b in enumerate(budgets):
        for name, c in b.components.items():
            shares[name] = shares.get(name, 0.0) + float(np.sum((c.contribution ** 2)[ok[i]]))
        for why in b.not_estimated:
            key = why.split(":")[0]
            missing[key] = missing.get(key, 0) + 1
    return {k: round(v / total, 4) for k, v in sorted(shares.items())}, missing


def wavelength_term_ratio(run, errors):
    """RMS of the budgets' wavelength_scale term over the RMS of the same term computed from the
    truth's own slope, (∂truth/∂λ) · u(Δλ): above 1 where the reading's noise steepens the slope."""
    sigma = errors["wavelength_shift_sigma"]
    if sigma <= 0:
        return None
    budget = np.array([b.components["wavelength_scale"].contribution for b in run["budgets"]])
    truth = np.gradient(run["t"], run["wl"], axis=1) * sigma
    return round(float(np.sqrt(np.mean(budget ** 2) / np.mean(truth ** 2))), 3)


def summarise(label, run, k, errors):
    """One session's figures (printed as a JSON line) and its (inside, z) over valid pairs."""
    f, u, t, wl = run["f"], run["u"], run["t"], run["wl"]
    ok = np.isfinite(f) & np.isfinite(u) & (u > 0) & np.isfinite(t)
    inside = np.abs(f - t) <= k * u
    band = int(np.argmin(np.abs(wl - 552)))
    z = ((f - t) / u)[ok]
    shares, missing = component_shares(run["budgets"], ok)
    row = {"run": label, "readings": int(f.shape[0]), "pairs": int(ok.sum()),
           "coverage_all_bands": round(float(inside[ok].mean()), 4),
           "coverage_552nm": round(float(inside[:, band][ok[:, band]].mean()), 4),
           "z_rms": round(float(np.sqrt(np.mean(z ** 2))), 3),
           "z_mean": round(float(np.mean(z)), 3), "z_sd": round(float(np.std(z)), 3),
           "median_rel_U": round(float(np.median((k * u / np.abs(f))[ok & (f != 0)])), 4),
           "wavelength_term_vs_truth": wavelength_term_ratio(run, errors),
           "variance_shares": shares, "not_estimated": missing}
    print(json.dumps(row), flush=True)
    return inside[ok], z


def overall(label, inside_runs, z_runs):
    """Coverage over all pairs with two standard errors: the binomial one as if the pairs were
    independent, sqrt(p (1 − p) / n), and the one the sessions allow, sd(session coverage) /
    sqrt(sessions): readings of one session share the white standard, the wavelength shift, the
    references and the stray light, so the session, not the pair, is the unit of luck."""
    inside, z = np.concatenate(inside_runs), np.concatenate(z_runs)
    p, n = float(inside.mean()), int(inside.size)
    per_session = np.array([float(x.mean()) for x in inside_runs])
    se_sessions = (float(np.std(per_session, ddof=1)) / math.sqrt(len(per_session))
                   if len(per_session) > 1 else None)
    row = {"run": label, "sessions": len(inside_runs), "pairs": n,
           "coverage_all_bands": round(p, 4),
           "se_binomial": round(math.sqrt(p * (1 - p) / n), 4),
           "se_sessions": None if se_sessions is None else round(se_sessions, 4),
           "session_coverage_range": [round(float(per_session.min()), 4),
                                      round(float(per_session.max()), 4)],
           "z_rms": round(float(np.sqrt(np.mean(z ** 2))), 3), "z_sd": round(float(np.std(z)), 3),
           "z_mean": round(float(np.mean(z)), 3),
           "within_2sd": round(float(np.mean(np.abs(z) <= 2)), 4)}
    print(json.dumps(row), flush=True)
    return row


def parse_args():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n", maxsplit=1)[0])
    p.add_argument("--materials", nargs="+", default=["paint", "glossy", "clay", "gold",
                                                      "blue-plastic"])
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    p.add_argument("--plan", default=os.path.join(ROOT, "examples", "plans", "demo.json"))
    p.add_argument("--k", type=float, default=2.0)
    p.add_argument("--pose-jitter", type=float, default=ERRORS["pose_jitter"])
    p.add_argument("--sources", nargs="+", choices=SOURCES, default=list(SOURCES),
                   help="error sources switched on, in the simulator and the budget alike (the "
                        "others are 0 in both); the detector's noise is always on")
    p.add_argument("--json", help="write the overall and per-material figures to this file")
    p.add_argument("--expect-coverage", nargs=2, type=float, metavar=("LO", "HI"),
                   help="exit 1 unless the overall coverage lies in [LO, HI] (the ctest's check)")
    p.add_argument("--expect-z-rms", nargs=2, type=float, metavar=("LO", "HI"),
                   help="exit 1 unless the normalised errors' RMS lies in [LO, HI]")
    p.add_argument("--expect-pose-estimated", action="store_true",
                   help="exit 1 if a budget names the pose as a whole not estimated")
    return p.parse_args()


def check(args, results):
    """The failures of the --expect-* checks, as messages."""
    overall_row, failures = results["all"], []
    for key, bounds in (("coverage_all_bands", args.expect_coverage),
                        ("z_rms", args.expect_z_rms)):
        if bounds and not bounds[0] <= overall_row[key] <= bounds[1]:
            failures.append(f"{key} {overall_row[key]} outside [{bounds[0]}, {bounds[1]}]")
    if args.expect_pose_estimated and results["pose_not_estimated"]:
        failures.append(f"{results['pose_not_estimated']} budgets name the pose not estimated")
    return failures


def main():
    args = parse_args()
    errors = {name: (args.pose_jitter if name == "pose_jitter" else value)
              if name in args.sources else 0.0 for name, value in ERRORS.items()}
    sim, daemon = live_rig.binaries()
    if not sim or not daemon:
        print("build brdf-sim and brdfd first (BRDF_BUILD_DIR); skipped", file=sys.stderr)
        sys.exit(77)
    with open(args.plan, encoding="utf-8") as fh:
        plan = json.load(fh)
    print(json.dumps({"errors": errors, "k": args.k, "plan": os.path.basename(args.plan)}))
    results = {"errors": errors, "materials": {}, "pose_not_estimated": 0}
    every_inside, every_z = [], []
    for entry in args.materials:
        material, path = material_file(entry)
        inside_runs, z_runs = [], []
        for seed in args.seeds:
            run = run_session(sim, daemon, path, sim_seed(material, seed), plan, errors)
            inside, z = summarise(f"{material} seed {seed}", run, args.k, errors)
            results["pose_not_estimated"] += sum(
                any(w.startswith("pose:") for w in b.not_estimated) for b in run["budgets"])
            inside_runs.append(inside)
            z_runs.append(z)
        results["materials"][material] = overall(material, inside_runs, z_runs)
        every_inside += inside_runs
        every_z += z_runs
    results["all"] = overall("all", every_inside, every_z)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as fh:
            json.dump(results, fh, indent=1)
    return check(args, results)


if __name__ == "__main__":
    FAILURES = main()
    for failure in FAILURES:
        print("FAILED: " + failure, file=sys.stderr)
    sys.exit(1 if FAILURES else 0)
