#!/usr/bin/env python3
"""Time outside the solver (issue 14): the wall time of the whole `grip solve` process against
the solver's own "total" line, on the refined Hertz scenes of bench/scaling.py (a/h 40 and 20,
friction 0 and 0.3, 10 steps, the scene's default output: every field of every step).

Prints a markdown table, one row per run, the runs of the cases interleaved: the load average
(1 min) before the run, process wall, solver, outside / solver, and the process's CPU (user,
system), minor page faults and context switches (voluntary + involuntary), which the load of
other work inflates least. With two binaries (--before), their runs alternate.
Usage: bench/around_the_solver.py [--grip build/apps/grip] [--before OTHER_GRIP] [--runs 3]
Timing is a benchmark, never a test: no pass/fail here.
"""
import argparse
import json
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from scaling import block_scene, hertz_scene  # noqa: E402

# Hertz at the two refinements (every field of every step written), and the flat under a
# block with 2000 contact nodes (10 and 40 element rows; 2000 divisions are the reader's most), friction 0.3 (the last step written).
CASES = [("a/h 40, mu 0.0", lambda: hertz_scene(40, 0.0)), ("a/h 40, mu 0.3", lambda: hertz_scene(40, 0.3)),
         ("a/h 20, mu 0.0", lambda: hertz_scene(20, 0.0)), ("a/h 20, mu 0.3", lambda: hertz_scene(20, 0.3)),
         ("flat, 2000 contact nodes", lambda: block_scene(2000, 10)),
         ("flat, 2001 contact nodes, 40 rows", lambda: block_scene(2001, 40))]


def run(grip, scene_path, out_path):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    proc = subprocess.run([grip, "solve", scene_path, "--out", out_path], capture_output=True, text=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(proc.stderr[-500:])
    solver = float(re.search(r"total: .* ([0-9.]+) s", proc.stdout).group(1))
    return {"wall": wall, "solver": solver, "user": after.ru_utime - before.ru_utime,
            "sys": after.ru_stime - before.ru_stime, "minflt": after.ru_minflt - before.ru_minflt,
            "csw": (after.ru_nvcsw - before.ru_nvcsw, after.ru_nivcsw - before.ru_nivcsw)}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", default="build/apps/grip")
    ap.add_argument("--before", help="a second grip binary, run alternately with --grip")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    binaries = [("before", args.before), ("after", args.grip)] if args.before else [("", args.grip)]
    print("| case | binary | load | process wall s | solver s | outside / solver | user s | sys s | minor faults | context switches |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    with tempfile.TemporaryDirectory() as tmp:
        for _ in range(args.runs):
            for number, (label, make) in enumerate(CASES):
                scene = Path(tmp) / f"case_{number}.json"
                scene.write_text(json.dumps(make()))
                for name, grip in binaries:
                    load = os.getloadavg()[0]
                    r = run(grip, str(scene), str(Path(tmp) / "out.json"))
                    outside = (r["wall"] - r["solver"]) / r["solver"]
                    print(f"| {label} | {name or grip} | {load:.1f} | {r['wall']:.3f} | {r['solver']:.3f} | "
                          f"{100 * outside:.1f} % | {r['user']:.2f} | {r['sys']:.2f} | {r['minflt']} | "
                          f"{r['csw'][0]} + {r['csw'][1]} |", flush=True)


if __name__ == "__main__":
    main()
