#!/usr/bin/env python3
"""Resident memory of a command over time, to see which phase makes the peak.

Usage: scripts/rss_timeline.py [--every SECONDS] -- CMD ARGS...
Samples /proc/PID/status (VmRSS) of the command every SECONDS (default
0.1) and prints "seconds MB" lines, then the peak (VmHWM) and when it was
first reached. Children (mpirun's processes) are not followed.
"""
import subprocess
import sys
import time


def rss_kb(pid, field):
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except OSError:
        return None
    return None


def main():
    args = sys.argv[1:]
    every = 0.1
    if args[:1] == ["--every"]:
        every = float(args[1])
        args = args[2:]
    if args[:1] == ["--"]:
        args = args[1:]
    if not args:
        sys.exit(__doc__)
    start = time.monotonic()
    proc = subprocess.Popen(args, stdout=subprocess.DEVNULL)
    peak, peak_at, hwm = 0, 0.0, 0
    while proc.poll() is None:
        now = time.monotonic() - start
        rss = rss_kb(proc.pid, "VmRSS")
        hwm = max(hwm, rss_kb(proc.pid, "VmHWM") or 0)
        if rss is not None:
            print(f"{now:8.2f} {rss / 1024:8.1f}", flush=True)
            if rss > peak:
                peak, peak_at = rss, now
        time.sleep(every)
    print(f"# exit {proc.returncode}, {time.monotonic() - start:.2f} s, peak {max(peak, hwm) / 1024:.1f} MB "
          f"(sampled {peak / 1024:.1f} MB first at {peak_at:.2f} s)")
    sys.exit(proc.returncode)


if __name__ == "__main__":
    main()
