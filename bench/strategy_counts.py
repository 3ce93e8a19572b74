#!/usr/bin/env python3
"""What accuracy costs, in counts: `grip solve` on the shipped example scenes with each contact
strategy at the scenes' own tolerance (1e-8), tabulated as real equilibrium solves and Newton
iterations per load step. Counts do not depend on the machine's load; times do, and are left
to grip_bench (bench/results/strategies.md).

    python3 bench/strategy_counts.py [--grip build/apps/grip] > bench/results/strategy_counts.md
"""

import argparse
import datetime
import json
import os
import platform
import subprocess
import sys
import tempfile

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SCENES = ["beam-on-cylinder", "sheet-stretching", "hertz", "cattaneo-mindlin", "sliding-block"]
STRATEGIES = [  # (label, changes to solver.contact)
    ("cev (default)", {}),
    ("cev, tau passes", {"friction_loop": "passes"}),
    ("ssn", {"method": "ssn"}),
    ("uzawa", {"method": "uzawa"}),
    ("penalty", {"method": "penalty"}),
]


def run(grip, scene_name, changes, work):
    with open(os.path.join(REPO, "schemas", "examples", scene_name + ".json")) as f:
        scene = json.load(f)
    scene.setdefault("solver", {}).setdefault("contact", {}).update(changes)
    scene["output"] = {"steps": "last", "fields": []}
    path = os.path.join(work, "scene.json")
    out = os.path.join(work, "result.json")
    with open(path, "w") as f:
        json.dump(scene, f)
    subprocess.run([grip, "solve", path, "--out", out], cwd=REPO, capture_output=True,
                   timeout=1800)
    with open(out) as f:
        return json.load(f)["summary"]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", default=os.path.join(REPO, "build", "apps", "grip"))
    args = ap.parse_args()
    load_start = os.getloadavg()
    started = datetime.datetime.now(datetime.timezone.utc)
    rows = []
    with tempfile.TemporaryDirectory() as work:
        for scene in SCENES:
            for label, changes in STRATEGIES:
                s = run(args.grip, scene, changes, work)
                steps = max(s["steps"], 1)
                status = "ok" if s["completed"] else s["reason"][:120].replace("|", "/")
                rows.append((scene, label, s["contact_iterations"] / steps,
                             s["newton_iterations"] / steps, s["steps"], status))
                print(f"{scene} {label}: done", file=sys.stderr)
    load_end = os.getloadavg()
    print("# What accuracy costs, in counts (bench/strategy_counts.py)\n")
    print(f"{started:%Y-%m-%d %H:%M} UTC, {platform.machine()}, {os.cpu_count()} cores; load "
          f"average {load_start[0]:.1f} at the start, {load_end[0]:.1f} at the end (counts do not "
          "depend on it). Each example scene as shipped (tolerance 1e-8 of the body's length), "
          "with solver.contact changed as the strategy column says, each with its default budget "
          "of real solves per step (solver.contact.max_iterations); a step over it is cut, and "
          "a run that cannot go on stops with the status given.\n")
    print("| scene | strategy | real solves / step | Newton it. / step | steps | status |")
    print("|---|---|---:|---:|---:|---|")
    for r in rows:
        print(f"| {r[0]} | {r[1]} | {r[2]:.2f} | {r[3]:.2f} | {r[4]} | {r[5]} |")


if __name__ == "__main__":
    main()
