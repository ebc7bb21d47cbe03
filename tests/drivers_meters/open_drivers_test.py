#!/usr/bin/env python3
"""The open drivers labs use (tools/check/open_meter_drivers.py: PsychoPy's PR655 class,
Psychtoolbox's PR670Toolbox, the TU Berlin CS-2000 MATLAB driver, each rendered call for call)
against brdf-sim's PR-670 and CS-2000 as processes: every call they make is answered in the form
they parse. Skipped (exit 77) when brdf-sim is not built."""

import os
import subprocess
import sys
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "tools", "check"))
import open_meter_drivers as drivers  # noqa: E402

BUILD = os.environ.get("BRDF_BUILD_DIR", os.path.join(HERE, "..", "..", "build"))
SIM = os.path.join(BUILD, "tools", "brdf-sim", "brdf-sim")


class Sim:
    """brdf-sim with --meter, fast simulated time, on free ports; its meter's port."""

    def __init__(self, meter, *extra):
        self.proc = subprocess.Popen(
            [SIM, "--meter", meter, "--time-scale", "50", "--modbus-port", "0", "--wake-window",
             "0", "--log-level", "warn", *extra],
            stdout=subprocess.PIPE, text=True)
        self.port = None
        for line in self.proc.stdout:
            key, _, value = line.strip().partition(" ")
            if key == meter:
                self.port = value
            if key == "ready":
                break
        if self.port is None:
            raise RuntimeError("brdf-sim printed no %s line" % meter)

    def stop(self):
        self.proc.terminate()
        self.proc.wait(10)
        self.proc.stdout.close()


class PsychoPyPR655Test(unittest.TestCase):
    def test_every_call_of_the_class_gets_what_it_parses(self):
        sim = Sim("pr670", "--meter-serial", "67000123")
        try:
            pr = drivers.PsychoPyPR655(sim.port)
            self.assertEqual(pr.type, "PR-670")
            self.assertEqual(pr.getDeviceSN(), "67000123")
            pr.measure()
            self.assertGreater(pr.lastLum, 0)
            self.assertTrue(0 < pr.lastXY[0] < 1 and 0 < pr.lastXY[1] < 1)
            self.assertTrue(0 < pr.lastUV[0] < 1 and 0 < pr.lastUV[1] < 1)
            self.assertAlmostEqual(pr.lastTristim[1], pr.lastLum, delta=pr.lastLum * 1e-3)
            self.assertTrue(2000 < pr.lastColorTemp < 4000)  # a tungsten lamp
            nm, power = pr.lastSpectrum
            # The class skips the report's first two lines, as it does for the PR-650's D5: on
            # the PR-670's report (one header line) that drops the 380 nm band.
            self.assertEqual(len(nm), 200)
            self.assertEqual(nm[0], 382.0)
            self.assertEqual(nm[-1], 780.0)
            self.assertTrue(all(p > 0 for p in power))
            pr.close()
        finally:
            sim.stop()


class PtbPR670Test(unittest.TestCase):
    def test_init_serial_sync_and_a_spectrum_of_201_bands(self):
        sim = Sim("pr670")
        try:
            pr = drivers.PtbPR670(sim.port)
            self.assertTrue(pr.init_reply)  # PR670init waits for any answer to PHOTO
            self.assertEqual(pr.getserialnumber(), "67012345")
            freq, code = pr.getsyncfreq()
            self.assertEqual(code, 0)
            self.assertEqual(freq, 100.0)
            spd, qual = pr.measspd("on")
            self.assertEqual(qual, 0)
            self.assertEqual(len(spd), 201)
            self.assertTrue(all(v > 0 for v in spd))
            pr.close()
        finally:
            sim.stop()

    def test_too_dark_gives_zeros_and_a_sync_failure_is_measured_again(self):
        sim = Sim("pr670", "--serial-quality-code", "-8")
        try:
            pr = drivers.PtbPR670(sim.port)
            spd, qual = pr.measspd()
            self.assertEqual(qual, -8)
            self.assertEqual(spd, [0.0] * 201)
            pr.close()
        finally:
            sim.stop()
        sim = Sim("pr670", "--serial-quality-code", "-10")
        try:
            pr = drivers.PtbPR670(sim.port)
            spd, qual = pr.measspd()
            self.assertEqual(qual, 0)  # SS0, then the second measurement
            self.assertEqual(len(spd), 201)
            pr.close()
        finally:
            sim.stop()


class MatlabCS2000Test(unittest.TestCase):
    def test_connect_measure_and_read_401_values_and_the_colorimetry(self):
        sim = Sim("cs2000")
        try:
            cs = drivers.MatlabCS2000(sim.port)
            self.assertEqual(cs.message, "connected")
            spectral, colorimetric = cs.measure()
            self.assertEqual(cs.message1, "Measurement has been completed.")
            self.assertGreaterEqual(cs.pre_meas_time, 1)
            self.assertEqual(len(spectral), 401)
            self.assertTrue(all(v > 0 for v in spectral))
            self.assertEqual(len(colorimetric), 24)
            self.assertGreater(colorimetric[1], 0)  # Lv
            self.assertAlmostEqual(colorimetric[1], colorimetric[3], delta=1e-6 * colorimetric[1])
            cs.close()
        finally:
            sim.stop()

    def test_an_error_code_is_reported_in_the_drivers_words(self):
        sim = Sim("cs2000", "--serial-quality-code", "10")
        try:
            cs = drivers.MatlabCS2000(sim.port)
            spectral, colorimetric = cs.measure()
            self.assertEqual(cs.message1, "Over measurement range.")
            self.assertEqual(spectral, "No data.")  # ER20 for each block
            self.assertIsNone(colorimetric)
            cs.close()
        finally:
            sim.stop()


if __name__ == "__main__":
    if not os.access(SIM, os.X_OK):
        print("brdf-sim is not built (%s): skipped" % SIM)
        sys.exit(77)
    unittest.main()
