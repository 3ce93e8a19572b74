#!/usr/bin/env python3
"""Issue 39's benchmark of the geometrically exact beam: the strip on a drum
(schemas/examples/strip-on-drum-beam.json: E 1e4, nu 0.3, L 3, t 0.1, R 1, F 1, friction 0.2,
20 steps) as a reissner_beam, against the same strip as a plane-stress continuum (q9, finite
strain), each run by `grip solve --threads 1` (build/apps/grip) `--repeat` times.

Prints a markdown page (machine, load, date, then one row per case: the fastest run's solve
wall time and CPU time as grip reports them, the whole process' wall time, Newton iterations,
factorizations, and the tip deflection at F = 1) and writes it to
bench/results/reissner-beam.md with --write. Usage (from the repository root):
    bench/reissner_beam.py [--repeat N] [--write]
"""
import argparse, copy, datetime, json, os, platform, re, subprocess, tempfile, time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GRIP = os.path.join(ROOT, "build", "apps", "grip")
EXAMPLE = os.path.join(ROOT, "schemas", "examples", "strip-on-drum-beam.json")


def continuum(beam, along, across):
    """The example's strip as a plane-stress q9 continuum (width 1: the beam's E and G)."""
    s = copy.deepcopy(beam)
    s["name"] = f"strip-on-drum-continuum-{along}x{across}"
    s["body"] = {
        "model": "continuum", "kinematics": "finite", "analysis": "plane_stress", "element": "q9",
        "thickness": 1, "material": {"young": 1e4, "poisson": 0.3, "law": "saint_venant_kirchhoff"},
        "mesh": {"rectangle": {"origin": [0, -0.05], "size": [3, 0.1], "divisions": [along, across]}},
        "contact_set": "bottom", "supports": [{"set": "left", "fix": ["x", "y"]}],
        "loads": [{"set": "right", "traction": [0, -10]}]}
    return s


def tip(result):
    last = result["steps"][-1]
    if result["scene"]["body"]["model"] == "reissner_beam":
        return -last["nodes"][-1]["w"]
    mid = [n for n in last["nodes"] if abs(n["x"] - n["ux"] - 3) < 1e-6 and abs(n["y"] - n["uy"]) < 1e-6]
    return -mid[0]["uy"]


def run(scene, repeat):
    best = None
    with tempfile.TemporaryDirectory() as tmp:
        path, out = os.path.join(tmp, "scene.json"), os.path.join(tmp, "result.json")
        with open(path, "w") as f:
            json.dump(scene, f)
        for _ in range(repeat):
            start = time.perf_counter()
            p = subprocess.run([GRIP, "solve", path, "--out", out, "--threads", "1"], capture_output=True, text=True)
            wall = time.perf_counter() - start
            text = p.stdout + p.stderr
            m = re.search(r"solve ([0-9.]+) s \(cpu ([0-9.]+)\)", text)
            n = re.search(r"(\d+) Newton iterations, (\d+) factorizations", text)
            row = {"solve": float(m.group(1)), "cpu": float(m.group(2)), "process": wall,
                   "newton": int(n.group(1)), "factorizations": int(n.group(2))}
            if best is None or row["solve"] < best["solve"]:
                with open(out) as f:
                    row["tip"] = tip(json.load(f))
                best = row
    return best


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--repeat", type=int, default=10)
    ap.add_argument("--write", action="store_true")
    args = ap.parse_args()
    with open(EXAMPLE) as f:
        beam = json.load(f)
    b2 = copy.deepcopy(beam)
    b2["body"]["element"], b2["body"]["mesh"]["elements"] = "b2", 60
    b2["body"]["loads"][0]["node"] = 60
    cases = [("reissner_beam, 30 b3 (the example)", beam, args.repeat),
             ("reissner_beam, 60 b2", b2, args.repeat),
             ("continuum q9 75 x 2", continuum(beam, 75, 2), 3),
             ("continuum q9 150 x 4", continuum(beam, 150, 4), 1)]
    commit = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True).stdout.strip()
    cpu = next((l.split(":", 1)[1].strip() for l in open("/proc/cpuinfo") if l.startswith("model name")), platform.processor())
    load_before = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    rows = [(name, run(scene, repeat)) for name, scene, repeat in cases]
    load_after = subprocess.run(["uptime"], capture_output=True, text=True).stdout.strip()
    lines = [
        "# The strip on a drum as a geometrically exact beam (issue 39)",
        "",
        "    bench/reissner_beam.py --repeat 10 --write",
        "",
        f"Date {datetime.datetime.utcnow():%Y-%m-%d %H:%M} UTC, commit {commit}, {cpu} ({os.cpu_count()} hardware threads), "
        "`grip solve --threads 1`, the fastest of the runs (10 for the beams, 3 and 1 for the continua).",
        f"Load (uptime) before: `{load_before}`; after: `{load_after}`.",
        "",
        "| case | solve s | solve cpu s | whole process s | Newton | factorizations | tip deflection at F = 1 |",
        "|---|---|---|---|---|---|---|",
    ]
    for name, r in rows:
        lines.append(f"| {name} | {r['solve']:.3f} | {r['cpu']:.3f} | {r['process']:.3f} | {r['newton']} | "
                     f"{r['factorizations']} | {r['tip']:.5f} |")
    page = "\n".join(lines) + "\n"
    print(page)
    if args.write:
        path = os.path.join(ROOT, "bench", "results", "reissner-beam.md")
        notes = ""
        if os.path.exists(path):
            notes = open(path).read().partition("\n## Notes\n")[2]
        with open(path, "w") as f:
            f.write(page + ("\n## Notes\n" + notes if notes else ""))


if __name__ == "__main__":
    main()
