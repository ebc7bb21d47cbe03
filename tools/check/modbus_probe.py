#!/usr/bin/env python3
"""Independent Modbus TCP probe for the stage (simulated or real AZ-like drives).

Plain Python (socket + struct), sharing no code with brdfd or libmodbus, so it can check the
simulator's Modbus endpoint by hand:

  modbus_probe.py --port 5020                     # status, alarm and position of units 1-4, control unit
  modbus_probe.py --port 5020 --move 2 45         # move unit 2 to 45 deg and wait until in position
  modbus_probe.py --port 5020 --reset 1           # pulse ALM-RST on unit 1
  modbus_probe.py --port 5020 --control-write 20 6 2   # control unit: exception 06 for the next 2

Register map: the default AZ-like profile (docs/stage-modbus.md): 32-bit values high
word first; operation block 0x0058 (type 0x005A, position 0x005C, speed 0x005E, trigger 0x0066);
driver input command 0x007C; status 0x007E; alarm code 0x0080; feedback position 0x00CC.
Exit status: 0 when every request was answered as expected, 1 otherwise.
"""

import argparse
import socket
import struct
import sys
import time

BLOCK_START = 0x0058
TYPE, POSITION, SPEED, TRIGGER = 0x005A, 0x005C, 0x005E, 0x0066
INPUT_COMMAND, STATUS, ALARM_CODE, FEEDBACK = 0x007C, 0x007E, 0x0080, 0x00CC
STATUS_BITS = {5: "READY", 7: "ALM-A", 8: "SYS-BSY", 13: "MOVE", 14: "IN-POS"}
ALM_RST = 1 << 7

CONTROL_NAMES = {
    0: "mounted_target", 1: "power_cycle_meter",
    10: "serial.silent", 11: "serial.garbage_next", 12: "serial.truncate_next",
    13: "serial.quality_code", 14: "serial.quality_count", 15: "serial.vanish_ms(hi)",
    16: "serial.vanish_ms(lo)",
    20: "modbus.exception_code", 21: "modbus.exception_count", 22: "modbus.late_reply_ms",
    23: "modbus.late_count", 24: "modbus.drop_connection", 25: "modbus.alarm_mid_move",
    26: "modbus.stall",
}
EXCEPTIONS = {1: "illegal function", 2: "illegal data address", 3: "illegal data value",
              4: "device failure", 6: "device busy", 0x0B: "gateway target failed to respond"}


class ModbusError(Exception):
    pass


class Client:
    """One Modbus TCP connection; checks the MBAP of every reply against its request."""

    def __init__(self, host, port, timeout):
        self.sock = socket.create_connection((host, port), timeout=timeout)
        self.sock.settimeout(timeout)
        self.tid = 0

    def close(self):
        self.sock.close()

    def _recv_exact(self, n):
        data = b""
        while len(data) < n:
            chunk = self.sock.recv(n - len(data))
            if not chunk:
                raise ModbusError("connection closed by the server")
            data += chunk
        return data

    def request(self, unit, pdu):
        self.tid = (self.tid + 1) & 0xFFFF
        self.sock.sendall(struct.pack(">HHHB", self.tid, 0, len(pdu) + 1, unit) + pdu)
        tid, proto, length, runit = struct.unpack(">HHHB", self._recv_exact(7))
        body = self._recv_exact(length - 1)
        if tid != self.tid or proto != 0 or runit != unit:
            raise ModbusError(f"reply does not match the request: tid {tid} (sent {self.tid}), "
                              f"protocol {proto}, unit {runit} (sent {unit})")
        if body[0] & 0x80:
            code = body[1]
            raise ModbusError(f"unit {unit}: exception {code:02X} "
                              f"({EXCEPTIONS.get(code, 'unknown')})")
        if body[0] != pdu[0]:
            raise ModbusError(f"unit {unit}: function {body[0]:#x} in reply to {pdu[0]:#x}")
        return body

    def read(self, unit, address, count):
        body = self.request(unit, struct.pack(">BHH", 0x03, address, count))
        if body[1] != 2 * count or len(body) != 2 + 2 * count:
            raise ModbusError(f"unit {unit}: {body[1]} data bytes for {count} registers")
        return list(struct.unpack(f">{count}H", body[2:]))

    def write(self, unit, address, values):
        pdu = struct.pack(f">BHHB{len(values)}H", 0x10, address, len(values), 2 * len(values),
                          *values)
        body = self.request(unit, pdu)
        if struct.unpack(">HH", body[1:5]) != (address, len(values)):
            raise ModbusError(f"unit {unit}: write echo does not match")


def int32(high, low):
    return struct.unpack(">i", struct.pack(">HH", high, low))[0]


def words(value):
    return list(struct.unpack(">HH", struct.pack(">i", value)))


def describe_status(word):
    names = [name for bit, name in STATUS_BITS.items() if word & (1 << bit)]
    return f"0x{word:08X} [{' '.join(names) or '-'}]"


def show_unit(client, unit, cpd):
    status_alarm = client.read(unit, STATUS, 4)
    status = int32(status_alarm[0], status_alarm[1]) & 0xFFFFFFFF
    alarm = int32(status_alarm[2], status_alarm[3])
    fb = client.read(unit, FEEDBACK, 2)
    counts = int32(*fb)
    print(f"unit {unit}: status {describe_status(status)} alarm 0x{alarm:02X} "
          f"position {counts} counts = {counts / cpd:.3f} deg")
    return status, alarm, counts


def show_control(client, unit):
    regs = client.read(unit, 0, 27)
    shown = ", ".join(f"{name}={regs[a]}" for a, name in CONTROL_NAMES.items())
    print(f"control unit {unit}: {shown}")


def move(client, unit, deg, speed_deg_s, cpd, timeout_s):
    target = round(deg * cpd)
    block = [0] * 16  # 0x0058..0x0067: data no., type, position, speed, rates, current, trigger
    for address, value in ((TYPE, 1), (POSITION, target), (SPEED, round(speed_deg_s * cpd)),
                           (0x0060, 1_000_000), (0x0062, 1_000_000), (0x0064, 1000),
                           (TRIGGER, 1)):
        block[address - BLOCK_START:address - BLOCK_START + 2] = words(value)
    start = time.monotonic()
    client.write(unit, BLOCK_START, block)
    print(f"unit {unit}: move to {deg} deg ({target} counts) at {speed_deg_s} deg/s started")
    saw_move = False
    while time.monotonic() - start < timeout_s:
        status, alarm, counts = show_unit(client, unit, cpd)
        saw_move |= bool(status & (1 << 13))
        if status & (1 << 7):
            raise ModbusError(f"unit {unit}: alarm 0x{alarm:02X} during the move")
        if not status & (1 << 13) and status & (1 << 14) and counts == target:
            print(f"unit {unit}: in position after {time.monotonic() - start:.2f} s "
                  f"(MOVE seen: {saw_move})")
            return
        time.sleep(0.1)
    raise ModbusError(f"unit {unit}: not in position within {timeout_s} s")


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--host", default="127.0.0.1")
    ap.add_argument("--port", type=int, default=502)
    ap.add_argument("--units", default="1,2,3,4", help="axis unit ids to read")
    ap.add_argument("--control", type=int, default=100, help="control unit id")
    ap.add_argument("--no-control-status", action="store_true",
                    help="do not print the control unit's registers")
    ap.add_argument("--counts-per-degree", type=float, default=10000 / 360)
    ap.add_argument("--timeout", type=float, default=1.0, help="reply timeout, s")
    ap.add_argument("--move", nargs=2, metavar=("UNIT", "DEG"))
    ap.add_argument("--speed", type=float, default=30.0, help="move speed, deg/s")
    ap.add_argument("--move-timeout", type=float, default=30.0)
    ap.add_argument("--reset", type=int, metavar="UNIT", help="pulse ALM-RST")
    ap.add_argument("--control-write", nargs="+", type=int, metavar="ADDR VALUE",
                    help="write VALUE... to the control unit starting at ADDR")
    args = ap.parse_args()

    try:
        client = Client(args.host, args.port, args.timeout)
    except OSError as e:
        print(f"cannot connect to {args.host}:{args.port}: {e}", file=sys.stderr)
        return 1
    ok = True
    try:
        if args.control_write:
            client.write(args.control, args.control_write[0], args.control_write[1:])
            print(f"control unit {args.control}: wrote {args.control_write[1:]} "
                  f"at {args.control_write[0]}")
        if args.reset is not None:
            client.write(args.reset, INPUT_COMMAND, words(ALM_RST))
            client.write(args.reset, INPUT_COMMAND, words(0))
            print(f"unit {args.reset}: ALM-RST pulsed")
        for unit in (int(u) for u in args.units.split(",") if u):
            try:
                show_unit(client, unit, args.counts_per_degree)
            except (ModbusError, OSError) as e:
                ok = False
                print(f"unit {unit}: {e}")
        if not args.no_control_status:
            show_control(client, args.control)
        if args.move:
            move(client, int(args.move[0]), float(args.move[1]), args.speed,
                 args.counts_per_degree, args.move_timeout)
    except (ModbusError, OSError) as e:
        print(f"error: {e}", file=sys.stderr)
        ok = False
    finally:
        client.close()
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
