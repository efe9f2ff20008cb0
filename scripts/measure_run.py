#!/usr/bin/python3
"""Runs a command and measures it: wall time, exit code, and the peak resident memory of
the command and of every process it starts (Dask's workers, identify's threads are one
process), for scripts/scale_benchmark.sh.

    /usr/bin/python3 scripts/measure_run.py [--interval S] -- COMMAND [ARG...]

Prints one JSON object on stdout: wall_s, exit, processes (how many were seen),
main_peak_mb (the command's own process), worker_peak_mb (the largest peak of any other
process, or null), total_peak_mb (the sum of every process's peak: an upper bound on the
memory all held at once). A process's peak is its VmHWM (/proc/PID/status), read every
--interval seconds while it lives; the command's own peak is also taken from the kernel when
it ends (ru_maxrss: the largest of it and of the children it waited for). The command's
stdout goes to stderr, so that stdout holds only the JSON."""

import argparse
import json
import os
import subprocess
import sys
import time


def children_of(root):
    """The pids of root's descendants, from the parent pids in /proc/*/stat."""
    parent = {}
    for name in os.listdir("/proc"):
        if not name.isdigit():
            continue
        try:
            with open(f"/proc/{name}/stat", encoding="ascii", errors="replace") as stat:
                fields = stat.read().rsplit(")", 1)[1].split()
        except OSError:
            continue  # gone meanwhile
        parent[int(name)] = int(fields[1])
    found, frontier = set(), {root}
    while frontier:
        frontier = {pid for pid, ppid in parent.items() if ppid in frontier} - found
        found |= frontier
    return found


def peak_kb(pid):
    try:
        with open(f"/proc/{pid}/status", encoding="ascii") as status:
            for line in status:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--interval", type=float, default=0.1, help="seconds between samples")
    parser.add_argument("command", nargs=argparse.REMAINDER)
    args = parser.parse_args()
    command = args.command[1:] if args.command[:1] == ["--"] else args.command
    if not command:
        parser.error("no command")
    start = time.monotonic()
    process = subprocess.Popen(command, stdout=sys.stderr)
    peaks = {}
    while True:
        for pid in {process.pid} | children_of(process.pid):
            kb = peak_kb(pid)
            if kb is not None:
                peaks[pid] = max(peaks.get(pid, 0), kb)
        try:
            waited, status, usage = os.wait4(process.pid, os.WNOHANG)
        except ChildProcessError:
            sys.exit("measure_run: lost the command's process")
        if waited:
            break
        time.sleep(args.interval)
    wall = time.monotonic() - start
    code = os.waitstatus_to_exitcode(status)
    process.returncode = code
    main_kb = peaks.pop(process.pid, 0)
    # ru_maxrss covers the children it waited for: the main process's own peak only when no
    # other process was seen to grow larger.
    if not peaks or usage.ru_maxrss > max(peaks.values()):
        main_kb = max(main_kb, usage.ru_maxrss)
    worker_kb = max(peaks.values()) if peaks else None
    print(json.dumps({
        "wall_s": round(wall, 3), "exit": code, "processes": 1 + len(peaks),
        "main_peak_mb": round(main_kb / 1024, 1),
        "worker_peak_mb": None if worker_kb is None else round(worker_kb / 1024, 1),
        "total_peak_mb": round((main_kb + sum(peaks.values())) / 1024, 1)}))


if __name__ == "__main__":
    main()
