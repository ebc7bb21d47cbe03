#!/usr/bin/env python3
"""Figure 8: the interpolated spectrum (solid) and its vertex spectra (dotted) → OUT/fig8.png

    clients/python/examples/fig8.py --address 127.0.0.1:50051 --token TOKEN --session ID --out DIR

(--help lists the options.) The drawing lives in brdf_client/figures/fig8.py.
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from brdf_client.figures import fig8  # noqa: E402  pylint: disable=wrong-import-position

if __name__ == "__main__":
    sys.exit(fig8.main())
