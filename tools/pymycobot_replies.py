#!/usr/bin/env python3
"""Feed reply frames to pymycobot's own read path and check what the user's call returns.

Reads lines from stdin: `<method> | <args as JSON list> | <reply frame hex> | <expected JSON>`.
For each, MyCobot280 (unchanged, on a fake serial port that answers every request frame with
the given reply bytes) calls `<method>(*args)`; the result is compared with the expected value
(floats to 1e-6). Prints one line per case, `ok <method>` or `FAIL <method>: got ... want ...`,
then `done <n>`. Used by protocol-core/tests/pymycobot_replies.rs.
"""
import contextlib
import io
import json
import math
import sys
import time

import serial


class ReplySerial:
    """serial.Serial stand-in: every frame written is answered with `self.reply`."""

    def __init__(self, *args, **kwargs):
        self.port = None
        self.baudrate = 115200
        self.timeout = 0.1
        self.rts = False
        self.rx = bytearray()
        self.reply = b""

    def open(self):
        pass

    def close(self):
        pass

    def isOpen(self):
        return True

    def reset_input_buffer(self):
        self.rx.clear()

    def inWaiting(self):
        return len(self.rx)

    def write(self, data):
        data = bytes(data)
        if len(data) >= 5 and data[0] == 0xFE and data[1] == 0xFE:
            self.rx += self.reply
        return len(data)

    def read(self, n=1):
        out = bytes(self.rx[:n])
        del self.rx[:n]
        return out


def same(got, want):
    if isinstance(want, list):
        return isinstance(got, list) and len(got) == len(want) and all(same(g, w) for g, w in zip(got, want))
    if isinstance(want, (int, float)) and isinstance(got, (int, float)):
        return math.isclose(got, want, rel_tol=0, abs_tol=1e-6)
    return got == want


def main():
    serial.Serial = ReplySerial
    time.sleep = lambda s: None
    from pymycobot import MyCobot280

    bot = MyCobot280("/dev/fake")
    port = bot._serial_port
    n = 0
    for line in sys.stdin:
        line = line.strip()
        if not line:
            continue
        method, args, reply_hex, want = [p.strip() for p in line.split("|")]
        port.reply = bytes(int(h, 16) for h in reply_hex.split())
        want = json.loads(want)
        with contextlib.redirect_stdout(io.StringIO()):  # pymycobot prints servo errors
            try:
                got = getattr(bot, method)(*json.loads(args))
            except Exception as e:  # noqa: BLE001 - a crash is a failed case
                got = "exception: {!r}".format(e)
        if isinstance(got, tuple):
            got = list(got)
        n += 1
        if same(got, want):
            print("ok", method)
        else:
            print("FAIL {} {}: got {!r} want {!r}".format(method, args, got, want))
    print("done", n)


if __name__ == "__main__":
    main()
