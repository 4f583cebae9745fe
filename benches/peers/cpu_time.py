#!/usr/bin/env python3
"""CPU and wall time of a command, for `make bench-peers` (standard library only).

  cpu_time.py run --label NAME --record FILE -- COMMAND ...
      runs COMMAND (its output passes through), then appends one JSON line to FILE:
      label, CPU seconds of the child (user + sys from getrusage(RUSAGE_CHILDREN), all
      its threads included), wall seconds, the load averages before and after, exit code.
      Exits with the command's exit code.
  cpu_time.py compare FILE
      prints the recorded runs side by side and the CPU and wall ratios of the last run
      against the first (numpy / langevin-fem in `make bench-peers`).
"""
import json
import os
import resource
import subprocess
import sys
import time


def run(label, record, command):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    load_before = os.getloadavg()
    wall = time.perf_counter()
    code = subprocess.call(command)
    wall = time.perf_counter() - wall
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    entry = {
        "label": label,
        "cpu_user": after.ru_utime - before.ru_utime,
        "cpu_sys": after.ru_stime - before.ru_stime,
        "wall": wall,
        "load_before": [round(x, 2) for x in load_before],
        "load_after": [round(x, 2) for x in os.getloadavg()],
        "exit_code": code,
        "command": command,
    }
    entry["cpu"] = entry["cpu_user"] + entry["cpu_sys"]
    with open(record, "a") as f:
        f.write(json.dumps(entry) + "\n")
    print(f"[cpu_time] {label}: cpu {entry['cpu']:.1f} s (user {entry['cpu_user']:.1f}, "
          f"sys {entry['cpu_sys']:.1f}), wall {wall:.1f} s, exit {code}", flush=True)
    return code


def compare(record):
    with open(record) as f:
        runs = [json.loads(line) for line in f if line.strip()]
    print(f"{'':14} {'CPU s':>8} {'user':>8} {'sys':>6} {'wall s':>8}  load avg (1/5/15 min) before -> after")
    for r in runs:
        print(f"{r['label']:14} {r['cpu']:>8.1f} {r['cpu_user']:>8.1f} {r['cpu_sys']:>6.1f} "
              f"{r['wall']:>8.1f}  {'/'.join(map(str, r['load_before']))} -> "
              f"{'/'.join(map(str, r['load_after']))}")
    if len(runs) >= 2:
        a, b = runs[0], runs[-1]
        print(f"ratio {b['label']}/{a['label']}: CPU {b['cpu'] / a['cpu']:.2f}, "
              f"wall {b['wall'] / a['wall']:.2f}")
        print(f"cpu_ratio={b['cpu'] / a['cpu']:.3f}")


def main(argv):
    if len(argv) >= 2 and argv[0] == "compare":
        compare(argv[1])
        return 0
    if len(argv) >= 6 and argv[0] == "run" and argv[1] == "--label" and argv[3] == "--record" \
            and argv[5] == "--" and len(argv) > 6:
        return run(argv[2], argv[4], argv[6:])
    sys.stderr.write(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
