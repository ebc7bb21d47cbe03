"""brdf_client (clients/python) against brdf-archive, unchanged: what it reads of a session through
the archive is what it reads through the session's rig.

Run by archive_server_tests (ArchiveServerTest.PythonClientReadsTheArchiveAsTheRig), which starts
PostgreSQL, brdf-sim, brdfd and brdf-archive and records the session:

  python3 python_client_check.py --rig ADDR --archive ADDR --token T --rig-session ID \
      --archive-session ID --uuid UUID --material M --workdir DIR

Checks, each failing with a message that names what differed: the catalogue filter finds the
session by material (any case) and by rig; interpolate and interpolate_batch give the same
statuses and the same spectra, to the bit; load_readings gives the same readings; the readings CSV
and RGL exports are the same bytes (the CSV but for its first line, which names the server's
session id). Prints one line per check; exit 0 when all hold.
"""

import argparse
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "clients", "python"))

from brdf_client import BrdfClient  # noqa: E402  pylint: disable=wrong-import-position


def fail(what):
    print(f"python client through brdf-archive: {what}", file=sys.stderr)
    sys.exit(1)


def main():
    ap = argparse.ArgumentParser()
    for flag in ("--rig", "--archive", "--token", "--rig-session", "--archive-session", "--uuid",
                 "--material", "--workdir"):
        ap.add_argument(flag, required=True)
    a = ap.parse_args()
    rig = BrdfClient(a.rig, a.token)
    archive = BrdfClient(a.archive, a.token)

    found = [s.uuid for s in archive.list_sessions(material=a.material.upper())]
    if a.uuid not in found:
        fail(f"list_sessions(material={a.material.upper()!r}) did not find {a.uuid}: {found}")
    rig_name = rig.get_session(a.rig_session).rig
    if a.uuid not in [s.uuid for s in archive.list_sessions(rig=rig_name)]:
        fail(f"list_sessions(rig={rig_name!r}) did not find {a.uuid}")
    if archive.list_sessions(rig=rig_name + "-nowhere"):
        fail("list_sessions with a rig nobody has answered sessions")
    print(f"list_sessions: found by material and by rig {rig_name!r}")

    directions = [(15, 31, 170), (30, 40, 160), (20, 20, 170), (45, 30, 120), (10, 60, 90)]
    answered = 0
    for d in directions:
        for method, quantity in (("octant", "brdf"), ("nearest", "brdf"), ("octant", "radiance"),
                                 ("delaunay", "reflectance")):
            r = rig.interpolate(a.rig_session, *d, method=method, quantity=quantity)
            x = archive.interpolate(a.archive_session, *d, method=method, quantity=quantity)
            if r.status != x.status or not np.array_equal(r.spectrum, x.spectrum):
                fail(f"interpolate {d} {method} {quantity}: rig {r.status} vs archive "
                     f"{x.status}, or other spectra")
            answered += r.ok
    if answered == 0:
        fail("no direction was answered: the comparison says nothing")
    rb = rig.interpolate_batch(a.rig_session, directions, method="nearest")
    xb = archive.interpolate_batch(a.archive_session, directions, method="nearest")
    if list(rb.statuses) != list(xb.statuses) or not np.array_equal(rb.spectra, xb.spectra,
                                                                     equal_nan=True):
        fail("interpolate_batch differs")
    print(f"interpolate, interpolate_batch: {len(directions)} directions × 4 methods/quantities, "
          f"{answered} answered, same bits")

    rr = rig.load_readings(a.rig_session)
    xr = archive.load_readings(a.archive_session)
    if len(rr) == 0 or len(rr) != len(xr) or not np.array_equal(rr.ids, xr.ids):
        fail(f"load_readings: {len(rr)} readings on the rig, {len(xr)} in the archive")
    print(f"load_readings: {len(rr)} readings, same ids")

    for fmt, extra in (("csv", {}), ("rgl", {"rgl_theta_i_count": 4, "rgl_resolution": 8})):
        files = []
        for name, client, session in (("rig", rig, a.rig_session),
                                      ("archive", archive, a.archive_session)):
            path = os.path.join(a.workdir, f"{name}.{fmt}")
            client.export(session, fmt, path, **extra)
            with open(path, "rb") as f:
                data = f.read()
            files.append(data.split(b"\n", 1)[1] if fmt == "csv" else data)
        if not files[0] or files[0] != files[1]:
            fail(f"export {fmt}: {len(files[0])} bytes from the rig, {len(files[1])} from the "
                 "archive, not the same")
        print(f"export {fmt}: {len(files[0])} bytes, the same")


if __name__ == "__main__":
    main()
