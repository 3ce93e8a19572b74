#!/usr/bin/python3
"""The continuum's element kernels on 1 and 2 threads (issue 39; bench/results/kernels.md,
"Parallel assembly"): `grip solve --threads N`, best of RUNS by wall time with that run's CPU
seconds, and grip_kernels_bench's per-call wall medians at the reference state (the internal
force with its tangent assembled into the free block, and the force alone: the line search's
residual). Beside every row: the load average and a control, the wall time of two processes
each running a fixed Python loop over that of one: 1.0 means a second core was free, 2.0 that
it was not (then no 2-thread number in that row says anything about the code).

Cases: the strip of schemas/examples/strip-on-cylinder.json as shipped (q9 50 x 2: 900
integration points, below the kernels' threshold, so 2 threads run them serially) and refined
to 150 x 4 (5,400 points; bench/kernels.py), and the rubber o-ring of
schemas/examples/seal-o-ring.json refined to 24 x 12 (q9, axisymmetric Mooney-Rivlin, 2,592
points). Usage:
  bench/parallel_assembly.py --grip build/apps/grip --kernels-bench build/tests/bench/grip_kernels_bench [--runs 5]
Timing is a benchmark, never a test: no pass/fail here.
"""
import argparse
import json
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import kernels  # noqa: E402  (strip_scene, run_grip)


def seal_scene(nr, nt):
    scene = json.loads((ROOT / "schemas/examples/seal-o-ring.json").read_text())
    scene["body"]["mesh"]["half_disc"]["divisions"] = [nr, nt]
    scene["output"] = {"steps": "last"}
    return scene


def load_average():
    return float(Path("/proc/loadavg").read_text().split()[0])


def control_ratio():
    """Wall of two processes running the same CPU loop at once over one alone."""
    loop = ["/usr/bin/python3", "-c", "s = 0\nfor i in range(4_000_000): s += i"]
    start = time.monotonic()
    subprocess.run(loop, check=True)
    one = time.monotonic() - start
    start = time.monotonic()
    pair = [subprocess.Popen(loop) for _ in range(2)]
    for p in pair:
        p.wait()
    return (time.monotonic() - start) / one


def kernels_bench(binary, scene, threads):
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.json"
        path.write_text(json.dumps(scene))
        out = subprocess.run([binary, str(path), "200", "--threads", str(threads), "--no-solve"], capture_output=True,
                             text=True, check=True).stdout
        return json.loads(out.strip().splitlines()[-1])


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", required=True)
    ap.add_argument("--kernels-bench", required=True)
    ap.add_argument("--runs", type=int, default=5)
    args = ap.parse_args()
    cases = [("strip q9 50 x 2", 900, kernels.strip_scene(50, 2)),
             ("strip q9 150 x 4", 5400, kernels.strip_scene(150, 4)),
             ("o-ring q9 24 x 12, rubber", 2592, seal_scene(24, 12))]
    print("| case | points | threads | wall s (best) | cpu s | assembly ms | force only ms | Newton | load | "
          "control 2/1 | UTC |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, points, scene in cases:
        for threads in (1, 2):
            load, control, stamp = load_average(), control_ratio(), time.strftime("%H:%M", time.gmtime())
            solve = min((kernels.run_grip(args.grip, scene, threads) for _ in range(args.runs)),
                        key=lambda r: r["wall"])
            k = kernels_bench(args.kernels_bench, scene, threads)
            print(f"| {label} | {points} | {threads} | {solve['wall']:.2f} | {solve['cpu']:.2f} | "
                  f"{k['assemble_wall_ms']:.3f} | {k['force_wall_ms']:.3f} | "
                  f"{solve['counters']['newton_iterations']} | {load:.1f} | {control:.2f} | {stamp} |", flush=True)
    print(f"\n{time.strftime('%Y-%m-%d', time.gmtime())}; runs {args.runs}; load average (1 min) at each row's start; "
          "assembly and force only: grip_kernels_bench's wall medians of 200 calls")


if __name__ == "__main__":
    main()
