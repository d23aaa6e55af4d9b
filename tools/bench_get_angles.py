#!/usr/bin/env python3
"""Benchmark: pymycobot get_angles round trips per second against the virtual robot in real
time, and how many calls failed (returned -1 or anything but six angles in range).

    cargo run --release -- --pty-link /tmp/mycobot &
    .venv/bin/python tools/bench_get_angles.py /tmp/mycobot [--calls 10000]
    .venv/bin/python tools/bench_get_angles.py --tcp 127.0.0.1:9000   # with --tcp 127.0.0.1:9000

Targets: >= 300 round trips/s (the 115200 baud wire allows ~520/s for a 5-byte request and a
17-byte reply) and zero failed calls. Exits non-zero if a target is missed.
"""

import argparse
import statistics
import sys
import time
import warnings

from pymycobot import MyCobot280, MyCobot280Socket

warnings.filterwarnings("ignore", category=DeprecationWarning)  # pymycobot's locale call

LIMITS = [168, 140, 150, 150, 160, 180]
TARGET_RATE = 300.0


def valid(angles):
    return (
        isinstance(angles, list)
        and len(angles) == 6
        and all(isinstance(a, float) and abs(a) <= limit + 1 for a, limit in zip(angles, LIMITS))
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("port", nargs="?", default="/tmp/mycobot", help="serial device or pty link")
    parser.add_argument("--calls", type=int, default=10_000, help="number of get_angles calls")
    parser.add_argument("--tcp", metavar="HOST:PORT", help="use MyCobot280Socket on this address instead")
    args = parser.parse_args()

    if args.tcp:
        host, port = args.tcp.rsplit(":", 1)
        mc = MyCobot280Socket(host, int(port))
    else:
        mc = MyCobot280(args.port)
    failures = []
    latencies_ms = []
    start = time.perf_counter()
    for i in range(args.calls):
        t0 = time.perf_counter()
        angles = mc.get_angles()
        latencies_ms.append((time.perf_counter() - t0) * 1000)
        if not valid(angles):
            failures.append((i, angles))
    elapsed = time.perf_counter() - start
    rate = args.calls / elapsed

    latencies_ms.sort()
    p50 = statistics.median(latencies_ms)
    p99 = latencies_ms[min(len(latencies_ms) - 1, int(len(latencies_ms) * 0.99))]
    print(f"get_angles: {args.calls} calls in {elapsed:.2f} s = {rate:.0f} round trips/s")
    print(f"latency ms: median {p50:.2f}, p99 {p99:.2f}, max {latencies_ms[-1]:.2f}")
    print(f"failed calls: {len(failures)}")
    for i, angles in failures[:10]:
        print(f"  call {i}: {angles!r}")
    ok = rate >= TARGET_RATE and not failures
    print("PASS" if ok else f"FAIL (targets: >= {TARGET_RATE:.0f}/s, 0 failures)")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
