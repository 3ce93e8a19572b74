#!/usr/bin/python3
"""Contact on exactly incompressible rubber against the same scene with a compressible body.

The bulging block (docs/verification.md#bulging-block: a Mooney-Rivlin quarter block, bulk
1e3 x shear, `incompressibility: exact`, pressed 10 % by a frictionless plate, the top's x held)
on n x n q9 and the shipped O-ring (schemas/examples/seal-o-ring.json) with `exact`, each beside
the same scene with a compressible neo-Hookean body of the same shear modulus (nu 0.3). Prints
one markdown row per scene and binary: CPU seconds, real solves, Newton iterations, moves of the
pressures, cuts, and the real solves over the compressible body's.

    bench/exact_incompressibility.py --grip build/apps/grip [--before OTHER_GRIP] [--runs 3]
"""
import argparse
import json
import os
import resource
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
COMPRESSIBLE = {"law": "neo_hookean", "young": 2.6, "poisson": 0.3}  # shear modulus 1


def block(n, exact):
    material = {"law": "mooney_rivlin", "c10": 0.4, "c01": 0.1, "bulk": 1000.0} if exact else COMPRESSIBLE
    return {
        "body": {"model": "continuum", "element": "q9", "kinematics": "finite",
                 "incompressibility": "exact" if exact else "none", "material": material,
                 "mesh": {"rectangle": {"size": [1, 1], "divisions": [n, n]}}, "contact_set": "top",
                 "supports": [{"set": "left", "fix": ["x"]}, {"set": "bottom", "fix": ["y"]},
                              {"set": "top", "fix": ["x"]}]},
        "obstacles": [{"name": "plate", "shape": {"type": "segment", "from": [-1, 1], "to": [3, 1]},
                       "motion": {"translation": [0, -0.1]}}],
        "steps": 4, "solver": {"contact": {"method": "cev", "tolerance": 1e-9}}}


def o_ring(exact):
    with open(os.path.join(HERE, "..", "schemas", "examples", "seal-o-ring.json")) as f:
        j = json.load(f)
    if exact:
        j["body"]["incompressibility"] = "exact"
    else:
        j["body"]["material"] = COMPRESSIBLE
    return j


def run(grip, scene, runs):
    """Least CPU seconds of `runs` runs and the counts of the last."""
    with tempfile.TemporaryDirectory() as tmp:
        path, out = os.path.join(tmp, "scene.json"), os.path.join(tmp, "result.json")
        with open(path, "w") as f:
            json.dump(scene, f)
        best = None
        for _ in range(runs):
            before = resource.getrusage(resource.RUSAGE_CHILDREN)
            subprocess.run([grip, "solve", path, "--out", out, "--threads", "1"], check=True,
                           stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            after = resource.getrusage(resource.RUSAGE_CHILDREN)
            cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
            best = cpu if best is None else min(best, cpu)
        with open(out) as f:
            r = json.load(f)
    steps = r["steps"]
    return {"cpu": best, "solves": r["effects"]["counters"]["equilibrium_solves"],
            "newton": sum(s.get("newton_iterations", 0) for s in steps),
            "moves": sum(s.get("multiplier_updates", 0) for s in steps),
            "cuts": sum(s.get("cuts", 0) for s in steps), "steps": len(steps)}


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--grip", required=True)
    ap.add_argument("--before", help="another grip to run beside it")
    ap.add_argument("--runs", type=int, default=3)
    args = ap.parse_args()
    scenes = [(f"bulging block q9 {n} x {n}", block(n, True), block(n, False)) for n in (4, 8, 16)]
    scenes.append(("O-ring q9 (seal-o-ring.json)", o_ring(True), o_ring(False)))
    binaries = [("before", args.before)] if args.before else []
    binaries.append(("after" if args.before else "grip", args.grip))
    print(f"load average (1 min) at the start: {os.getloadavg()[0]:.2f}")
    print("| scene | grip | cpu s | real solves | Newton | moves of the pressures | cuts | compressible: real solves, cpu s | ratio |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, exact, soft in scenes:
        base = run(args.grip, soft, args.runs)
        for label, grip in binaries:
            r = run(grip, exact, args.runs)
            print(f"| {name} | {label} | {r['cpu']:.2f} | {r['solves']} | {r['newton']} | {r['moves']} | {r['cuts']} | "
                  f"{base['solves']}, {base['cpu']:.2f} | {r['solves'] / base['solves']:.2f} x |")
        sys.stdout.flush()
    print(f"load average (1 min) at the end: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
