#!/usr/bin/env python3
"""The open drivers labs use with the PR-655/670 and the CS-2000, rendered call for call in Python
so they can run against brdf-sim's meters (issue 41): neither PsychoPy nor MATLAB is installable
here, and pyserial is not either.

Each class below issues the same commands, in the same order, with the same pauses and reads,
and parses the replies the same way as the driver it is named after; the comments name the
original function each method stands for. The code is written for this file (the originals are
GPL / MIT programs in other languages); what carries over is their sequence of calls and their
parsing rules, which is what a simulated meter has to satisfy.

  PsychoPyPR655   psychopy-photoresearch, pr.py, class PR655 (pyserial)
  PtbPR670        Psychtoolbox-3, PR670Toolbox (IOPort): PR670init, PR670write, PR670read,
                  PR670rawspd, PR670parsespdstr, PR670measspd, PR670getserialnumber,
                  PR670getsyncfreq, PR670setsyncfreq, PR670close
  MatlabCS2000    fglichttechnik/KonicaMinolta-CS2000-MATLAB (MATLAB serial): CS2000_initConnection,
                  CS2000_measure, CS2000_errMessage

SerialPort is the small part of pyserial's Serial those drivers use, over termios.
"""

import os
import re
import select
import termios
import time
import tty


class SerialPort:
    """pyserial's Serial as the drivers use it: timeout (s), read, readline, readlines, write,
    flush, inWaiting, close; 8N1, raw."""

    def __init__(self, path, baudrate=9600, timeout=None):
        self.fd = os.open(path, os.O_RDWR | os.O_NOCTTY)
        tty.setraw(self.fd)
        attrs = termios.tcgetattr(self.fd)
        attrs[4] = attrs[5] = termios.B9600 if baudrate == 9600 else termios.B115200
        termios.tcsetattr(self.fd, termios.TCSANOW, attrs)
        self.baudrate = baudrate
        self.timeout = timeout
        self._pending = b""

    def _fill(self, wait):
        ready, _, _ = select.select([self.fd], [], [], wait)
        if ready:
            self._pending += os.read(self.fd, 65536)
            return True
        return False

    def inWaiting(self):
        while self._fill(0):
            pass
        return len(self._pending)

    def read(self, n=1):
        deadline = None if self.timeout is None else time.monotonic() + self.timeout
        while len(self._pending) < n:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                break
            self._fill(left)
        out, self._pending = self._pending[:n], self._pending[n:]
        return out

    def readline(self):
        deadline = None if self.timeout is None else time.monotonic() + self.timeout
        while b"\n" not in self._pending:
            left = None if deadline is None else deadline - time.monotonic()
            if left is not None and left <= 0:
                out, self._pending = self._pending, b""
                return out
            self._fill(left)
        line, _, self._pending = self._pending.partition(b"\n")
        return line + b"\n"

    def readlines(self):
        # pyserial: lines until a read times out.
        lines = []
        while True:
            line = self.readline()
            if not line:
                return lines
            lines.append(line)
            if not line.endswith(b"\n"):
                return lines

    def write(self, data):
        os.write(self.fd, data)

    def flush(self):
        termios.tcdrain(self.fd)

    def close(self):
        os.close(self.fd)


class PsychoPyPR655:
    """psychopy-photoresearch's PR655: 9600 8N1, a 0.1 s timeout outside measurements."""

    def __init__(self, port):
        self.com = SerialPort(port, 9600)  # __init__: serial.Serial, 9600, N, 1
        self.com.timeout = 0.1
        self.startRemoteMode()
        self.type = self.getDeviceType()

    def sendMessage(self, message, timeout=0.5):
        if message[-1] != "\n":
            message += "\n"  # a newline is appended
        self.com.read(self.com.inWaiting())  # the read buffer is emptied first
        for letter in message:  # one character per write, each flushed
            self.com.write(letter.encode("utf-8"))
            self.com.flush()
        time.sleep(0.1)
        self.com.timeout = timeout
        if message in ("d5\n", "D5\n"):
            return [line.decode("utf-8") for line in self.com.readlines()]
        return self.com.readline().decode("utf-8")

    def startRemoteMode(self):
        return self.sendMessage("PHOTO", timeout=10.0)

    def getDeviceType(self):
        return self.sendMessage("D111").split(",")[-1].replace("\r", "").replace("\n", "")

    def getDeviceSN(self):
        return self.sendMessage("D110").split(",")[-1].replace("\r", "").replace("\n", "")

    def endRemoteMode(self):
        self.com.write(b"Q")

    def getLastTristim(self):
        return self.sendMessage("D2").split(",")

    def getLastUV(self):
        return self.sendMessage("D3").split(",")

    def getLastXY(self):
        return self.sendMessage("D1").split(",")

    def getLastColorTemp(self):
        return self.sendMessage("D4").split(",")

    def getLastSpectrum(self):
        raw = self.sendMessage("D5")
        return self.parseSpectrumOutput(raw[2:])  # the first two lines are skipped

    def measure(self, timeOut=30.0):
        self.sendMessage("M0", timeout=timeOut)
        uv = self.getLastUV()
        xy = self.getLastXY()
        tristim = self.getLastTristim()
        self.lastLum = float(uv[2])
        self.lastUV = [float(uv[3]), float(uv[4])]
        self.lastXY = [float(xy[3]), float(xy[4])]
        self.lastTristim = [float(tristim[2]), float(tristim[3]), float(tristim[4])]
        self.lastSpectrum = self.getLastSpectrum()
        self.lastColorTemp = int(self.getLastColorTemp()[3])

    def parseSpectrumOutput(self, rawStr):
        nm, power = [], []
        for point in rawStr:  # each line "wl,value": exactly two fields
            thisNm, thisPower = point.split(",")
            nm.append(float(thisNm))
            power.append(float(thisPower.replace("\r\n", "")))
        return nm, power

    def close(self):
        self.endRemoteMode()
        time.sleep(0.1)
        self.com.close()


class PtbPR670:
    """Psychtoolbox's PR670Toolbox over IOPort (9600 8N1, no handshake)."""

    def __init__(self, port):  # PR670init
        self.port = SerialPort(port, 9600, timeout=0)
        self.write("Q", append_cr=False)
        time.sleep(0.5)
        self.write("PHOTO", append_cr=False)
        start, self.init_reply = time.monotonic(), ""
        while not self.init_reply and time.monotonic() - start < 10:
            self.init_reply = self.read()

    def write(self, cmd, append_cr=True):  # PR670write: upper case, a character every 50 ms
        if append_cr and cmd[-1] != "\r":
            cmd += "\r"
        for ch in cmd:
            self.port.write(ch.upper().encode())
            time.sleep(0.05)

    def read(self):  # PR670read: what is there, then on until 50 ms bring nothing
        data = self.port.read(self.port.inWaiting()).decode()
        if data:
            more = "x"
            while more:
                time.sleep(0.05)
                more = self.port.read(self.port.inWaiting()).decode()
                data += more
        return data

    def flush(self):
        while self.read():
            pass

    def rawspd(self, timeout):  # PR670rawspd
        self.flush()
        self.write("M5")
        start, reply = time.monotonic(), ""
        while not reply and time.monotonic() - start < timeout:
            reply = self.read()
        if not reply:
            raise RuntimeError("Unable to get reading from radiometer")
        return reply

    @staticmethod
    def parsespdstr(read_str):  # PR670parsespdstr, up to the spline to S (native sampling kept)
        lines = read_str.split("\n")
        lines = [line for line in lines if line != ""][1:]  # textscan %s: the first line tossed
        if len(lines) != 201:
            raise RuntimeError("Unexpected native number of wavelength samples for PR-670")
        wavelengths, spd = [], []
        for line in lines:
            m = re.match(r"\s*([-+]?\d+),\s*([-+0-9.eE]+)", line)
            wavelengths.append(int(m.group(1)))
            spd.append(float(m.group(2)))
        spd = [2 * v for v in spd]  # "convert to our units standard"
        if wavelengths[1] - wavelengths[0] != 2:
            raise RuntimeError("Unexpected native wavelength sampling for PR-670")
        return wavelengths, spd

    def measspd(self, sync_mode="off"):  # PR670measspd (S = native)
        if sync_mode == "on":
            self.setsyncfreq(1 if self.getsyncfreq()[0] is not None else 0)
        else:
            self.setsyncfreq(0)
        read_str = self.rawspd(300)
        qual = float(re.match(r"\s*([-+]?[0-9.]+)", read_str).group(1))
        if qual == 0:
            return self.parsespdstr(read_str)[1], qual
        if qual == -8:
            return [0.0] * 201, qual
        if qual in (-1, -10):
            self.write("SS0")
            read_str = self.rawspd(300)
            qual = float(re.match(r"\s*([-+]?[0-9.]+)", read_str).group(1))
            if qual == -8:
                return [0.0] * 201, qual
            if qual == 0:
                return self.parsespdstr(read_str)[1], qual
        raise RuntimeError("Bad return code %g from meter" % qual)

    def _wait_reply(self, timeout, message):
        waited, in_str = 0, ""
        while not in_str and waited < timeout:
            time.sleep(1 if waited else 0.05)  # PTB polls once a second
            waited += 1
            in_str = self.read()
        if not in_str:
            raise RuntimeError(message)
        reply = in_str
        while in_str:
            in_str = self.read()
            reply += in_str
        return reply

    def getserialnumber(self):  # PR670getserialnumber: '%d,%s', its first 8 characters
        self.flush()
        self.write("D110")
        reply = self._wait_reply(30, "No response from meter")
        return reply.split(",", 1)[1].split()[0][:8]

    def getsyncfreq(self):  # PR670getsyncfreq: sscanf '%f,%f'
        self.flush()
        self.write("F")
        start, reply = time.monotonic(), ""
        while not reply and time.monotonic() - start < 30:
            reply = self.read()
        m = re.match(r"\s*([-+0-9.eE]+),\s*([-+0-9.eE]+)", reply)
        if m:
            return float(m.group(2)), float(m.group(1))
        return None, float(re.match(r"\s*([-+0-9.eE]+)", reply).group(1))

    def setsyncfreq(self, freq):  # PR670setsyncfreq for 0 and 1: SSn, the reply's code must be 0
        self.flush()
        self.write("SS%d" % freq)
        reply = self._wait_reply(30, "No response after SS command")
        if int(re.match(r"\s*([-+]?\d+)", reply).group(1)) != 0:
            raise RuntimeError("PR670setsyncfreq:Received error code")

    def close(self):  # PR670close
        self.write("Q", append_cr=False)
        self.port.close()


ERROR_MESSAGES = {  # CS2000_errMessage
    "ER00": "Invalid command string or number of parameters received.",
    "ER02": "Measurement error.",
    "ER05": "No user calibration values.",
    "ER10": "Over measurement range.",
    "ER17": "Parameter error.",
    "ER20": "No data.",
    "ER51": "CCD Peltier abnormality.",
    "ER52": "Temperatur count abnormality.",
    "ER71": "Outside synchronization signal range.",
    "ER81": "Shutter operation abnormality.",
    "ER82": "Internal ND filter operation malfunction.",
    "ER83": "Measurement angle abnormality.",
    "ER99": "Program abnormality.",
}


def err_message(code):
    """CS2000_errMessage: (1, ' ') for OK00, else (0, the message)."""
    if code.startswith("OK00"):
        return 1, " "
    return 0, ERROR_MESSAGES.get(code[:4], "")


class MatlabCS2000:
    """The TU Berlin MATLAB driver: serial with Terminator LF, a 240 s timeout."""

    def __init__(self, port):  # CS2000_initConnection
        self.s = SerialPort(port, 9600, timeout=240)
        self.fprintf("RMTS,1")
        tf, out = err_message(self.fscanf())
        self.message = "connected" if tf == 1 else out

    def fprintf(self, text):  # MATLAB fprintf on a serial object: the text, then the terminator
        self.s.write((text + "\n").encode())

    def fscanf(self):  # MATLAB fscanf on a serial object: up to the terminator
        return self.s.readline().decode()

    @staticmethod
    def scan_values(answer, count):
        """After the 4-character check code: `count` times one separator character, then %e."""
        pos, values = 4, []
        for _ in range(count):
            pos += 1
            m = re.compile(r"[-+]?\d*\.?\d+(?:[eE][-+]?\d+)?").match(answer, pos)
            values.append(float(m.group(0)))
            pos = m.end()
        return values

    def measure(self):  # CS2000_measure
        self.fprintf("MEAS,1")
        answer = self.fscanf()
        error_check, pre_meas_time = answer.strip().split(",")[0], answer.strip().split(",")[-1]
        tf, out = err_message(error_check)
        if tf == 1:
            self.pre_meas_time = int(pre_meas_time)
            tf, out = err_message(self.fscanf().strip())
            self.message1 = "Measurement has been completed." if tf == 1 else out
        else:
            self.message1 = out
        spectral, error = [], None
        for n in range(1, 5):
            self.fprintf("MEDR,1,0,%d" % n)
            answer = self.fscanf()
            tf, out = err_message(answer[:4])
            if tf != 1:
                error = out
                continue
            spectral += self.scan_values(answer, 101 if n == 4 else 100)
        self.fprintf("MEDR,2,0,00")
        answer = self.fscanf()
        colorimetric = self.scan_values(answer, 24) if answer.startswith("OK00") else None
        return error or spectral, colorimetric

    def close(self):  # CS2000_terminateConnection: the port closed (no RMTS,0)
        self.s.close()
