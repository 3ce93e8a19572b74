#!/usr/bin/python3
"""grip against GetFEM on the same Hertz geometry (run by bench/peers/run.sh).

Both codes: the half-disc of schemas/examples/hertz.json, its diameter lowered 0.05 mm in
10 equal steps (held in x at the centre node), a rigid flat with friction 0 or 0.3, the
same graded mesh (grip's half-disc with elements of `size` within 0.8 mm of the pole and the
fewest graded divisions beyond that it accepts; GetFEM reads it from grip's result). Accuracy: a and p0 of a semi-ellipse fitted to the nodal contact pressures,
against the closed form at each code's own load P. Time: the whole process (start-up,
meshing, solving, writing the answer), one run each, grip with its default output (every field
of every step, as a user gets it). Prints each row with its GetFEM/grip time ratio as it is
measured and writes the table to bench/results/peers.md (the run before it moves under
"Earlier runs"). Usage: compare.py [GRIP] [--sizes 10,20,40] [--table PATH]
"""
import argparse
import json
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
from scaling import hertz_scene  # noqa: E402  the scenes of the scaling benchmark

E, NU, R = 200000.0, 0.3, 10.0
ES = E / (1 - NU * NU)
SIZES = {10: 0.05, 20: 0.0265, 40: 0.01325}  # as bench/scaling.py's hertz_scene


def fit(xs, sigma):
    """a and p0 of p0 (1 - x^2 / a^2)^(1/2) fitted to (x, sigma > 0): a line in x^2, sigma^2."""
    X = [x * x for x, s in zip(xs, sigma) if s > 0]
    Y = [s * s for s in sigma if s > 0]
    n = len(X)
    sx, sy = sum(X), sum(Y)
    slope = (n * sum(a * b for a, b in zip(X, Y)) - sx * sy) / (n * sum(a * a for a in X) - sx * sx)
    intercept = (sy - slope * sx) / n
    return math.sqrt(-intercept / slope), math.sqrt(intercept)


def grip_run(grip, a_over_h, mu, mesh_path):
    """grip on the scene, timed; writes its mesh (reference positions, cells) to mesh_path."""
    with tempfile.TemporaryDirectory() as tmp:
        scene = Path(tmp) / "scene.json"
        scene.write_text(json.dumps(hertz_scene(a_over_h, mu)))  # grip's default output
        start = time.monotonic()
        subprocess.run([grip, "solve", str(scene), "--out", str(Path(tmp) / "out.json")], check=True,
                       capture_output=True)
        seconds = time.monotonic() - start
        result = json.loads((Path(tmp) / "out.json").read_text())
    step = result["steps"][-1]
    points = step["contact_points"]
    # Reference abscissae (x - ux), as GetFEM's reading and tests/support/contact_profile.hpp
    # take them: the surface moves inward by about (1 - 2 nu) P / E under the load, which would
    # shorten the fitted a by 1 % at a/h 10.
    u_x = {n["node"]: n["ux"] for n in step["nodes"]}
    reference = {n["node"]: [n["x"] - n["ux"], n["y"] - n["uy"]] for n in step["nodes"]}
    Path(mesh_path).write_text(json.dumps({"nodes": [reference[k] for k in range(len(reference))],
                                           "cells": result["mesh"]["cells"]}))
    xs = [c["x"] - u_x[c["node"]] for c in points]
    P = -sum(c["p_n"] for c in points)
    xc = sum(c["p_n"] * x for c, x in zip(points, xs)) / sum(c["p_n"] for c in points)
    a_fit, p0_fit = fit([x - xc for x in xs], [-c["sigma_n"] for c in points])
    a = math.sqrt(4 * P * R / (math.pi * ES))
    p0 = 2 * P / (math.pi * a)
    return {"P": P, "a_error": a_fit / a - 1, "p0_error": p0_fit / p0 - 1, "seconds": seconds}


def getfem_run(a_over_h, mu, mesh_path):
    start = time.monotonic()
    out = subprocess.run(["/usr/bin/python3", str(Path(__file__).parent / "getfem_hertz.py"), str(mu),
                          str(SIZES[a_over_h]), "1", str(mesh_path)], check=True, capture_output=True,
                         text=True).stdout
    seconds = time.monotonic() - start
    r = json.loads(out.strip().splitlines()[-1])
    r["seconds"] = seconds
    return r


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("grip", nargs="?", default=str(ROOT / "build/apps/grip"))
    ap.add_argument("--sizes", default="10,20,40", help="a/h values, from " + ",".join(map(str, SIZES)))
    ap.add_argument("--table", default=str(ROOT / "bench/results/peers.md"))
    args = ap.parse_args()
    load = os.getloadavg()
    rows = []
    for a_over_h in (int(v) for v in args.sizes.split(",")):
        for mu in (0.0, 0.3):
            with tempfile.TemporaryDirectory() as tmp:
                mesh_path = Path(tmp) / "mesh.json"
                g = grip_run(args.grip, a_over_h, mu, mesh_path)
                f = getfem_run(a_over_h, mu, mesh_path)
            rows.append((a_over_h, mu, g, f))
            print(f"a/h {a_over_h} mu {mu}: grip {g['seconds']:.2f} s, GetFEM {f['seconds']:.2f} s, "
                  f"GetFEM/grip {f['seconds'] / g['seconds']:.1f}x (load {os.getloadavg()[0]:.1f})",
                  json.dumps(g), json.dumps(f), flush=True)
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    pct = lambda v: f"{100 * v:+.2f} %"
    lines = [
        "# grip and GetFEM on the same Hertz geometry (bench/peers/run.sh)",
        "",
        f"Measured at commit {commit}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, on 2 hardware threads "
        f"shared with other sessions (load average {load[0]:.1f} at the start, {os.getloadavg()[0]:.1f} at the "
        "end). Half-disc R 10 mm, E 200 GPa, nu 0.3, plane strain, small strain; diameter lowered 0.05 mm in "
        "10 steps; the same graded quadrilateral mesh (q4 / GetFEM Q1). grip: `cev` (tolerance 1e-8). GetFEM "
        "5.4 (Debian python3-getfem): integral contact brick with a rigid obstacle, Alart-Curnier augmented "
        "Lagrangian, Newton (residual 1e-9). a and p0: a semi-ellipse fitted to the nodal contact pressures, "
        "error against the closed form at each code's own load P, both read at the nodes' reference "
        "abscissae (GetFEM's multiplier at its reference nodes; grip's x - ux). With friction 0.3 the "
        "frictionless closed form is not the answer (the coupling of normal and tangential tractions "
        "narrows the zone and raises the peak, Spence): there the two codes are compared with each "
        "other. Time: the whole process, one run each; grip with its default output (every field of every "
        "step written: 28 MB at a/h 40).",
        "",
        "| a/h | friction | grip P N/mm | grip a err | grip p0 err | grip s | GetFEM P N/mm | GetFEM a err | "
        "GetFEM p0 err | GetFEM s | time ratio |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for a_over_h, mu, g, f in rows:
        lines.append(f"| {a_over_h} | {mu} | {g['P']:.0f} | {pct(g['a_error'])} | {pct(g['p0_error'])} | "
                     f"{g['seconds']:.2f} | {f['P']:.0f} | {pct(f['a_error'])} | {pct(f['p0_error'])} | "
                     f"{f['seconds']:.2f} | {f['seconds'] / g['seconds']:.0f}x |")
    lines.append("")
    table = Path(args.table)
    if table.exists():  # the previous run moves under "Earlier runs"
        old = table.read_text()
        top, _, earlier = old.partition("## Earlier runs")
        top = top.replace("# grip and GetFEM on the same Hertz geometry (bench/peers/run.sh)\n", "").strip()
        lines += ["## Earlier runs", "", top, "", earlier.strip(), ""]
    table.write_text("\n".join(lines))
    print("\n".join(lines[:len(rows) + 6]))


if __name__ == "__main__":
    main()
