#!/usr/bin/python3
"""The finite-strain kernels' benchmark (issue 39; bench/results/kernels.md): grip before and
after a change, and GetFEM, in the same run.

- strip: schemas/examples/strip-on-cylinder.json as shipped (q9 50 x 2) and refined to q9
  150 x 4 (5418 dofs), against GetFEM's large-sliding contact with a rigid obstacle on Q2
  elements of the same mesh (bench/peers/getfem_strip.py);
- hertz a/h 40 mu 0.3 and the flat with 2000 contact nodes of bench/scaling.py (the scenes of
  bench/results/scaling.md), which must be no slower.

Each case runs RUNS times per program (one thread, or --threads N: grip solve's default is the
machine's cores, which its element kernels, G's sums and a large factorization's rows use); the
table keeps the best run by CPU seconds (user + system of the whole process: what the load of
other work inflates least) and shows its wall seconds too, and the medians over all runs. With --kernels-bench, grip_kernels_bench gives the CPU time of one
numeric factorization of the strip's stiffness and of one assembly, beside the CPU time per
Newton iteration: of the whole solve, and of Newton's own work (the CPU time inside its solves,
without the contact loop's compliance between them). Usage:
  bench/kernels.py --grip NEW [--before OLD] [--runs 3] [--threads 1] [--getfem] [--kernels-bench BIN]
Timing is a benchmark, never a test: no pass/fail here.
"""
import argparse
import copy
import json
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "bench"))
import scaling  # noqa: E402  (hertz_scene, block_scene: the scaling benchmark's scenes)


def strip_scene(nx, ny):
    scene = json.loads((ROOT / "schemas/examples/strip-on-cylinder.json").read_text())
    scene["body"]["mesh"]["rectangle"]["divisions"] = [nx, ny]
    scene["output"] = {"steps": "last"}
    return scene


def run_grip(grip, scene, threads=1):
    """CPU and wall seconds of the whole process, and the result's counters."""
    with tempfile.TemporaryDirectory() as tmp:
        path, out, times = Path(tmp) / "scene.json", Path(tmp) / "out.json", Path(tmp) / "times"
        path.write_text(json.dumps(scene))
        proc = subprocess.run(["/usr/bin/time", "-f", "%e %U %S", "-o", str(times), grip, "solve", str(path),
                               "--out", str(out), "--threads", str(threads)], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr[-500:])
        wall, user, system = (float(x) for x in times.read_text().split()[-3:])
        result = json.loads(out.read_text())
        tip = None
        last = result["steps"][-1]
        for n in last.get("nodes", []):
            if abs(n["x"] - n["ux"] - 1) < 1e-9 and abs(n["y"] - n["uy"]) < 1e-9:
                tip = [n["ux"], n["uy"]]
        return {"cpu": user + system, "wall": wall, "counters": result["effects"]["counters"],
                "steps": len(result["steps"]), "tip": tip}


def run_getfem(nx, ny):
    proc = subprocess.run(["/usr/bin/time", "-f", "%e %U %S", "/usr/bin/python3",
                           str(ROOT / "bench/peers/getfem_strip.py"), str(nx), str(ny)],
                          capture_output=True, text=True)
    wall, user, system = (float(x) for x in proc.stderr.strip().splitlines()[-1].split())
    line = json.loads(proc.stdout.strip().splitlines()[-1])
    return {"cpu": user + system, "wall": wall, "line": line}


def best(runs):
    """The run with the least CPU, with the medians of all runs' CPU and wall seconds beside it."""
    r = dict(min(runs, key=lambda r: r["cpu"]))
    r["cpu_median"] = statistics.median(x["cpu"] for x in runs)
    r["wall_median"] = statistics.median(x["wall"] for x in runs)
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", required=True)
    ap.add_argument("--before")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--getfem", action="store_true")
    ap.add_argument("--kernels-bench")
    args = ap.parse_args()
    cases = [("strip q9 50 x 2", strip_scene(50, 2)), ("strip q9 150 x 4", strip_scene(150, 4)),
             ("hertz a/h 40 mu 0.3", scaling.hertz_scene(40, 0.3)),
             ("flat 2000 contact nodes", scaling.block_scene(2000, 10))]
    programs = [("after", args.grip)] + ([("before", args.before)] if args.before else [])
    print("| case | program | cpu s (best) | wall s | median cpu / wall s | real solves | Newton | steps | "
          "factorizations (Newton + body + dissected) | per Newton iteration | tip (ux, uy) |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for label, scene in cases:
        for name, grip in programs:
            r = best([run_grip(grip, copy.deepcopy(scene), args.threads) for _ in range(args.runs)])
            c = r["counters"]
            split = (f"{c['factorizations']} ({c['newton_factorizations']} + {c['body_factorizations']} + "
                     f"{c['dissected_factorizations']})" if "newton_factorizations" in c else f"{c['factorizations']}")
            per = f"{c['factorizations_per_newton_iteration']:.3f}" if "newton_factorizations" in c else \
                f"{c['factorizations'] / max(1, c['newton_iterations']):.3f} (counted)"
            tip = f"{r['tip'][0]:.5f}, {r['tip'][1]:.5f}" if r["tip"] else ""
            print(f"| {label} | grip {name} | {r['cpu']:.2f} | {r['wall']:.2f} | "
                  f"{r['cpu_median']:.2f} / {r['wall_median']:.2f} | {c['equilibrium_solves']} | "
                  f"{c['newton_iterations']} | {r['steps']} | {split} | {per} | {tip} |", flush=True)
        if args.getfem and label.startswith("strip"):
            nx, ny = scene["body"]["mesh"]["rectangle"]["divisions"]
            g = best([run_getfem(nx, ny) for _ in range(args.runs)])
            line = g["line"]
            print(f"| {label} | GetFEM Q2 large sliding | {g['cpu']:.2f} | {g['wall']:.2f} | "
                  f"{g['cpu_median']:.2f} / {g['wall_median']:.2f} | | "
                  f"{line['newton_iterations']} | 20 | | | {line['tip'][0]:.5f}, {line['tip'][1]:.5f} |", flush=True)
    if args.kernels_bench:
        for nx, ny in ((50, 2), (150, 4)):
            with tempfile.TemporaryDirectory() as tmp:
                path = Path(tmp) / "scene.json"
                path.write_text(json.dumps(strip_scene(nx, ny)))
                runs = []
                for _ in range(args.runs):
                    out = subprocess.run([args.kernels_bench, str(path)], capture_output=True, text=True).stdout
                    runs.append(json.loads(out.strip().splitlines()[-1]))
                k = min(runs, key=lambda r: r["solve_cpu_s"])
                f = k["factorize_ms"]
                print(f"\nstrip q9 {nx} x {ny}: {json.dumps(k)}\n"
                      f"  over one numeric factorization ({f:.2f} ms): the whole solve per Newton iteration "
                      f"{k['ms_per_newton_iteration'] / f:.2f} x; Newton's own work per iteration "
                      f"{k['newton_own_ms_per_iteration'] / f:.2f} x; the compliance's forms "
                      f"{100 * k['compliance_cpu_s'] / k['solve_cpu_s']:.0f} % of the solve")


if __name__ == "__main__":
    main()
