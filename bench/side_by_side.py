#!/usr/bin/env python3
"""Two lamina binaries, one command, alternating runs: the medians of each one's `timing:` phases,
wall time, peak RSS and page faults (docs/performance.md). On a noisy 2-core VM only runs made
side by side in one go compare.

  bench/side_by_side.py --runs 5 OLD NEW -- slice /tmp/s1m.stl --step 0.1
  bench/side_by_side.py OLD NEW -- plan /tmp/s1m.stl --out /tmp/sbs

Each run of a plan writes to its own --out (…-a, …-b) so neither reads the other's files.
--old-env / --new-env NAME=VALUE run one side with more in its environment (the same binary
with and without LAMINA_MALLOC_TUNING=0, say). Needs /usr/bin/time (Debian's `time`).
"""
import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time


def run_once(binary, args, tag, env=None):
    args = list(args)
    if "--out" in args:
        i = args.index("--out") + 1
        args[i] = f"{args[i]}-{tag}"
    start = time.monotonic()
    with tempfile.NamedTemporaryFile("r") as usage:
        done = subprocess.run(["/usr/bin/time", "-f", "%M %R", "-o", usage.name, binary] + args,
                              capture_output=True, text=True, env=env)
        wall = time.monotonic() - start
        rss_kib, faults = (int(x) for x in usage.read().split()[-2:])
    if done.returncode not in (0, 1):  # 1: a plan with warnings over the tolerance still plans
        sys.exit(f"{binary} {' '.join(args)} exited {done.returncode}:\n{done.stderr[-2000:]}")
    out = {"wall": wall, "rss_mib": rss_kib / 1024.0, "faults": faults}
    for line in done.stdout.splitlines():
        if line.lstrip().startswith("timing:"):
            for name, value in re.findall(r"(\w[\w ]*?) ([0-9.]+) s", line.split(":", 1)[1]):
                out[name.strip()] = float(value)
    return out


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--runs", type=int, default=3)
    p.add_argument("--old-env", action="append", default=[], metavar="NAME=VALUE",
                   help="run OLD with this in its environment (again for more)")
    p.add_argument("--new-env", action="append", default=[], metavar="NAME=VALUE")
    p.add_argument("old")
    p.add_argument("new")
    p.add_argument("args", nargs=argparse.REMAINDER)
    a = p.parse_args()
    args = a.args[1:] if a.args[:1] == ["--"] else a.args
    def env_with(pairs):
        env = dict(os.environ)
        for pair in pairs:
            name, _, value = pair.partition("=")
            env[name] = value
        return env
    runs = {"old": [], "new": []}
    for _ in range(a.runs):
        runs["old"].append(run_once(a.old, args, "a", env_with(a.old_env)))
        runs["new"].append(run_once(a.new, args, "b", env_with(a.new_env)))
    keys = list(runs["new"][0])
    print(f"{'':12} {'old':>9} {'new':>9}   (median of {a.runs}, alternating)")
    for k in keys:
        med = [statistics.median(r[k] for r in runs[s] if k in r) if any(k in r for r in runs[s]) else float("nan")
               for s in ("old", "new")]
        print(f"{k:12} {med[0]:9.3f} {med[1]:9.3f}")


if __name__ == "__main__":
    main()
