#!/usr/bin/python3
"""Prandtl's punch: the load-penetration curve against the limit load (issue 37; bench/results/prandtl-curve.md).

The problem, the mesh and both codes' inputs are bench/peers/prandtl_ccx.py's (imported, not
repeated): the half model of a 10 b x 10 b elastic-perfectly plastic block (von Mises, plane
strain, small strain) under a flat punch of half-width b pressed to 0.1 b. Runs grip (q4_bbar)
for the smooth and the rough punch on the coarse (h = b/10) and refined (h = b/20) meshes and,
where CalculiX's ccx is installed, CalculiX's CPE8R on the same node density (quadrilaterals of
2 h); reads the load (the sum of the punch nodes' reactions) at every step (grip's result) or
converged increment (CalculiX's .dat), and draws load / ((2 + pi) k b) against penetration / b
with the limit as a horizontal line. Prints one JSON line per run (its curve with the Newton
iterations of each step), then the table and the summary as Markdown.

    /usr/bin/python3 bench/prandtl_curve.py [GRIP] [--steps 20] [--no-ccx] [--out PNG]
"""
import argparse
import json
import shutil
import sys
import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "bench" / "peers"))
from prandtl_ccx import LIMIT, run_ccx, run_grip  # noqa: E402

MESHES = [(0.1, "b/10"), (0.05, "b/20")]


def label(r):
    return f"{r['code']} {r['element']}, h = {r['mesh']}"


def interpolate(curve, d):
    """The load at penetration d, linear between a curve's points (None outside them)."""
    for (d0, f0, _), (d1, f1, _) in zip(curve, curve[1:]):
        if d0 - 1e-12 <= d <= d1 + 1e-12:
            return f0 + (f1 - f0) * (d - d0) / (d1 - d0) if d1 > d0 else f1
    return None


def summary(r):
    """Last load / limit, the change over the last three steps and over 0.05 b .. 0.1 b (% of the
    last load), the iterations per step where the penetration is at least 0.05 b."""
    c = r["curve"]
    last = c[-1][1]
    half = interpolate(c, 0.05)
    plateau = [n for d, _, n in c if d >= 0.05 - 1e-12 and n is not None]
    return {"ratio": last / LIMIT, "last3": 100 * (last - c[-4][1]) / last, "half": 100 * (last - half) / last,
            "its": (min(plateau), sum(plateau) / len(plateau), max(plateau)) if plateau else None}


def draw(runs, out):
    fig, axes = plt.subplots(2, 2, figsize=(10, 7), sharex=True)
    colours = {("grip", "b/10"): "tab:blue", ("grip", "b/20"): "navy",
               ("CalculiX", "b/10"): "tab:orange", ("CalculiX", "b/20"): "firebrick"}
    for col, rough in enumerate((False, True)):
        for row in (0, 1):
            ax = axes[row, col]
            for r in runs:
                if r["rough"] != rough:
                    continue
                d = [0.0] + [p[0] for p in r["curve"]]
                f = [0.0] + [p[1] / LIMIT for p in r["curve"]]
                grip = r["code"] == "grip"
                ax.plot(d, f, "-o" if grip else "--s", ms=3 if grip else 2.5, lw=1.2,
                        color=colours[r["code"], r["mesh"]], label=label(r))
            ax.axhline(1.0, color="black", lw=0.8)
            ax.grid(alpha=0.3)
            ax.text(0.099, 0.99 if row else 0.97, "limit (2 + pi) k b", ha="right", va="top", fontsize=8)
            if row == 0:
                ax.set_ylim(0, 1.15)
                ax.set_title(("rough" if rough else "smooth") + " punch", fontsize=10)
            else:
                ax.set_ylim(0.94, 1.09)
                ax.set_xlabel("penetration / b")
            if col == 0:
                ax.set_ylabel("load / ((2 + pi) k b)" + (", near the limit" if row else ""))
    axes[0, 0].legend(fontsize=8, loc="lower right")
    fig.suptitle("Prandtl's punch, half model, E/sigma_y = 1000, nu = 0.3, plane strain", fontsize=11)
    fig.tight_layout()
    fig.savefig(out, dpi=100)


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("grip", nargs="?", default=str(ROOT / "build/apps/grip"))
    p.add_argument("--steps", type=int, default=20)
    p.add_argument("--no-ccx", action="store_true", help="grip alone even where ccx is installed")
    p.add_argument("--skip", action="append", default=[],
                   help="leave a run out, e.g. 'grip rough b/20' (repeatable)")
    p.add_argument("--out", default=str(ROOT / "bench/results/prandtl-curve.png"))
    a = p.parse_args()
    ccx = not a.no_ccx and shutil.which("ccx")
    if not ccx:
        print("CalculiX (ccx) left out: " + ("--no-ccx" if a.no_ccx else "not installed"), file=sys.stderr)
    work = Path(tempfile.mkdtemp(prefix="prandtl-curve-"))
    runs = []
    for rough in (False, True):
        for h, name in MESHES:
            jobs = [("grip", lambda w: run_grip(a.grip, h, a.steps, w, rough))]
            if ccx:
                jobs.append(("CalculiX", lambda w: run_ccx(h, a.steps, 2, w, rough)))
            for code, job in jobs:
                if f"{code} {'rough' if rough else 'smooth'} {name}" in a.skip:
                    continue
                w = work / f"{code}-{rough}-{h}"
                w.mkdir()
                r = job(w)
                r.update(rough=rough, mesh=name, h=h)
                print(json.dumps(r), flush=True)
                runs.append(r)
    shutil.rmtree(work)
    draw(runs, a.out)
    print("wrote", a.out)

    # The table at grip's penetrations (CalculiX's increments interpolated linearly).
    grid = [d for d, _, _ in runs[0]["curve"]]
    heads = [f"{'rough' if r['rough'] else 'smooth'} {r['code']} {r['mesh']}" for r in runs]
    print("\n| penetration / b | " + " | ".join(heads) + " |")
    print("|---" * (len(runs) + 1) + "|")
    for d in grid:
        cells = []
        for r in runs:
            f = interpolate(r["curve"], d)
            n = next((k for dd, _, k in r["curve"] if abs(dd - d) < 1e-9), None) if r["code"] == "grip" else None
            cells.append("-" if f is None else f"{f / LIMIT:.4f}" + (f" ({n})" if n is not None else ""))
        print(f"| {d:.3f} | " + " | ".join(cells) + " |")
    print("\n| punch | code, element | h | nodes | steps / increments | load / limit at 0.1 b "
          "| change over the last 3 | change 0.05 b .. 0.1 b | iterations per step from 0.05 b (min / mean / max) | CPU s |")
    print("|---|---|---|---|---|---|---|---|---|---|")
    for r in runs:
        s = summary(r)
        its = "-" if s["its"] is None else f"{s['its'][0]} / {s['its'][1]:.1f} / {s['its'][2]}"
        print(f"| {'rough' if r['rough'] else 'smooth'} | {r['code']} {r['element']} | {r['mesh']} | {r['nodes']} "
              f"| {len(r['curve'])} | {s['ratio']:.4f} | {s['last3']:+.2f} % | {s['half']:+.2f} % | {its} "
              f"| {r['cpu']:.1f} |")


if __name__ == "__main__":
    main()
