#!/usr/bin/env python3
"""The BRDF at one wavelength (default 550 nm) in the plane of incidence, polar → OUT/polar.png

    clients/python/examples/polar.py --address 127.0.0.1:50051 --token TOKEN --session ID --out DIR

(--help lists the options.) The drawing lives in brdf_client/figures/polar.py.
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from brdf_client.figures import polar  # noqa: E402  pylint: disable=wrong-import-position

if __name__ == "__main__":
    sys.exit(polar.main())
