"""Runs clients/python/README.md's ```python blocks in order, in one namespace, as a user pastes
them into the interpreter this runs in (the venv of the install), and writes what the test checks
to a JSON file. Not a test by itself: test_readme_examples.py starts it.

    VENV/bin/python readme_harness.py README.md OUT.json        (cwd: the repository's root)
"""

import contextlib
import io
import json
import re
import sys

import numpy as np


def python_blocks(path):
    with open(path, encoding="utf-8") as f:
        return re.findall(r"```python\n(.*?)```", f.read(), re.S)


def after_first(ns, printed):
    r, b = ns["r"], ns["b"]
    return {"state": ns["names"].state_name(ns["final"].state), "acted": "operator:" in printed,
            "r_status": r.status, "r_shape": list(r.spectrum.shape),
            "r_vertices": len(r.vertex_ids), "b_shape": list(b.spectra.shape)}


def after_labelled(ns):
    import brdf_client  # pylint: disable=import-outside-toplevel
    df, f, grid, same = ns["df"], ns["f"], ns["grid"], ns["same"]
    raw = np.load("run/analysis/grid.npy")
    with open("run/analysis/grid.npy.json", encoding="utf-8") as side_file:
        side = json.load(side_file)
    counts = {k: int((grid.provenance == c).sum()) for c, k in enumerate(
        ("interpolated", "fallback", "model", "empty"))}
    return {
        "module_file": brdf_client.__file__, "rows": len(df), "kinds": sorted(set(df.kind)),
        "f_dims": list(f.dims), "grid_dims": list(grid.brdf.dims),
        "grid_equals_npy": bool(np.array_equal(grid.brdf.values, raw, equal_nan=True)),
        "same_equals_npy": bool(np.array_equal(same.brdf.values, raw, equal_nan=True)),
        "provenance_counts": counts,
        "sidecar_fill": {k: side["fill"][k] for k in counts},
        "grid_unit": grid.brdf.attrs["units"], "sidecar_unit": side["unit"],
        "r_dims": list(ns["r"].brdf.dims), "b_dims": list(ns["b"].brdf.dims),
        "hd_dims": list(ns["hd"].brdf.dims),
    }


def main(readme, out_path):
    blocks = python_blocks(readme)
    ns = {"__name__": "readme_example"}
    results = {}
    for k, (code, summary) in enumerate(((blocks[0], after_first), (blocks[1], after_labelled))):
        out = io.StringIO()
        with contextlib.redirect_stdout(out):
            exec(compile(code, f"README.md block {k + 1}", "exec"), ns)  # pylint: disable=exec-used
        print(out.getvalue()[-2000:], file=sys.stderr)
        results[f"block{k + 1}"] = (summary(ns, out.getvalue()) if summary is after_first
                                    else summary(ns))
    with open(out_path, "w", encoding="utf-8") as f:
        json.dump(results, f)


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
