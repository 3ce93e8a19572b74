#!/usr/bin/python3
"""Hertz's sphere (axisymmetric) against the same section as a cylinder in plane strain, and
against CalculiX's CAX4 on the same nodes and CAX8 on the same corners (issue 36, "Speed (benchmark)").

grip: schemas/examples/hertz-sphere.json (the hemisphere's quarter-disc section, q8, its
diameter lowered 0.05 mm in 2 steps onto a rigid frictionless flat) with the refine size
a / (a/h), a = 0.707 mm the closed form at the nominal load, and the fewest graded divisions the
generator accepts; the cylinder is the same scene in plane strain (the same mesh, its axis held
in x as a symmetry line), so the two differ only in the analysis. CalculiX (`ccx`, Debian's
calculix-ccx: `apt-get install calculix-ccx` for this benchmark only, never in scripts/setup.sh;
without it only the grip table is written): grip's q4 result mesh written as CAX4 on the same
nodes, the flat a row of fixed CAX4 elements, frictionless surface-to-surface penalty contact,
the same prescribed displacement in 2 increments; and CAX8 on the same corners (a mid-side node at
each side's middle, on the arc moved onto it) against grip's q8.
Accuracy: a and p0 of a semi-ellipse fitted about the axis (x = 0) to the nodal contact
pressures, against the closed form at each code's own load P (the sphere: a = (3 P R /
(4 E*))^(1/3), p0 = 3 P / (2 pi a^2); the cylinder: a = (4 P R / (pi E*))^(1/2), p0 = 2 P /
(pi a)). Time: the whole process, the fastest of 5 runs. Writes bench/results/axisymmetric.md.
Usage: axisymmetric.py [GRIP] [--sizes 10,20,40] [--table PATH] [--penalty 1e9] [--repeat 5] [--no-ccx]
"""
import argparse
import json
import math
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[2]
sys.path.insert(0, str(ROOT / "bench"))
from scaling import fewest_half_disc_divisions  # noqa: E402

sys.path.insert(0, str(Path(__file__).resolve().parent))
from compare import fit as fit_about_axis  # noqa: E402  a, p0 of a Hertz profile fitted about the axis

E, NU, R, DELTA = 200000.0, 0.3, 10.0, 0.05
ES = E / (1 - NU * NU)
A_SPHERE = math.sqrt(R * DELTA)  # the closed-form contact radius at the nominal load
OFF_AXIS = 0.25  # the second fit takes the nodes at r > a / 4 only (ccx's nearest the axis are off)


def closed_form(analysis, P):
    if analysis == "axisymmetric":
        a = (3 * P * R / (4 * ES)) ** (1 / 3)
        return a, 3 * P / (2 * math.pi * a * a)
    a = math.sqrt(4 * P * R / (math.pi * ES))
    return a, 2 * P / (math.pi * a)


def scene(a_over_h, analysis, element="q8"):
    j = json.loads((ROOT / "schemas/examples/hertz-sphere.json").read_text())
    j["body"]["element"] = element
    disc = j["body"]["mesh"]["half_disc"]
    size = A_SPHERE / a_over_h
    disc["refine"]["size"] = size
    disc["divisions"] = fewest_half_disc_divisions(disc["radius"], size, disc["refine"]["extent"])
    j["body"]["analysis"] = analysis
    if analysis != "axisymmetric":
        j["body"]["thickness"] = 1
        j["body"]["supports"].append({"set": "axis", "fix": ["x"]})  # the symmetry line
    return j


def timed(command, **kw):
    """Wall and CPU (user + system) seconds of a child process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    run = subprocess.run(command, capture_output=True, text=True, **kw)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if run.returncode != 0:
        raise RuntimeError(f"{command[0]} failed:\n{run.stdout[-3000:]}{run.stderr[-2000:]}")
    timed.last = run
    return wall, after.ru_utime + after.ru_stime - before.ru_utime - before.ru_stime


def grip_run(grip, a_over_h, analysis, tmp, repeat, element="q8"):
    path = Path(tmp) / f"{analysis}-{element}.json"
    path.write_text(json.dumps(scene(a_over_h, analysis, element)))
    out = Path(tmp) / f"{analysis}-{element}-out.json"
    seconds, cpu, solver_seconds = math.inf, math.inf, math.inf
    for _ in range(repeat):  # the fastest of `repeat` runs: the machine is shared
        wall, used = timed([grip, "solve", str(path), "--out", str(out)])
        cpu = min(cpu, used)
        if wall < seconds:
            seconds = wall
            solver_seconds = json.loads(out.read_text())["summary"]["seconds"]
    result = json.loads(out.read_text())
    step = result["steps"][-1]
    points = step["contact_points"]
    u_x = {n["node"]: n["ux"] for n in step["nodes"]}
    xs = [c["x"] - u_x[c["node"]] for c in points]  # reference abscissae, as the tests read them
    # the section is x >= 0: the cylinder's other half carries as much again
    P = -sum(c["p_n"] for c in points) * (1 if analysis == "axisymmetric" else 2)
    sigma = [-c["sigma_n"] for c in points]
    a, p0 = closed_form(analysis, P)
    a_fit, p0_fit = fit_about_axis(xs, sigma)
    a_off, p0_off = fit_about_axis(*zip(*[(x, v) for x, v in zip(xs, sigma) if x > OFF_AXIS * a]))
    s = result["summary"]
    return {"P": P, "a_error": a_fit / a - 1, "p0_error": p0_fit / p0 - 1,
            "a_error_off_axis": a_off / a - 1, "p0_error_off_axis": p0_off / p0 - 1, "seconds": seconds,
            "cpu_seconds": cpu, "solver_seconds": solver_seconds, "factorizations": s["factorizations"],
            "contact_iterations": s["contact_iterations"], "nodes": len(step["nodes"]),
            "result": result}


# ---- CalculiX ---------------------------------------------------------------------------------

def quadratic_sides(xy, cells):
    """CAX8 on the q4 mesh's corners: a mid-side node at each side's middle, shared by the two
    elements that meet there; on the sphere's arc it is moved out onto the arc (grip's q8 of the
    same divisions has the same corners and its arc sides on the circle)."""
    mids, points = {}, [tuple(p) for p in xy]
    out = []
    for c in cells:
        extra = []
        for f in range(4):
            key = tuple(sorted((c[f], c[(f + 1) % 4])))
            if key not in mids:
                m = 0.5 * (xy[key[0]] + xy[key[1]])
                on_arc = all(abs(math.hypot(*xy[k]) - R) < 1e-6 * R for k in key)
                if on_arc:
                    m = m * R / math.hypot(*m)
                mids[key] = len(points)
                points.append(tuple(m))
            extra.append(mids[key])
        out.append(list(c) + extra)
    return np.array(points), out


def ccx_deck(result, k_penalty, quadratic=False):
    """The .inp: grip's q4 mesh as CAX4 (its reference positions), or as CAX8 with mid-side nodes
    added (quadratic), and a fixed CAX4 flat below y = -R. (grip's result lists each q8's corners
    only, and its graded rows put the mid-side nodes at the sides' parametric middles, which
    geometry alone does not pair with their sides: CAX8 gets its own.)"""
    step = result["steps"][-1]
    xy = np.array([[n["x"] - n["ux"], n["y"] - n["uy"]] for n in sorted(step["nodes"], key=lambda n: n["node"])])
    cells = []
    for c in result["mesh"]["cells"]:
        p = xy[c]
        area = 0.5 * sum(p[i, 0] * p[(i + 1) % 4, 1] - p[(i + 1) % 4, 0] * p[i, 1] for i in range(4))
        c = list(c) if area > 0 else list(reversed(c))  # counter-clockwise
        cells.append(c)
    if quadratic:
        xy, cells = quadratic_sides(xy, cells)
    n = len(xy)
    lines = ["*HEADING", "grip bench/peers/axisymmetric.py: Hertz sphere", "*NODE"]
    lines += [f"{i + 1}, {x:.15g}, {y:.15g}" for i, (x, y) in enumerate(xy)]
    # the flat: 0 <= r <= 2, one row of CAX4 0.05 mm wide, 0.5 mm thick, every node fixed
    width, cols = 2.0, 40
    flat0 = n + 1
    lines += [f"{flat0 + i}, {width * i / cols:.15g}, {-R:.15g}" for i in range(cols + 1)]
    lines += [f"{flat0 + cols + 1 + i}, {width * i / cols:.15g}, {-R - 0.5:.15g}" for i in range(cols + 1)]
    lines += [f"*ELEMENT, TYPE={'CAX8' if quadratic else 'CAX4'}, ELSET=SPHERE"]
    lines += [f"{e + 1}, " + ", ".join(str(v + 1) for v in c) for e, c in enumerate(cells)]
    e0 = len(cells) + 1
    lines += ["*ELEMENT, TYPE=CAX4, ELSET=FLAT"]
    # counter-clockwise: bottom-left, bottom-right, top-right, top-left; face 3 is the top
    lines += [f"{e0 + i}, {flat0 + cols + 1 + i}, {flat0 + cols + 2 + i}, {flat0 + i + 1}, {flat0 + i}"
              for i in range(cols)]
    # slave faces: the sphere's element sides on the arc within 2 mm of the axis
    on_arc = np.abs(np.hypot(xy[:, 0], xy[:, 1]) - R) < 1e-6 * R
    slave = []
    for e, c in enumerate(cells):
        for f in range(4):
            i, j = c[f], c[(f + 1) % 4]
            if on_arc[i] and on_arc[j] and max(xy[i, 0], xy[j, 0]) <= 2.0 and xy[i, 1] < 0:
                slave.append(f"{e + 1}, S{f + 1}")
    diameter = [i + 1 for i in range(n) if abs(xy[i, 1]) < 1e-9]
    axis = [i + 1 for i in range(n) if abs(xy[i, 0]) < 1e-9]
    lines += ["*NSET, NSET=DIAMETER"] + [f"{i}," for i in diameter]
    lines += ["*NSET, NSET=AXIS"] + [f"{i}," for i in axis]
    lines += ["*NSET, NSET=FLATN, GENERATE", f"{flat0}, {flat0 + 2 * cols + 1}, 1"]
    lines += ["*SURFACE, NAME=SSPHERE, TYPE=ELEMENT"] + slave
    lines += ["*SURFACE, NAME=SFLAT, TYPE=ELEMENT"] + [f"{e0 + i}, S3" for i in range(cols)]
    lines += ["*MATERIAL, NAME=STEEL", "*ELASTIC", f"{E}, {NU}",
              "*SOLID SECTION, ELSET=SPHERE, MATERIAL=STEEL", "*SOLID SECTION, ELSET=FLAT, MATERIAL=STEEL",
              "*SURFACE INTERACTION, NAME=FRICTIONLESS", "*SURFACE BEHAVIOR, PRESSURE-OVERCLOSURE=LINEAR",
              f"{k_penalty:g}, 1.0",
              "*CONTACT PAIR, INTERACTION=FRICTIONLESS, TYPE=SURFACE TO SURFACE", "SSPHERE, SFLAT",
              "*BOUNDARY", "FLATN, 1, 2, 0.0", "AXIS, 1, 1, 0.0",
              "*STEP", "*STATIC", "0.5, 1.0, 0.5, 0.5",
              "*BOUNDARY", f"DIAMETER, 2, 2, {-DELTA}",
              "*NODE FILE", "U", "*CONTACT FILE", "CSTR",
              "*NODE PRINT, NSET=DIAMETER, TOTALS=ONLY", "RF",
              "*END STEP"]
    return "\n".join(lines) + "\n", xy


def frd_blocks(text, name):
    """The last result block `name` of an ascii .frd: node -> values."""
    blocks = text.split("\n    1PSTEP")
    for block in reversed(blocks):
        m = re.search(r"^ -4  " + name + r"\b.*$", block, re.M)
        if not m:
            continue
        values = {}
        for line in block[m.end():].splitlines():
            if line.startswith(" -3"):
                break
            if line.startswith(" -1"):
                node = int(line[3:13])
                values[node] = [float(line[13 + 12 * k:25 + 12 * k]) for k in range((len(line) - 13) // 12)]
        return values
    return {}


def ccx_run(result, tmp, k_penalty, repeat, quadratic=False):
    deck, xy = ccx_deck(result, k_penalty, quadratic)
    job = "sphere8" if quadratic else "sphere"
    (Path(tmp) / f"{job}.inp").write_text(deck)
    seconds, cpu = math.inf, math.inf
    for _ in range(repeat):
        wall, used = timed(["ccx", "-i", job], cwd=tmp, env=dict(os.environ, OMP_NUM_THREADS="1"))
        seconds, cpu = min(seconds, wall), min(cpu, used)
    run = timed.last
    if "Job finished" not in run.stdout:
        raise RuntimeError("ccx failed:\n" + run.stdout[-3000:] + run.stderr[-2000:])
    dat = (Path(tmp) / f"{job}.dat").read_text()
    totals = re.findall(r"^\s*(-?[\d.E+-]+)\s+(-?[\d.E+-]+)\s+(-?[\d.E+-]+)\s*$",
                        dat.split("total force")[-1], re.M)
    reaction = float(totals[0][1])  # the diameter's total y force, as ccx reports it
    contact = frd_blocks((Path(tmp) / f"{job}.frd").read_text(), "CONTACT")
    xs, p = [], []
    for node, v in contact.items():
        if node <= len(xy) and v[3] > 0:  # CPRESS
            xs.append(xy[node - 1, 0])
            p.append(v[3])
    iterations = sum(int(l.split()[3]) for l in (Path(tmp) / f"{job}.sta").read_text().splitlines()
                     if re.match(r"\s+1\s+\d+\s+\d+\s+\d+\s", l))
    return {"reaction": reaction, "xs": xs, "p": p, "seconds": seconds, "cpu_seconds": cpu,
            "iterations": iterations, "nodes": len(xy)}


def ccx_reading(c):
    """P (full circle) from ccx's reaction and a, p0 errors at that load."""
    xs, p = zip(*sorted(zip(c["xs"], c["p"])))
    a_fit, p0_fit = fit_about_axis(xs, p)
    # ccx expands an axisymmetric model into a 2 degree wedge and reports its forces for it;
    # the pressures' integral over the full circle (trapezoids in r) checks the factor 180.
    P = 180 * abs(c["reaction"])
    f = [2 * math.pi * x * v for x, v in zip(xs, p)]
    integral = sum(0.5 * (f[k] + f[k + 1]) * (xs[k + 1] - xs[k]) for k in range(len(xs) - 1))
    if abs(integral / P - 1) > 0.1:
        raise RuntimeError(f"ccx: 180 x its reaction {P:g} N against its pressures' integral {integral:g} N")
    a, p0 = closed_form("axisymmetric", P)
    a_off, p0_off = fit_about_axis(*zip(*[(x, v) for x, v in zip(xs, p) if x > OFF_AXIS * a]))
    return {"P": P, "pressure_integral": integral, "a_error": a_fit / a - 1, "p0_error": p0_fit / p0 - 1,
            "a_error_off_axis": a_off / a - 1, "p0_error_off_axis": p0_off / p0 - 1,
            "seconds": c["seconds"], "cpu_seconds": c["cpu_seconds"], "iterations": c["iterations"],
            "contact_nodes": len(xs), "nodes": c["nodes"]}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("grip", nargs="?", default=str(ROOT / "build/apps/grip"))
    ap.add_argument("--sizes", default="10,20,40")
    ap.add_argument("--table", default=str(ROOT / "bench/results/axisymmetric.md"))
    ap.add_argument("--penalty", type=float, default=1e9, help="ccx's contact stiffness, MPa / mm")
    ap.add_argument("--repeat", type=int, default=5, help="runs of each, the fastest counts")
    ap.add_argument("--no-ccx", action="store_true")
    args = ap.parse_args()
    use_ccx = not args.no_ccx and shutil.which("ccx") is not None
    load = os.getloadavg()
    rows = []
    for a_over_h in (int(v) for v in args.sizes.split(",")):
        with tempfile.TemporaryDirectory() as tmp:
            s = grip_run(args.grip, a_over_h, "axisymmetric", tmp, args.repeat)
            c = grip_run(args.grip, a_over_h, "plane_strain", tmp, args.repeat)
            q4 = grip_run(args.grip, a_over_h, "axisymmetric", tmp, args.repeat, "q4") if use_ccx else None
            x = ccx_reading(ccx_run(q4["result"], tmp, args.penalty, args.repeat)) if use_ccx else None
            x8 = ccx_reading(ccx_run(q4["result"], tmp, args.penalty, args.repeat, True)) if use_ccx else None
        rows.append((a_over_h, s, c, q4, x, x8))
        print(f"a/h {a_over_h}: sphere {s['seconds']:.2f} s, cylinder {c['seconds']:.2f} s, ratio "
              f"{s['seconds'] / c['seconds']:.2f}" + (f", ccx {x['seconds']:.2f} s, CAX8 {x8['seconds']:.2f} s" if x else "") +
              f" (load {os.getloadavg()[0]:.1f})", flush=True)
        for r in (s, c, q4, x, x8):
            if r:
                print("  ", json.dumps({k: v for k, v in r.items() if k != "result"}), flush=True)
    write_table(args, rows, load)


def write_table(args, rows, load):
    commit = subprocess.run(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    cpu = next((l.split(":", 1)[1].strip() for l in Path("/proc/cpuinfo").read_text().splitlines()
                if l.startswith("model name")), "?")
    ccx_version = ""
    if any(x for *_, x, _ in rows):
        ccx_version = re.search(r"Version\s+(\S+)", subprocess.run(["ccx", "-v"], capture_output=True,
                                                                    text=True).stdout or "Version ?").group(1)
    pct = lambda v: f"{100 * v:+.2f} %"
    both = lambda r, k: f"{pct(r[k])} ({pct(r[k + '_off_axis'])})"
    secs = lambda r: f"{r['seconds']:.2f} / {r['cpu_seconds']:.2f}"
    lines = [
        "# Hertz's sphere: axisymmetric against plane strain, and against CalculiX (bench/peers/axisymmetric.py)",
        "",
        f"Measured at commit {commit}, {time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, on {os.cpu_count()} "
        f"hardware threads ({cpu}) shared with other sessions (load average {load[0]:.1f} at the start, "
        f"{os.getloadavg()[0]:.1f} at the end). Each time is the fastest of {args.repeat} runs of the whole "
        "process (start-up, meshing or reading, solving, writing): wall / CPU (user + system) seconds. "
        "The machine's load moves the wall time by up to 2x from run to run; the CPU time is the steadier "
        "measure of the cost.",
        "",
        "The scene: schemas/examples/hertz-sphere.json (R 10 mm, E 200 GPa, nu 0.3, linear small strain; the "
        "hemisphere's quarter-disc section pressed 0.05 mm onto a rigid frictionless flat in 2 steps), "
        f"elements of a / (a/h) within 1.2 mm of the pole (a = {A_SPHERE:.3f} mm, the closed form at the "
        "nominal load), the fewest graded divisions the generator accepts. a and p0: a semi-ellipse fitted "
        "about the axis to the nodal contact pressures at the nodes' reference radii, against the closed form "
        "at each code's own load P (from the reactions, the full circle); in brackets the same fit to the "
        "nodes at r > a / 4 only.",
        "",
        "## grip: the sphere against the same section as a cylinder in plane strain",
        "",
        "The cylinder is the same scene with analysis plane_strain (the same q8 mesh, its axis held in x as "
        "a symmetry line; P per unit length is twice the section's): the two differ only in the analysis.",
        "",
        "| a/h | nodes | sphere a err | sphere p0 err | sphere s | cylinder a err | cylinder p0 err | "
        "cylinder s | sphere / cylinder, wall | CPU |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for a_over_h, s, c, *_ in rows:
        lines.append(f"| {a_over_h} | {s['nodes']} | {pct(s['a_error'])} | {pct(s['p0_error'])} | {secs(s)} | "
                     f"{pct(c['a_error'])} | {pct(c['p0_error'])} | {secs(c)} | "
                     f"{s['seconds'] / c['seconds']:.2f}x | {s['cpu_seconds'] / c['cpu_seconds']:.2f}x |")
    counts = {(r["factorizations"], r["contact_iterations"]) for _, s, c, *_ in rows for r in (s, c)}
    lines += ["", "Factorizations and contact iterations (the whole run): " +
              ", ".join(f"{f} and {i}" for f, i in sorted(counts)) + " in every grip run above."]
    if any(x for *_, x, _ in rows):
        lines += [
            "", "## The sphere: grip (q4) against CalculiX (CAX4) on the same nodes", "",
            f"CalculiX {ccx_version} (Debian calculix-ccx, installed for this benchmark only, one thread: "
            "OMP_NUM_THREADS=1, its default SPOOLES solver), read from grip's q4 result mesh (CAX4 on the same "
            "nodes; CAX8 on the same corners in the next table). The "
            f"flat: a row of fixed CAX4 elements 0.05 mm wide. Contact: surface to surface, frictionless, "
            f"penalty with a linear pressure-overclosure of {args.penalty:g} MPa/mm (1e8 at a/h 10: P 0.1 % lower, "
            "the off-axis a and p0 within 0.4 %); the same prescribed displacement in 2 increments. Its pressure: CPRESS at the "
            "slave nodes in the .frd; its load: the diameter's reaction, which ccx reports for the 2 degree "
            "wedge it expands an axisymmetric model into (x 180 for the full circle, checked against the "
            "pressures' integral over the circle). grip: cev, tolerance 1e-8, the same scene in q4.",
            "",
            "| a/h | grip P N | grip a err | grip p0 err | grip s | ccx P N | ccx a err | ccx p0 err | ccx s | "
            "ccx Newton iterations | ccx / grip, wall | CPU |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for a_over_h, _, _, s, x, _ in rows:
            if x:
                lines.append(f"| {a_over_h} | {s['P']:.0f} | {both(s, 'a_error')} | {both(s, 'p0_error')} | "
                             f"{secs(s)} | {x['P']:.0f} | {both(x, 'a_error')} | {both(x, 'p0_error')} | {secs(x)} | "
                             f"{x['iterations']} | {x['seconds'] / s['seconds']:.0f}x | "
                             f"{x['cpu_seconds'] / s['cpu_seconds']:.0f}x |")
        lines += [
            "", "## The sphere: grip (q8) against CalculiX (CAX8) on the same corners", "",
            "CAX8 on the q4 mesh's corners (the corners of grip's q8 mesh of the same divisions), a mid-side "
            "node at each side's middle (on the sphere's arc moved out onto the arc); everything else as for "
            "CAX4 above. grip: the shipped scene in q8 (the first table's sphere). Nodes: each model's.",
            "",
            "| a/h | grip P N | grip a err | grip p0 err | grip s | ccx nodes | ccx P N | ccx a err | "
            "ccx p0 err | ccx s | ccx Newton iterations | ccx / grip, wall | CPU |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|"]
        for a_over_h, s, _, _, _, x in rows:
            if x:
                lines.append(f"| {a_over_h} | {s['P']:.0f} | {both(s, 'a_error')} | "
                             f"{both(s, 'p0_error')} | {secs(s)} | {x['nodes']} | {x['P']:.0f} | {both(x, 'a_error')} | "
                             f"{both(x, 'p0_error')} | {secs(x)} | {x['iterations']} | "
                             f"{x['seconds'] / s['seconds']:.0f}x | {x['cpu_seconds'] / s['cpu_seconds']:.0f}x |")
    lines.append("")
    table = Path(args.table)
    if table.exists():  # the previous run moves under "Earlier runs", the notes stay on top
        old = table.read_text()
        notes = old.partition("## Notes")[2].partition("## Earlier runs")[0].strip()
        earlier = old.partition("## Earlier runs")[2].strip()
        previous = old.partition("## Notes")[0].split("\n", 1)[1].strip()
        if notes:
            lines += ["## Notes", "", notes, ""]
        lines += ["## Earlier runs", "", previous.replace("\n## ", "\n### "), "", earlier, ""]
    table.write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
