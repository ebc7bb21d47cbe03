#!/usr/bin/env python3
"""All three figures of a session (fig7.png, fig8.png, polar.png) into --out, and the
interpolation behind Figures 7 and 8 printed: the query, its vertices and weights, the spectrum.

    clients/python/examples/make_figures.py --address 127.0.0.1:50051 --token TOKEN \
        --session ID --out DIR

Same as `python3 -m brdf_client.figures ...` with clients/python on PYTHONPATH.
"""

import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))

from brdf_client.figures import __main__ as figures  # noqa: E402  pylint: disable=wrong-import-position

if __name__ == "__main__":
    sys.exit(figures.main())
