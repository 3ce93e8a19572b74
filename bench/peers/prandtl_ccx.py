#!/usr/bin/python3
"""Prandtl's punch, grip against CalculiX's *PLASTIC on the same mesh (bench/results/prandtl-peers.md).

The problem of tests/support/prandtl_punch.hpp: the half model x >= 0 of a 10 b x 10 b block
(b = 1, E = 1000, nu = 0.3, von Mises, sigma_y = 1, perfectly plastic, plane strain, small
strain); the symmetry line x = 0 and the far side held in x, the base in x and y, the smooth
punch the top nodes with x <= b moved down together to 0.1 b in STEPS equal steps (y
prescribed, x free). The limit load of the half model is (2 + pi) k b, k = sigma_y / sqrt(3).
The mesh (written here, the same nodes for both codes): elements of h up to 2.5 b from the
punch's edge and from the top, growing geometrically beyond. grip: q4_bbar (mean dilatation).
CalculiX: CPE4 on the same quadrilaterals, and CPE8R (8-node, reduced integration, the element
CalculiX's users take near incompressibility) on quadrilaterals of 2 h, whose nodes are as
dense as the 4-node mesh's. Each code's whole process is timed (start, solve, writing its
answer): wall and CPU (user + system) seconds, one thread each, one run. The load is the sum of the punch nodes' reactions.
run_grip and run_ccx (rough=True: the punch's nodes held in x too) also give the load at every
step or increment (bench/prandtl_curve.py draws them).
Usage: prandtl_ccx.py [GRIP] [--h 0.05] [--steps 20]
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
LIMIT = (2 + math.pi) / math.sqrt(3)  # the half model's limit load


def children_cpu():
    u = resource.getrusage(resource.RUSAGE_CHILDREN)
    return u.ru_utime + u.ru_stime


def graded(length, h, fine, growth=1.15):
    """Coordinates 0 .. length: steps of h up to `fine`, then growing by `growth` (the last fitted)."""
    xs = [0.0]
    while xs[-1] < fine - 1e-9:
        xs.append(min(xs[-1] + h, fine))
    step = h
    while xs[-1] < length - 1e-9:
        step *= growth
        xs.append(min(xs[-1] + step, length))
    if len(xs) > 2 and xs[-1] - xs[-2] < 0.5 * (xs[-2] - xs[-3]):
        del xs[-2]  # no sliver at the end
    return xs


def mesh(h, order):
    """Nodes and elements of the half model, q4 (order 1) or q8 on cells of 2 h (order 2)."""
    cell = h * order
    xs, ys = graded(10.0, cell, 3.5), [-y for y in graded(10.0, cell, 2.5)]
    ys.reverse()  # -10 .. 0
    if order == 2:  # the mid-lines
        xs = sorted(set(xs + [(a + b) / 2 for a, b in zip(xs, xs[1:])]))
        ys = sorted(set(ys + [(a + b) / 2 for a, b in zip(ys, ys[1:])]))
    nx, ny = len(xs), len(ys)
    nid = {}
    nodes = []
    for j, y in enumerate(ys):
        for i, x in enumerate(xs):
            if order == 2 and i % 2 and j % 2:
                continue  # no centre node (serendipity)
            nid[i, j] = len(nodes)
            nodes.append((x, y))
    elements = []
    for j in range(0, ny - 1, order):
        for i in range(0, nx - 1, order):
            if order == 1:
                elements.append([nid[i, j], nid[i + 1, j], nid[i + 1, j + 1], nid[i, j + 1]])
            else:
                c = [nid[i, j], nid[i + 2, j], nid[i + 2, j + 2], nid[i, j + 2]]
                m = [nid[i + 1, j], nid[i + 2, j + 1], nid[i + 1, j + 2], nid[i, j + 1]]
                elements.append(c + m)
    sets = {
        "left": [n for n, (x, y) in enumerate(nodes) if x < 1e-9],
        "right": [n for n, (x, y) in enumerate(nodes) if x > 10 - 1e-9],
        "bottom": [n for n, (x, y) in enumerate(nodes) if y < -10 + 1e-9],
        "punch": [n for n, (x, y) in enumerate(nodes) if y > -1e-9 and x <= 1 + 1e-9],
    }
    return nodes, elements, sets


def run_grip(grip, h, steps, work, rough=False):
    """grip on the q4 mesh; "curve": (penetration / b, load, Newton iterations) per step."""
    nodes, elements, sets = mesh(h, 1)
    scene = {
        "body": {
            "model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4_bbar",
            "material": {"law": "j2_plasticity", "young": 1000, "poisson": 0.3, "yield_stress": 1},
            "mesh": {"nodes": [list(p) for p in nodes], "elements": elements, "sets": sets},
            "contact_set": "bottom",
            "supports": [
                {"set": "left", "fix": ["x"]}, {"set": "right", "fix": ["x"]},
                {"set": "bottom", "fix": ["x", "y"]},
                {"set": "punch", "fix": ["x", "y"] if rough else ["y"], "values": {"y": -0.1}},
            ],
        },
        # grip solves contact problems: a flat far below the base, never touched.
        "obstacles": [{"name": "far", "shape": {"type": "segment", "from": [20, -20], "to": [-20, -20]}}],
        "steps": steps,
    }
    path = work / "prandtl.json"
    path.write_text(json.dumps(scene))
    t, cpu = time.monotonic(), children_cpu()
    done = subprocess.run([grip, "solve", str(path), "--out", str(work / "result.json"), "--threads", "1"],
                          capture_output=True, text=True)
    seconds, cpu = time.monotonic() - t, children_cpu() - cpu
    if done.returncode:
        raise SystemExit("grip failed: " + done.stderr[-2000:])
    result = json.loads((work / "result.json").read_text())
    punch_dofs = {2 * n + 1 for n in sets["punch"]}
    curve = [(0.1 * s["load_factor"], -sum(r["force"] for r in s["reactions"] if r["dof"] in punch_dofs),
              s["newton_iterations"]) for s in result["steps"]]
    last = result["steps"][-1]
    return {"code": "grip", "element": "q4_bbar", "nodes": len(nodes), "elements": len(elements),
            "load": curve[-1][1], "seconds": seconds, "cpu": cpu,
            "converged": last["converged"] and len(result["steps"]) == steps, "curve": curve}


def run_ccx(h, steps, order, work, rough=False):
    """CalculiX; "curve": (penetration / b, load, iterations) per converged increment (its .dat and .sta)."""
    nodes, elements, sets = mesh(h, order)
    kind = "CPE4" if order == 1 else "CPE8R"
    lines = ["*NODE, NSET=NALL"]
    lines += [f"{n + 1}, {x:.12g}, {y:.12g}" for n, (x, y) in enumerate(nodes)]
    lines.append(f"*ELEMENT, TYPE={kind}, ELSET=EALL")
    lines += [", ".join(str(v) for v in [e + 1] + [n + 1 for n in el]) for e, el in enumerate(elements)]
    for name, ids in sets.items():
        lines.append(f"*NSET, NSET={name.upper()}")
        lines += [", ".join(str(n + 1) for n in ids[k:k + 12]) for k in range(0, len(ids), 12)]
    lines += [
        "*MATERIAL, NAME=STEEL", "*ELASTIC", "1000., 0.3", "*PLASTIC", "1., 0.",
        "*SOLID SECTION, ELSET=EALL, MATERIAL=STEEL", "1.",
        "*STEP, INC=1000", "*STATIC", f"{1 / steps:.12g}, 1., {1e-3 / steps:.12g}, {1 / steps:.12g}",
        "*BOUNDARY", "LEFT, 1, 1", "RIGHT, 1, 1", "BOTTOM, 1, 2", "PUNCH, 2, 2, -0.1",
        *(["PUNCH, 1, 1"] if rough else []),
        "*NODE PRINT, NSET=PUNCH, TOTALS=ONLY", "RF", "*END STEP",
    ]
    (work / "punch.inp").write_text("\n".join(lines) + "\n")
    env = dict(os.environ, OMP_NUM_THREADS="1", CCX_NPROC_EQUATION_SOLVER="1")
    t, cpu = time.monotonic(), children_cpu()
    done = subprocess.run(["ccx", "-i", "punch"], cwd=work, capture_output=True, text=True, env=env)
    seconds, cpu = time.monotonic() - t, children_cpu() - cpu
    dat = (work / "punch.dat").read_text() if (work / "punch.dat").exists() else ""
    totals = re.findall(r"total force.*?time\s+([0-9.Ee+-]+)\s*\n\s*\n\s*([-0-9.Ee+]+)\s+([-0-9.Ee+]+)", dat)
    if done.returncode or not totals:
        raise SystemExit("ccx failed: " + done.stdout[-2000:])
    time_reached, _, fy = totals[-1]
    # .sta: STEP INC ATT ITRS TOT-TIME STEP-TIME INC-TIME, an attempt a line ("1U": not converged,
    # the increment cut); the converged ones in the order of the .dat's totals
    sta = (work / "punch.sta").read_text() if (work / "punch.sta").exists() else ""
    its = [int(f[3]) for f in map(str.split, sta.splitlines()) if len(f) == 7 and f[0].isdigit() and f[2].isdigit()]
    if len(its) != len(totals):
        its = [None] * len(totals)
    curve = [(0.1 * float(t), -float(y), n) for (t, _, y), n in zip(totals, its)]
    return {"code": "CalculiX", "element": kind, "nodes": len(nodes), "elements": len(elements),
            "load": -float(fy), "seconds": seconds, "cpu": cpu, "converged": abs(float(time_reached) - 1) < 1e-9,
            "curve": curve}


def main():
    p = argparse.ArgumentParser()
    p.add_argument("grip", nargs="?", default=str(ROOT / "build/apps/grip"))
    p.add_argument("--h", type=float, default=0.05)
    p.add_argument("--steps", type=int, default=20)
    a = p.parse_args()
    if not shutil.which("ccx"):
        raise SystemExit("ccx (Debian's calculix-ccx) is not installed")
    work = Path(tempfile.mkdtemp(prefix="prandtl-"))
    runs = [lambda: run_grip(a.grip, a.h, a.steps, work), lambda: run_ccx(a.h, a.steps, 1, work),
            lambda: run_ccx(a.h, a.steps, 2, work)]
    for run in runs:
        r = run()
        r["error_percent"] = 100 * (r["load"] / LIMIT - 1)
        del r["curve"]
        print(json.dumps(r), flush=True)
    shutil.rmtree(work)


if __name__ == "__main__":
    main()
