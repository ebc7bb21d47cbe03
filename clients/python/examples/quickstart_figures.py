#!/usr/bin/env python3
"""The quick start's figures: deploy/quickstart.sh runs this once its demo session is complete.

Writes into --out, from the live session (an analyst token is enough):
  fig7.png   the paper's Figure 7: the readings as points in (α, β, δ) and in (θi, θo, φ), the
             query direction and the tetrahedron of readings that encloses it;
  fig8.png   the paper's Figure 8: the interpolated spectrum at the query with the spectra of the
             readings it blends (and their weights);
  polar.png  the BRDF at one wavelength in the plane of incidence, per incidence angle;
and prints the interpolation behind Figures 7 and 8.

    quickstart_figures.py --address HOST:PORT --token-file FILE --session ID --out DIR \
        [--query THETA_I THETA_O PHI] [any option of make_figures.py]

It is make_figures.py (brdf_client.figures) with the token read from a file, so that the token
never appears on a command line (ps shows command lines to every user).
"""

import argparse
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0], add_help=False)
    p.add_argument("--token-file", required=True,
                   help="file whose first line is the bearer token (analyst or operator)")
    p.add_argument("--out", default=".", help="directory for the PNG files (created)")
    args, rest = p.parse_known_args(argv)
    try:
        with open(args.token_file, encoding="utf-8") as f:
            token = f.readline().strip()
    except OSError as e:
        print(f"quickstart_figures: cannot read the token file {args.token_file}: {e}",
              file=sys.stderr)
        return 2
    os.makedirs(args.out, exist_ok=True)
    # Imported here: the import generates the gRPC stubs on first use (brdf_client/_stubs.py).
    from brdf_client.figures import __main__ as figures  # pylint: disable=import-outside-toplevel
    return figures.main(rest + ["--token", token, "--out", args.out])


if __name__ == "__main__":
    sys.exit(main())
