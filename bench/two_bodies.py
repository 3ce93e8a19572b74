#!/usr/bin/env python3
"""Issue 19's benchmark: two deformable bodies beside the same geometry against a rigid tool.

Runs `grip solve` (build/apps/grip) on schemas/examples/two-cylinders.json and
block-on-foundation.json, and on their one-body counterparts (the lower cylinder replaced by a
rigid circle, the foundation by a rigid flat), each `--repeat` times, and prints a markdown
table: strategy, dofs, contact unknowns, real solves, Newton iterations, seconds and CPU
seconds (of the run with the fewest seconds) and seconds per real solve. Usage:
bench/two_bodies.py [--repeat N] [--methods cev,uzawa,...] [--threads N] (from the repository root).
"""
import argparse, copy, json, resource, subprocess, tempfile, os

from scaling import fewest_half_disc_divisions  # the fewest divisions the half-disc generator accepts

def one_body(scene, obstacle):
    s = copy.deepcopy(scene)
    body = s.pop("bodies")[0]
    body.pop("name")
    s.pop("contacts")
    s["body"] = body
    s["obstacles"] = [obstacle]
    return s

# Strategies as the scene's solver.contact (the same names as two_bodies_held_test.cpp).
METHODS = {
    "cev": {"method": "cev"},
    "cev_paper": {"method": "cev", "loop": "paper"},
    "cev_paper_n3": {"method": "cev", "loop": "paper", "acceleration": {"n": 3}},
    "ssn": {"method": "ssn"},
    "uzawa": {"method": "uzawa"},
    "penalty": {"method": "penalty"},
}

def with_method(scene, method):
    s = copy.deepcopy(scene)
    contact = s.setdefault("solver", {}).setdefault("contact", {})
    contact.pop("method", None)
    contact.update(METHODS[method])
    return s

def run(grip, scene, repeat, threads):
    """The result of the repeat with the fewest seconds, with its process's CPU seconds."""
    best = None
    with tempfile.TemporaryDirectory() as d:
        path, out = os.path.join(d, "scene.json"), os.path.join(d, "result.json")
        json.dump(scene, open(path, "w"))
        for _ in range(repeat):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run([grip, "solve", path, "--out", out, "--threads", str(threads)], check=False, capture_output=True)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            r = json.load(open(out))
            r["cpu"] = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            if best is None or r["summary"]["seconds"] < best["summary"]["seconds"]:
                best = r
    return best

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--grip", default="build/apps/grip")
    ap.add_argument("--methods", default="cev", help="comma-separated: " + ",".join(METHODS))
    ap.add_argument("--only", default="", help="run only the cases whose name contains this")
    ap.add_argument("--threads", type=int, default=1, help="grip solve --threads (1: the bodies one after another)")
    a = ap.parse_args()
    cyl = json.load(open("schemas/examples/two-cylinders.json"))
    block = json.load(open("schemas/examples/block-on-foundation.json"))
    # The block as slave: it is the body that stays when the foundation becomes rigid.
    block_slave = copy.deepcopy(block)
    block_slave["contacts"] = [{"slave": "block.bottom", "master": "foundation.top"}]
    # Refined: elements of 0.025 mm within 0.8 mm of the poles (a/h 14 and 21 at the two steps).
    fine = copy.deepcopy(cyl)
    for b in fine["bodies"]:
        disc = b["mesh"]["half_disc"]
        disc["refine"]["size"] = 0.025
        disc["divisions"] = fewest_half_disc_divisions(disc["radius"], 0.025, disc["refine"]["extent"])
    rigid_lower = {"name": "lower", "shape": {"type": "circle", "centre": [0, -10], "radius": 10}}
    cases = [
        ("two cylinders (E 200/70 GPa)", cyl),
        ("upper cylinder on a rigid cylinder", one_body(cyl, rigid_lower)),
        ("two cylinders, refined (h 0.025 mm)", fine),
        ("upper cylinder on a rigid cylinder, refined", one_body(fine, rigid_lower)),
        ("block on foundation (foundation slave)", block),
        ("block on foundation (block slave)", block_slave),
        ("block on a rigid flat", one_body(block_slave, {"name": "flat", "shape": {"type": "segment", "from": [10, 0], "to": [-10, 0]}})),
    ]
    print("| case | strategy | dofs | contact unknowns | real solves | Newton iterations | seconds | CPU seconds | ms per real solve |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, scene in [c for c in cases if a.only in c[0]]:
        for method in a.methods.split(","):
            r = run(a.grip, with_method(scene, method), a.repeat, a.threads)
            e, s = r["effects"], r["summary"]
            dofs = sum(b["dofs"] for b in e["bodies"]) if "bodies" in e else 2 * max(max(c) for c in r["mesh"]["cells"]) + 2
            done = "" if s["completed"] else " (failed: " + s["reason"][:60] + ")"
            print(f"| {name} | {method}{done} | {dofs} | {e['contact_unknowns']} | {s['contact_iterations']} | {s['newton_iterations']} | "
                  f"{s['seconds']:.4f} | {r['cpu']:.3f} | {1000 * s['seconds'] / max(1, s['contact_iterations']):.2f} |", flush=True)

if __name__ == "__main__":
    main()
