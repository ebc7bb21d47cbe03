#!/usr/bin/env python3
"""Does a reading's k = 2 interval hold the truth as often as it claims? (issue 37, the simulator
check; docs/uncertainty.md, "Checking it against the simulator").

For each material and seed: brdf-sim with the material and its error sources switched on
(docs/simulator-errors.md), brdfd configured with the matching [uncertainty] terms, a plan run to
completion (the operator's actions done on the simulator's control unit), the stored budgets read
back through brdf_client, and every sample reading's BRDF compared, band by band, with
`brdf-sim truth` at the reading's directions. Prints the fraction of (reading, band) pairs and of
readings (at 552 nm) whose interval f ± k·u_c holds the truth, per run and over all, and the spread
of the normalised errors (f − truth) / u_c. The goal is 95 % ± 2 % at k = 2.

    bench/uncertainty/coverage.py --materials paint glossy clay gold blue-plastic --seeds 1 2 3

Needs a build with brdf-sim, brdfd and the Python stubs (BRDF_BUILD_DIR, default build/).
"""

import argparse
import json
import os
import subprocess
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "tests", "python"))
sys.path.insert(0, os.path.join(ROOT, "clients", "python"))

import live_rig  # noqa: E402  pylint: disable=wrong-import-position
from brdf_client import BrdfClient, names  # noqa: E402  pylint: disable=wrong-import-position

PROMPT_ACTIONS = {"mount_white": "white", "close_shutter": "dark", "mount_sample": "sample"}

# The error sources, as brdf-sim flags, and the budget's matching terms (docs/uncertainty.md's
# last section). white_error is relative; u(ρw) = ρw · white_error. brdf-sim's stray light is a
# fraction of a perfect diffuser's light; as a fraction of the white's signal it is s / ρw at
# normal incidence (the default reference pose).
ERRORS = {"gain_noise": 0.002, "white_error": 0.005, "wavelength_shift_sigma": 1.0,
          "stray_light": 0.0002, "lamp_drift": -0.002, "pose_jitter": 0.0}


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
stray_light = {errors["stray_light"] / 0.99}
stage_repeatability_deg = {errors["pose_jitter"]}
lamp_drift_per_hour = {errors["lamp_drift"]}
meter_gain_repeatability = {errors["gain_noise"]}
"""


def truth(sim, material, d):
    out = subprocess.run([sim, "--material", material, "truth", "--theta-i", repr(d[0]),
                          "--phi-i", repr(d[1]), "--theta-o", repr(d[2]), "--phi-o", repr(d[3]),
                          "--json"], check=True, capture_output=True, text=True).stdout
    return np.array(json.loads(out)["brdf"], dtype=float)


def run_session(sim, daemon, material, seed, plan, errors):
    """The sample readings of one session: (ids, directions, f, u, truth), all (n, m) or (n, 4)."""
    rig = live_rig.LiveRig(sim, daemon, seed=seed, sim_args=sim_flags(material, errors),
                           extra_config=budget_config(errors))
    rig.sample_extra = f"white_reflectance_uncertainty = {0.99 * errors['white_error']}\n"
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
    f = np.array([b.value for b in data.budgets])
    u = np.asarray(data.brdf_uncertainty)
    t = np.array([truth(sim, material, d) for d in data.directions])
    return data.ids, data.directions, f, u, t, data.wavelengths


def summarise(label, f, u, t, wl, k):
    ok = np.isfinite(f) & np.isfinite(u) & (u > 0) & np.isfinite(t)
    inside = np.abs(f - t) <= k * u
    band = int(np.argmin(np.abs(wl - 552)))
    z = ((f - t) / u)[ok]
    row = {"run": label, "readings": int(f.shape[0]),
           "coverage_all_bands": float(inside[ok].mean()),
           "coverage_552nm": float(inside[:, band][ok[:, band]].mean()),
           "z_sd": float(np.std(z)), "z_mean": float(np.mean(z)),
           "median_rel_U": float(np.median((k * u / np.abs(f))[ok & (f != 0)]))}
    print(json.dumps(row), flush=True)
    return inside[ok], z


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--materials", nargs="+", default=["paint", "glossy", "clay", "gold",
                                                      "blue-plastic"])
    p.add_argument("--seeds", nargs="+", type=int, default=[1, 2, 3])
    p.add_argument("--plan", default=os.path.join(ROOT, "examples", "plans", "demo.json"))
    p.add_argument("--k", type=float, default=2.0)
    p.add_argument("--pose-jitter", type=float, default=ERRORS["pose_jitter"])
    args = p.parse_args()
    errors = dict(ERRORS, pose_jitter=args.pose_jitter)
    sim, daemon = live_rig.binaries()
    if not sim or not daemon:
        sys.exit("build brdf-sim and brdfd first (BRDF_BUILD_DIR)")
    with open(args.plan, encoding="utf-8") as fh:
        plan = json.load(fh)
    print(json.dumps({"errors": errors, "k": args.k, "plan": os.path.basename(args.plan)}))
    all_inside, all_z = [], []
    for material in args.materials:
        path = os.path.join(ROOT, "deploy", "materials", material + ".toml")
        for seed in args.seeds:
            _, _, f, u, t, wl = run_session(sim, daemon, path, seed, plan, errors)
            inside, z = summarise(f"{material} seed {seed}", f, u, t, wl, args.k)
            all_inside.append(inside)
            all_z.append(z)
    inside, z = np.concatenate(all_inside), np.concatenate(all_z)
    print(json.dumps({"run": "all", "pairs": int(inside.size),
                      "coverage_all_bands": float(inside.mean()), "z_sd": float(np.std(z))}))


if __name__ == "__main__":
    main()
