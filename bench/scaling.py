#!/usr/bin/env python3
"""Scaling benchmark of `grip solve` (issue 14): whole-process wall time, the solver's own
time (the "total" line) and peak memory, against the number of contact unknowns and against
the number of dofs, on generated scenes:

- hertz: the shipped Hertz half-disc (schemas/examples/hertz.json) with friction 0.3 or 0,
  its diameter held in y and its centre node in x, 10 equal steps, elements of a/h = 10, 20,
  40 near the pole (the table of issue 14);
- flat: an elastic block (width 1, linear, plane strain) pressed onto a rigid flat with
  friction 0.3 by a prescribed top displacement, 4 steps; N contact nodes along its bottom
  (contact unknowns 2N), 10 element rows (dofs grow with N);
- dofs: the same block with 100 contact nodes and a growing height (dofs 1e3 to 2e5).

Writes bench/results/scaling.csv, scaling.md (tables, fitted exponents, machine and load)
and scaling.png. Usage: bench/scaling.py [--grip build/apps/grip] [--quick]
Timing is a benchmark, never a test: no pass/fail here.
"""
import argparse
import copy
import csv
import json
import math
import os
import platform
import re
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LIMIT_S = 400  # a run longer than this ends its sweep
RESULTS = ROOT / "bench" / "results"


def fewest_half_disc_divisions(radius, size, extent, growth=1.4):
    """The fewest [2 (fine + coarse), fine + coarse] the half-disc generator accepts: coarse
    elements growing at most `growth`-fold from the fine size, along the arc (half-length
    pi R / 2) and down the axis (R) (solver/elements/half_disc_mesh.cpp, graded_divisions)."""
    fine = round(extent / size)
    h = extent / fine
    needed = lambda rest: max(1, math.ceil(math.log(1 + rest * (growth - 1) / (h * growth)) / math.log(growth) - 1e-9))
    coarse = max(needed(math.pi * radius / 2 - extent), needed(radius - extent))
    return [2 * (fine + coarse), fine + coarse]


def hertz_scene(a_over_h, mu):
    j = json.loads((ROOT / "schemas/examples/hertz.json").read_text())
    disc = j["body"]["mesh"]["half_disc"]
    size = {10: 0.05, 20: 0.0265, 40: 0.01325}[a_over_h]  # 33, 61, 121 candidates (issue 14)
    disc["refine"]["size"] = size
    disc["divisions"] = fewest_half_disc_divisions(disc["radius"], size, disc["refine"]["extent"])
    j["body"]["supports"] = [{"set": "diameter", "fix": ["y"], "values": {"y": -0.05}},
                             {"set": "centre", "fix": ["x"]}]
    j["obstacles"][0]["friction"] = mu
    j["steps"] = 10
    return j


def block_scene(nodes, rows, mu=0.3):
    """A block of width 1 on a flat: `nodes` contact nodes on its bottom, `rows` element rows
    of square elements."""
    nx = nodes - 1
    height = rows / nx
    return {
        "name": f"block-{nodes}x{rows}",
        "units": {"force": "N", "length": "mm"},
        "body": {
            "model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4",
            "thickness": 1, "material": {"young": 200000, "poisson": 0.3},
            "mesh": {"rectangle": {"origin": [0, 0], "size": [1, height], "divisions": [nx, rows]}},
            "supports": [{"set": "top", "fix": ["x", "y"], "values": {"y": -1e-4 * height}}],
        },
        "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [2, 0], "to": [-1, 0]},
                       "friction": mu}],
        "steps": 4,
        "output": {"steps": "last"},
    }


def run(grip, scene):
    """Wall seconds, solver seconds, CPU seconds (user + system: what the load of other work on
    the machine inflates least), peak RSS MB, contact iterations, candidates, dofs."""
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.json"
        path.write_text(json.dumps(scene))
        start = time.monotonic()
        with open(Path(tmp) / "stdout", "w") as out_f, open(Path(tmp) / "stderr", "w") as err_f:
            child = subprocess.Popen(["/usr/bin/time", "-f", "%M %U %S", "-o", str(Path(tmp) / "rss"), "timeout",
                                      str(LIMIT_S), grip, "solve", str(path), "--out", str(Path(tmp) / "out.json")],
                                     stdout=out_f, stderr=err_f)
            child.wait()
        wall = time.monotonic() - start
        proc = subprocess.CompletedProcess(child.args, child.returncode, (Path(tmp) / "stdout").read_text(),
                                           (Path(tmp) / "stderr").read_text())
        if proc.returncode in (124, 128 + 9):
            return None
        if proc.returncode != 0:
            raise RuntimeError(proc.stderr[-500:])
        m = re.search(r"total: (\d+) contact iterations, (\d+) Newton iterations, (\d+) factorizations, ([0-9.]+) s",
                      proc.stdout)
        out = json.loads((Path(tmp) / "out.json").read_text())
        effects = out.get("effects", {})
        steps = out["steps"]
        converged = all(s["converged"] for s in steps)
        peak_kb, user_s, system_s = (Path(tmp) / "rss").read_text().split()[-3:]
        return {
            "wall_s": wall, "solver_s": float(m.group(4)), "contact_iterations": int(m.group(1)),
            "factorizations": int(m.group(3)),
            "cpu_s": float(user_s) + float(system_s),
            "peak_mb": int(peak_kb) / 1024,  # grip's own peak (MiB)
            "converged": converged, "effects": effects,
        }


def counts(scene):
    """Candidates and dofs, read from the scene's mesh definition."""
    mesh = scene["body"]["mesh"]
    if "rectangle" in mesh:
        nx, ny = mesh["rectangle"]["divisions"]
        return nx + 1, 2 * (nx + 1) * (ny + 1)
    ns, nt = mesh["half_disc"]["divisions"]
    return None, 2 * (ns + 1) * (nt + 1)


def fit_exponent(xs, ys):
    lx = [math.log(x) for x in xs]
    ly = [math.log(y) for y in ys]
    n = len(lx)
    mx, my = sum(lx) / n, sum(ly) / n
    sxx = sum((a - mx) ** 2 for a in lx)
    return sum((a - mx) * (b - my) for a, b in zip(lx, ly)) / sxx if sxx > 0 else float("nan")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", default=str(ROOT / "build/apps/grip"))
    ap.add_argument("--quick", action="store_true", help="fewer sizes (a check of the script)")
    args = ap.parse_args()
    load_start = os.getloadavg()
    rows = []
    skipped = []

    def record(family, label, scene, unknowns, dofs):
        r = run(args.grip, scene)
        if r is None:
            print(f"{family:6s} {label:24s}: over {LIMIT_S} s, sweep ended", flush=True)
            skipped.append(f"{family} {label}: over {LIMIT_S} s")
            return None
        r.update(family=family, case=label, contact_unknowns=unknowns, dofs=dofs)
        rows.append(r)
        print(f"{family:6s} {label:24s} unknowns {unknowns:6d} dofs {dofs:7d}: wall {r['wall_s']:8.2f} s, "
              f"solver {r['solver_s']:8.2f} s, cpu {r['cpu_s']:8.2f} s, {r['peak_mb']:7.1f} MB, {r['contact_iterations']} solves, "
              f"converged {r['converged']}", flush=True)
        return r

    for ah in ([10, 20] if args.quick else [10, 20, 40]):
        for mu in (0.3, 0.0):
            scene = hertz_scene(ah, mu)
            cand = {10: 33, 20: 61, 40: 121}[ah]
            record("hertz", f"a/h {ah} mu {mu}", scene, cand * (2 if mu else 1), counts(scene)[1])
    for nodes in ([25, 100] if args.quick else [25, 50, 100, 200, 500, 1000, 2000]):
        scene = block_scene(nodes, 10)
        if record("flat", f"{nodes} contact nodes", scene, 2 * nodes, counts(scene)[1]) is None:
            break
    for rows_ in ([5, 50] if args.quick else [5, 20, 80, 250, 500, 1000]):
        scene = block_scene(100, rows_)
        if record("dofs", f"100 nodes, {rows_} rows", scene, 200, counts(scene)[1]) is None:
            break

    RESULTS.mkdir(parents=True, exist_ok=True)
    fields = ["family", "case", "contact_unknowns", "dofs", "wall_s", "solver_s", "cpu_s", "peak_mb",
              "contact_iterations", "factorizations", "converged"]
    with open(RESULTS / "scaling.csv", "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)

    flat = [r for r in rows if r["family"] == "flat"]
    dofs = [r for r in rows if r["family"] == "dofs"]
    # Exponents from the upper half of each sweep (the asymptotic regime).
    def upper(rs):
        return rs[len(rs) // 2 - (len(rs) % 2 == 0):] if len(rs) > 2 else rs
    e_unknowns = fit_exponent([r["contact_unknowns"] for r in upper(flat)], [r["wall_s"] for r in upper(flat)])
    e_unknowns_solver = fit_exponent([r["contact_unknowns"] for r in upper(flat)], [r["solver_s"] for r in upper(flat)])
    e_dofs = fit_exponent([r["dofs"] for r in upper(dofs)], [r["wall_s"] for r in upper(dofs)])
    e_dofs_solver = fit_exponent([r["dofs"] for r in upper(dofs)], [r["solver_s"] for r in upper(dofs)])
    e_unknowns_cpu = fit_exponent([r["contact_unknowns"] for r in upper(flat)], [r["cpu_s"] for r in upper(flat)])
    e_dofs_cpu = fit_exponent([r["dofs"] for r in upper(dofs)], [r["cpu_s"] for r in upper(dofs)])

    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    lines = [
        "# Scaling of `grip solve` (bench/scaling.py)",
        "",
        f"Measured at commit {commit}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, on "
        f"{platform.processor() or platform.machine()} with {os.cpu_count()} hardware threads shared with other "
        f"sessions: load average {load_start[0]:.1f} {load_start[1]:.1f} {load_start[2]:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} {os.getloadavg()[1]:.1f} {os.getloadavg()[2]:.1f} at the end. One run per row; "
        "wall = the whole process (reading, meshing, solving, writing); solver = its `total` line; "
        "cpu = the whole process's user + system seconds (least inflated by other work on the machine); "
        "peak = the process's peak resident memory (MiB). The compliance takes its sparse form from "
        "1200 contact unknowns on (ContactParams::sparse_compliance_from): the flat's 1000 and 2000 nodes.",
        "",
        "| family | case | contact unknowns | dofs | real solves | wall s | solver s | cpu s | peak MB | converged |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in rows:
        lines.append(f"| {r['family']} | {r['case']} | {r['contact_unknowns']} | {r['dofs']} | "
                     f"{r['contact_iterations']} | {r['wall_s']:.2f} | {r['solver_s']:.2f} | {r['cpu_s']:.2f} | {r['peak_mb']:.0f} | "
                     f"{'yes' if r['converged'] else 'no'} |")
    lines += [f"- {s}" for s in skipped]
    lines += [
        "",
        "Fitted exponents (least squares on log-log, upper half of each sweep):",
        "",
        f"- time against contact unknowns (block on a flat, mu 0.3, dofs growing with them): wall "
        f"{e_unknowns:.2f}, solver {e_unknowns_solver:.2f}, cpu {e_unknowns_cpu:.2f}",
        f"- time against dofs (100 contact nodes, growing height): wall {e_dofs:.2f}, solver {e_dofs_solver:.2f}, "
        f"cpu {e_dofs_cpu:.2f}",
        "",
    ]
    (RESULTS / "scaling.md").write_text("\n".join(lines))
    print("\n".join(lines[-5:]))

    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print("matplotlib missing: no plot", file=sys.stderr)
        return
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.2))
    for ax, rs, key, label, e in ((axes[0], flat, "contact_unknowns", "contact unknowns", e_unknowns),
                                  (axes[1], dofs, "dofs", "dofs", e_dofs)):
        xs = [r[key] for r in rs]
        ax.loglog(xs, [r["wall_s"] for r in rs], "o-", label="wall (whole process)")
        ax.loglog(xs, [r["solver_s"] for r in rs], "s--", label="solver")
        ax.loglog(xs, [r["cpu_s"] for r in rs], "^:", label="cpu (whole process)")
        ax.set_xlabel(label)
        ax.set_ylabel("seconds")
        ax.set_title(f"fitted exponent (wall) {e:.2f}")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.suptitle("grip solve: block pressed on a flat (mu 0.3, 4 steps)")
    fig.tight_layout()
    fig.savefig(RESULTS / "scaling.png", dpi=110)


if __name__ == "__main__":
    main()
