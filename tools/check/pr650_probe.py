#!/usr/bin/python3
"""Talk to a PR-650 (or brdf-sim's simulated one) by hand and see the exact bytes it sends.

Opens the port at 9600 8N1, optionally drops RTS (close/reopen) and waits like the driver does to
enter remote mode, then sends each command (LF-terminated by default) and prints every reply line
as a Python bytes literal, so CR, LF and stray bytes are visible.

    tools/check/pr650_probe.py /dev/ttyUSB0
    tools/check/pr650_probe.py /tmp/brdf-sim-pr650-XXXX/pr650 --commands B3 D110 D120
    tools/check/pr650_probe.py /dev/ttyUSB0 --commands b0 --eol cr --no-wake

Remote mode needs the first command within about 5 s of switching the meter on, with the cable's
XFER/CTRLR switch on CTRLR. Exit status: 0 if every command got a reply, 1 if any did not, 2 if
the port could not be opened.

Needs Debian's python3-serial (run with /usr/bin/python3).
"""

import argparse
import sys
import time

try:
    import serial  # python3-serial
except ImportError:  # pragma: no cover - depends on the machine
    sys.exit("pr650_probe: needs pyserial: apt-get install python3-serial, run with /usr/bin/python3")

DEFAULT_COMMANDS = ["B3", "D110", "D120", "S01,,,,,0,01,1", "M0", "D5"]
EOLS = {"lf": b"\n", "cr": b"\r", "crlf": b"\r\n"}


def read_reply(port, first_byte_timeout, quiet_gap):
    """Bytes of one reply: wait for the first byte, then read until quiet_gap passes silently.

    Looks once more at the deadline, so a reply landing in the last moment still counts.
    """
    deadline = time.monotonic() + first_byte_timeout
    data = bytearray()
    last = None
    while True:
        chunk = port.read(port.in_waiting or 1)
        now = time.monotonic()
        if chunk:
            data += chunk
            last = now
            continue
        if data and now - last >= quiet_gap:
            return bytes(data)
        if not data and now >= deadline:
            data += port.read(port.in_waiting)
            if not data:
                return b""
            last = now


def show(reply, full):
    lines = reply.splitlines(keepends=True)
    if not full and len(lines) > 8:
        shown = lines[:5] + [None] + lines[-2:]
    else:
        shown = lines
    for line in shown:
        if line is None:
            print(f"    ... {len(lines) - 7} more lines (--full shows all) ...")
        else:
            print(f"    {line!r}")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("port", help="serial port, e.g. /dev/ttyUSB0 or brdf-sim's pr650 path")
    parser.add_argument("--commands", nargs="+", default=DEFAULT_COMMANDS,
                        help="commands to send in order (default: %(default)s)")
    parser.add_argument("--baud", type=int, default=9600)
    parser.add_argument("--eol", choices=sorted(EOLS), default="lf",
                        help="line end after each command (the meter takes LF or CR)")
    parser.add_argument("--no-wake", action="store_true",
                        help="skip the RTS drop and settle wait (meter already in remote mode)")
    parser.add_argument("--settle", type=float, default=0.5,
                        help="seconds to wait after the RTS drop before the first command")
    parser.add_argument("--short-timeout", type=float, default=3.0,
                        help="seconds to wait for the first byte of a short reply")
    parser.add_argument("--long-timeout", type=float, default=30.0,
                        help="seconds to wait for the reply to M, S and F (a measurement)")
    parser.add_argument("--quiet-gap", type=float, default=0.05,
                        help="silence in seconds that ends a reply")
    parser.add_argument("--pacing", type=float, default=0.1,
                        help="seconds to pause between commands")
    parser.add_argument("--full", action="store_true", help="print every line of long replies")
    args = parser.parse_args()

    try:
        port = serial.Serial(args.port, baudrate=args.baud, bytesize=serial.EIGHTBITS,
                             parity=serial.PARITY_NONE, stopbits=serial.STOPBITS_ONE,
                             timeout=0.01, xonxoff=False, rtscts=False)
    except (serial.SerialException, OSError) as e:
        print(f"pr650_probe: cannot open {args.port}: {e}", file=sys.stderr)
        return 2

    print(f"port {args.port} at {args.baud} baud 8N1")
    if not args.no_wake:
        try:
            port.rts = False
        except (serial.SerialException, OSError) as e:
            print(f"  RTS not supported here ({e}); normal on a pseudo-terminal")
        time.sleep(0.1)
        port.close()
        port.open()
        print(f"  RTS dropped for 0.1 s (close/reopen), waiting {args.settle} s")
        time.sleep(args.settle)

    silent = 0
    for command in args.commands:
        port.reset_input_buffer()
        port.write(command.encode("ascii") + EOLS[args.eol])
        port.flush()
        start = time.monotonic()
        long_reply = command[:1].upper() in ("M", "S", "F")
        timeout = args.long_timeout if long_reply else args.short_timeout
        reply = read_reply(port, timeout, args.quiet_gap)
        took = time.monotonic() - start
        print(f"> {command!r}: {len(reply)} bytes in {took:.3f} s")
        if reply:
            show(reply, args.full)
        else:
            silent += 1
            print(f"    (no reply within {timeout} s)")
        time.sleep(args.pacing)

    port.close()
    if silent:
        print(f"{silent} command(s) got no reply: if all were silent, power-cycle the meter and run "
              "again within 5 s, and check the XFER/CTRLR switch is on CTRLR")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
