#!/usr/bin/python3
"""Real solves and Newton iterations of cev on plastic bodies, against the same scenes elastic.

The ten plastic scenes of bench/results/plasticity.md (the shipped Hertz examples and the golden
J2 scenes with the law of tests/verification/j2_contact_test.cpp: von Mises, yield 2000 MPa,
linear hardening 20000 MPa; "4 + 4": pressed in 4 steps, released in 4) and Prandtl's punch as a
contact obstacle (the square-edged punch of tests/verification/prandtl_punch_contact_test.cpp on
the b/5 mesh of bench/peers/prandtl_ccx.py, 0.1 b in 10 steps), each beside its linear elastic
twin where the issue's ratio is asked. Prints one markdown row per scene: real solves / Newton
iterations for every `solver.contact` variant given (JSON objects merged into the scene's).

    bench/plastic_contact_counts.py --grip build/apps/grip ['{}' '{"real_solve": "given"}' ...]
"""
import argparse
import copy
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
EXAMPLES, GOLDEN = os.path.join(ROOT, "schemas", "examples"), os.path.join(ROOT, "tests", "golden")
sys.path.insert(0, os.path.join(ROOT, "bench", "peers"))
from prandtl_ccx import mesh  # noqa: E402

J2 = {"law": "j2_plasticity", "yield_stress": 2000.0, "hardening": {"linear": 20000.0}}


def load(folder, name):
    with open(os.path.join(folder, name + ".json")) as f:
        return json.load(f)


def plastic(body, **changes):
    body["material"].update(J2, **changes)


def pressed_and_released(scene, release=True, steps=4):
    scene.pop("steps", None)
    scene["stages"] = [{"steps": steps, "factors": {"main": 1}}]
    if release:
        scene["stages"].append({"steps": 4, "factors": {"main": 0}})
    return scene


def hertz_bbar(law):
    scene = load(EXAMPLES, "hertz")
    scene["body"]["element"] = "q4_bbar"  # plastic flow keeps the volume: q4 would lock
    if law:
        plastic(scene["body"])
    return pressed_and_released(scene)


def punch(law, h=0.2, steps=10):
    nodes, elements, sets = mesh(h, 1)
    sets["near"] = [n for n, (x, y) in enumerate(nodes) if y > -1e-9 and x <= 2.5 + 1e-9]
    del sets["punch"]
    material = {"young": 1000, "poisson": 0.3}
    if law:
        material.update({"law": "j2_plasticity", "yield_stress": 1})
    edge = [{"type": "segment", "from": [-2, 0], "to": [1, 0]}, {"type": "segment", "from": [1, 0], "to": [1, 5]}]
    return {"body": {"model": "continuum", "kinematics": "linear", "analysis": "plane_strain", "element": "q4_bbar",
                     "material": material, "mesh": {"nodes": [list(p) for p in nodes], "elements": elements,
                                                    "sets": sets},
                     "contact_set": "near",
                     "supports": [{"set": "left", "fix": ["x"]}, {"set": "right", "fix": ["x"]},
                                  {"set": "bottom", "fix": ["x", "y"]}]},
            "obstacles": [{"name": "punch", "shape": {"type": "profile", "pieces": edge},
                           "motion": {"translation": [0, -0.1]}}],
            "steps": steps, "solver": {"contact": {"method": "cev"}}}


def scenes():
    """(name, plastic scene, its elastic twin or None)."""
    out = [("J2Contact (hertz, q4_bbar, 4 + 4)", hertz_bbar(True), hertz_bbar(False))]
    friction = hertz_bbar(True)
    friction["obstacles"][0]["friction"] = 0.3
    out.append(("J2Contact, mu 0.3", friction, None))
    softer = hertz_bbar(True)
    softer["body"]["material"]["yield_stress"] = 1000.0
    out.append(("J2Contact, yield 1000 MPa", softer, None))
    eight = pressed_and_released(hertz_bbar(True), release=False, steps=8)
    out.append(("J2Contact, 8 steps, no release", eight, None))
    out.append(("golden hertz-j2-bbar", load(GOLDEN, "hertz-j2-bbar"), None))
    out.append(("golden hertz-j2-finite", load(GOLDEN, "hertz-j2-finite"), None))
    out.append(("hertz-j2-finite 4 + 4", pressed_and_released(load(GOLDEN, "hertz-j2-finite")), None))
    sphere = load(EXAMPLES, "hertz-sphere")
    plastic(sphere["body"])
    out.append(("hertz-sphere (axisymmetric q8) 4 + 4", pressed_and_released(sphere), None))
    t6 = load(EXAMPLES, "hertz-t6")
    plastic(t6["body"])
    out.append(("hertz-t6 4 + 4", pressed_and_released(t6), None))
    cylinders = load(EXAMPLES, "two-cylinders")
    for body in cylinders["bodies"]:
        body["element"] = "q4_bbar"
        plastic(body)
    out.append(("two cylinders, both q4_bbar, 4 + 4", pressed_and_released(cylinders), None))
    out.append(("Prandtl's punch by contact, b/5, 10 steps", punch(True), punch(False)))
    return out


def run(grip, scene, contact, work):
    scene = copy.deepcopy(scene)
    scene.setdefault("solver", {}).setdefault("contact", {}).update(contact)
    path, out = os.path.join(work, "scene.json"), os.path.join(work, "result.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    done = subprocess.run([grip, "solve", path, "--out", out, "--threads", "1"], capture_output=True, text=True)
    if done.returncode:
        return None
    with open(out) as f:
        result = json.load(f)
    steps = result["steps"]
    return {"solves": result["effects"]["counters"]["equilibrium_solves"],
            "newton": sum(s.get("newton_iterations", 0) for s in steps),
            "converged": all(s["converged"] for s in steps)}


def cell(r, twin=None):
    if r is None:
        return "failed"
    text = f"{r['solves']} / {r['newton']}" + ("" if r["converged"] else " (not converged)")
    return text + (f" ({r['solves'] / twin['solves']:.2f} x)" if twin else "")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--grip", required=True)
    ap.add_argument("contacts", nargs="*", default=["{}"], help="solver.contact variants (JSON)")
    args = ap.parse_args()
    contacts = [json.loads(c) for c in args.contacts]
    print(f"load average (1 min) at the start: {os.getloadavg()[0]:.2f}")
    print("| scene | linear elastic | " + " | ".join(json.dumps(c) for c in contacts) + " |")
    print("|---|---|" + "---|" * len(contacts))
    totals = [[0, 0] for _ in contacts]
    with tempfile.TemporaryDirectory() as work:
        for name in os.listdir(EXAMPLES):  # the meshes scenes name by file
            if name.endswith(".msh"):
                shutil.copy(os.path.join(EXAMPLES, name), work)
        for name, scene, twin in scenes():
            elastic = run(args.grip, twin, {}, work) if twin else None
            rows = [run(args.grip, scene, c, work) for c in contacts]
            for t, r in zip(totals, rows):
                if r:
                    t[0] += r["solves"]
                    t[1] += r["newton"]
            print(f"| {name} | {cell(elastic) if twin else ''} | " + " | ".join(cell(r, elastic) for r in rows) + " |",
                  flush=True)
    print("| all | | " + " | ".join(f"{s} / {n}" for s, n in totals) + " |")
    print(f"load average (1 min) at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
