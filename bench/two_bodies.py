#!/usr/bin/env python3
"""Issue 19's benchmark: two deformable bodies beside the same geometry against a rigid tool.

Runs `grip solve` (build/apps/grip) on schemas/examples/two-cylinders.json and
block-on-foundation.json, and on their one-body counterparts (the lower cylinder replaced by a
rigid circle, the foundation by a rigid flat), each `--repeat` times, and prints a markdown
table: dofs, contact unknowns, real solves, Newton iterations, seconds (best of the repeats)
and seconds per real solve. Usage: bench/two_bodies.py [--repeat N] (from the repository root).
"""
import argparse, copy, json, subprocess, tempfile, os

from scaling import fewest_half_disc_divisions  # the fewest divisions the half-disc generator accepts

def one_body(scene, obstacle):
    s = copy.deepcopy(scene)
    body = s.pop("bodies")[0]
    body.pop("name")
    s.pop("contacts")
    s["body"] = body
    s["obstacles"] = [obstacle]
    return s

def run(grip, scene, repeat):
    best = None
    with tempfile.TemporaryDirectory() as d:
        path, out = os.path.join(d, "scene.json"), os.path.join(d, "result.json")
        json.dump(scene, open(path, "w"))
        for _ in range(repeat):
            subprocess.run([grip, "solve", path, "--out", out], check=True, capture_output=True)
            r = json.load(open(out))
            if best is None or r["summary"]["seconds"] < best["summary"]["seconds"]:
                best = r
    return best

def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--grip", default="build/apps/grip")
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
    print("| case | dofs | contact unknowns | real solves | Newton iterations | seconds | ms per real solve |")
    print("|---|---|---|---|---|---|---|")
    for name, scene in cases:
        r = run(a.grip, scene, a.repeat)
        e, s = r["effects"], r["summary"]
        dofs = sum(b["dofs"] for b in e["bodies"]) if "bodies" in e else 2 * max(max(c) for c in r["mesh"]["cells"]) + 2
        print(f"| {name} | {dofs} | {e['contact_unknowns']} | {s['contact_iterations']} | {s['newton_iterations']} | "
              f"{s['seconds']:.4f} | {1000 * s['seconds'] / max(1, s['contact_iterations']):.2f} |")

if __name__ == "__main__":
    main()
