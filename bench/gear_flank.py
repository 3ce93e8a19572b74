#!/usr/bin/env python3
"""The gear pair's contact along the flank, step by step (issue 35; bench/results/gear-pair.md).

Solves schemas/examples/gear-pair-torque.json with `grip solve` (or reads a result given with
--result) and draws each step's contact pressure (-sigma_n of the points in contact) against
their radius from the driver's centre: the contact climbs the driver's flank through the pitch
radius (20 mm) as the gears turn.

    /usr/bin/python3 bench/gear_flank.py [--grip build/apps/grip] [--result R.json] [--out PNG]
"""
import argparse
import json
import math
import os
import subprocess
import tempfile

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--grip", default=os.path.join(ROOT, "build", "apps", "grip"))
    ap.add_argument("--result", help="a result of gear-pair-torque.json (else solved here)")
    ap.add_argument("--out", default=os.path.join(ROOT, "bench", "results", "gear-pair-flank.png"))
    args = ap.parse_args()
    path = args.result
    if not path:
        path = os.path.join(tempfile.mkdtemp(), "gear-pair-torque.result.json")
        scene = os.path.join(ROOT, "schemas", "examples", "gear-pair-torque.json")
        subprocess.run([args.grip, "solve", scene, "--out", path], check=True)
    with open(path) as f:
        result = json.load(f)
    fig, ax = plt.subplots(figsize=(7, 4.2))
    cmap = plt.get_cmap("viridis")
    steps = result["steps"]
    for k, step in enumerate(steps):
        points = sorted((math.hypot(p["x"], p["y"]), -p["sigma_n"])
                        for p in step["contact_points"] if p["state"] != "open")
        if not points:
            continue
        r, p = zip(*points)
        ax.plot(r, p, "o", ms=7, color=cmap(k / max(1, len(steps) - 1)), label=f"step {step['step']}")
        print(f"step {step['step']}: " + ", ".join(f"r {a:.2f} mm: {b:.0f} MPa" for a, b in points))
    ax.axvline(20.0, color="grey", lw=0.8, ls="--")
    ax.text(20.02, ax.get_ylim()[1] * 0.95, "pitch radius", color="grey", va="top", fontsize=8)
    ax.set_xlabel("radius from the driver's centre (mm)")
    ax.set_ylabel("contact pressure -sigma_n (MPa)")
    ax.set_title("gear-pair-torque.json: the driver's flank nodes in contact, per step", fontsize=10)
    ax.legend(fontsize=7, ncol=2)
    fig.tight_layout()
    fig.savefig(args.out, dpi=120)
    print("wrote", args.out)


if __name__ == "__main__":
    main()
