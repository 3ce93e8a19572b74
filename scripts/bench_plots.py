#!/usr/bin/python3
"""Plots and the markdown table of the strategy benchmark (tests/bench/strategy_bench.cpp).

Reads bench/results/strategies.csv and scenes.csv (written by grip_bench) and writes, next to
them:
  error_vs_time_<scene>.png    error against median wall time on the middle mesh, a line per
                               strategy (penalty: one line over its stiffness factors)
  iterations_vs_tolerance.png  contact iterations against tolerance on the middle mesh
  strategies.md                per scene, every strategy at tolerance 1e-8 on the middle mesh,
                               and the issue's targets, met or not, with the measured numbers

Needs Debian's python3-matplotlib (run with /usr/bin/python3).
usage: bench_plots.py [RESULTS_DIR]
"""
import csv
import math
import os
import sys
import textwrap

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

TABLE_TOLERANCE = 1e-8
REFERENCE_STRATEGY = "cev-inf"
DEFAULT_STRATEGY = "cev"  # the default: Coulomb's bound moving with p inside the iteration
SCENE_TITLES = {
    "beam": "beam on cylinder (paper 4.2)",
    "sheet": "sheet stretching (paper 4.1)",
    "hertz": "Hertz",
    "cattaneo-mindlin": "Cattaneo-Mindlin",
}
# The time targets: the paper's scenes as shipped (cev's default, tolerance 1e-8).
TIME_TARGETS = [("beam", "40", 0.020), ("sheet", "30", 0.030)]
ERROR_KEYS = ["err_force", "err_peak", "err_point", "err_extent"]
# The quantity each scene's error-against-time plot shows (the table has all of them): the
# beam's peak nodal contact stress grows under refinement (a concentrated force at the edge of
# the wrapped zone), so its tip deflection is shown instead.
PRIMARY = {"beam": "point", "sheet": "peak", "hertz": "peak", "cattaneo-mindlin": "extent"}
QUANTITY_KEYS = ["force", "peak", "point", "extent"]


def number(text):
    try:
        return float(text)
    except (TypeError, ValueError):
        return math.nan


def finite(x):
    return x is not None and not math.isnan(x)


def read_rows(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    for r in rows:
        for key in ("tolerance", "median_seconds", "min_seconds", "median_cpu_seconds", "max_contact_error",
                    "contact_seconds",
                    "equilibrium_seconds", "overhead_ratio", *QUANTITY_KEYS, *ERROR_KEYS):
            r[key] = number(r[key])
        for key in ("mesh_level", "runs", "contact_iterations", "inner_iterations", "tau_passes", "cuts",
                    "newton_iterations", "factorizations"):
            r[key] = int(r[key])
        r["step_solves"] = [int(x) for x in r["step_solves"].split(";") if x]
    return rows


def read_scenes(path):
    if not os.path.exists(path):
        return {}
    with open(path, newline="") as f:
        return {r["scene"]: r for r in csv.DictReader(f)}


def largest_error(r, keys=ERROR_KEYS):
    values = [r[k] for k in keys if finite(r[k])]
    return max(values) if values else math.nan


def answered(r):
    """The run gave an answer to measure (every step ended)."""
    return r["status"] in ("ok", "not reached")


def middle_level(rows, scene):
    levels = sorted({r["mesh_level"] for r in rows if r["scene"] == scene})
    return levels[len(levels) // 2]


def solver_errors(rows, scene, level):
    """Error of each row against the same mesh's tightest-tolerance default run: what the
    contact solver itself leaves, with the discretization taken out."""
    same = [r for r in rows if r["scene"] == scene and r["mesh_level"] == level and r["strategy"] == REFERENCE_STRATEGY
            and r["status"] == "ok"]
    if not same:
        return {}
    ref = min(same, key=lambda r: r["tolerance"])
    out = {}
    for r in rows:
        if r["scene"] != scene or r["mesh_level"] != level or not answered(r):
            continue
        errs = [abs(r[k] - ref[k]) / abs(ref[k]) for k in QUANTITY_KEYS
                if finite(r[k]) and finite(ref[k]) and ref[k] != 0]
        out[id(r)] = max(errs) if errs else math.nan
    return out


def style(strategy, family):
    """Colour by acceleration level, dashes for the paper's loop, markers for the others."""
    colours = {"inf": "tab:blue", "auto": "tab:green", "2": "tab:olive", "4": "tab:orange", "8": "tab:red",
               "12": "tab:purple", "16": "tab:brown"}
    if family == "uzawa":
        return dict(color="black", linestyle="-", marker="s")
    if family == "penalty":
        return dict(color="tab:gray", linestyle="-", marker="D")
    if family in ("cev", "ssn"):  # cev's default (Coulomb inside the iteration), the semismooth Newton
        return dict(color="tab:cyan" if family == "cev" else "tab:pink", linestyle="-", marker="o")
    parts = strategy.split("-")
    level = parts[1]
    kw = dict(color=colours.get(level, "tab:cyan"), linestyle="--" if family == "cev-paper" else "-",
              marker="o" if "warmup" not in parts else "^")
    return kw


def plot_error_vs_time(rows, scenes, scene, out_dir):
    level = middle_level(rows, scene)
    mine = [r for r in rows if r["scene"] == scene and r["mesh_level"] == level]
    if not mine:
        return None
    mesh = mine[0]["mesh"]
    solver_err = solver_errors(rows, scene, level)
    fig, axes = plt.subplots(1, 2, figsize=(11, 4.4), sharex=True)
    primary = PRIMARY.get(scene, "force")
    described = [q for q in scenes.get(scene, {}).get("quantities", "").split("; ") if q.startswith(primary + ":")]
    name = described[0].split(": ", 1)[1].split(" (")[0] if described else primary
    panels = [(axes[0], lambda r: r["err_" + primary], f"error of the {name} against the reference"),
              (axes[1], lambda r: solver_err.get(id(r), math.nan),
               "largest relative error against this mesh at the tightest tolerance")]
    strategies = []
    for r in mine:
        if r["strategy"] not in strategies and r["family"] != "penalty":
            strategies.append(r["strategy"])
    for ax, error, title in panels:
        for strategy in strategies:
            pts = sorted((r for r in mine if r["strategy"] == strategy and answered(r)), key=lambda r: -r["tolerance"])
            # Zero error: the reference run itself, which a log axis cannot show.
            pts = [(r["median_seconds"], error(r)) for r in pts if finite(error(r)) and error(r) > 0]
            if not pts:
                continue
            kw = style(strategy, mine[[r["strategy"] for r in mine].index(strategy)]["family"])
            ax.plot([p[0] for p in pts], [p[1] for p in pts], label=strategy, markersize=3.5, linewidth=1,
                    **kw)
        # Penalty: one line over its stiffness factors at the table's tolerance (its answer does
        # not depend on the contact tolerance); the factors where Newton failed are listed.
        pen = sorted((r for r in mine if r["family"] == "penalty" and r["tolerance"] == TABLE_TOLERANCE),
                     key=lambda r: float(r["strategy"].split("-k")[1]))
        ok = [r for r in pen if answered(r) and finite(error(r)) and error(r) > 0]
        if ok:
            ax.plot([r["median_seconds"] for r in ok], [error(r) for r in ok], label="penalty (k factor)",
                    markersize=4, linewidth=1, **style("penalty", "penalty"))
            for r in ok:
                ax.annotate(r["strategy"].split("-k")[1], (r["median_seconds"], max(error(r), 1e-16)), fontsize=6,
                            xytext=(3, 3), textcoords="offset points", color="tab:gray")
        failed = [r["strategy"].split("-k")[1] for r in pen if not answered(r)]
        if failed:
            ax.text(0.02, 0.02, "penalty failed (Newton) at k factor " + ", ".join(failed), transform=ax.transAxes,
                    fontsize=7, color="tab:gray")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("median wall time per run (s)")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="major", alpha=0.3)
    axes[0].set_ylabel("relative error")
    handles, labels = axes[0].get_legend_handles_labels()
    fig.legend(handles, labels, loc="center right", fontsize=6.5, ncol=1, frameon=False)
    reference = scenes.get(scene, {}).get("reference", "")
    title = (f"{SCENE_TITLES.get(scene, scene)}: mesh {mesh}, tolerances 1e-2 to 1e-10 along each line. "
             f"Reference: {reference}")
    fig.suptitle(textwrap.fill(title, 170), fontsize=8)
    fig.subplots_adjust(left=0.07, right=0.80, bottom=0.12, top=0.84, wspace=0.22)
    path = os.path.join(out_dir, f"error_vs_time_{scene}.png")
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path


def plot_iterations(rows, scene_names, out_dir):
    n = len(scene_names)
    cols = 2 if n > 1 else 1
    nrows = (n + cols - 1) // cols
    fig, axes = plt.subplots(nrows, cols, figsize=(11, 3.6 * nrows), squeeze=False)
    handles = {}
    for i, scene in enumerate(scene_names):
        ax = axes[i // cols][i % cols]
        level = middle_level(rows, scene)
        mine = [r for r in rows if r["scene"] == scene and r["mesh_level"] == level and r["family"] != "penalty"]
        strategies = []
        for r in mine:
            if r["strategy"] not in strategies:
                strategies.append(r["strategy"])
        for strategy in strategies:
            pts = sorted((r for r in mine if r["strategy"] == strategy and r["status"] != "skipped"),
                         key=lambda r: -r["tolerance"])
            if not pts:
                continue
            kw = style(strategy, pts[0]["family"])
            reached = [r for r in pts if r["status"] == "ok"]
            line, = ax.plot([r["tolerance"] for r in reached], [max(r["contact_iterations"], 1) for r in reached],
                            markersize=3.5, linewidth=1, **kw)
            handles.setdefault(strategy, line)
            # Runs that stopped short: their count is a lower bound (hollow marker).
            short = [r for r in pts if r["status"] != "ok"]
            if short:
                ax.plot([r["tolerance"] for r in short], [max(r["contact_iterations"], 1) for r in short],
                        linestyle="none", marker=kw["marker"], markerfacecolor="none", color=kw["color"],
                        markersize=5)
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.invert_xaxis()
        ax.set_title(f"{SCENE_TITLES.get(scene, scene)}, mesh {mine[0]['mesh'] if mine else ''}", fontsize=9)
        ax.set_xlabel("contact tolerance (relative)")
        ax.set_ylabel("contact iterations (real solves)")
        ax.grid(True, which="major", alpha=0.3)
    for j in range(n, nrows * cols):
        axes[j // cols][j % cols].axis("off")
    fig.legend(list(handles.values()), list(handles.keys()), loc="center right", fontsize=6.5, frameon=False)
    fig.suptitle("Contact iterations against tolerance (hollow: stopped short of the tolerance, a lower bound)",
                 fontsize=9)
    fig.subplots_adjust(left=0.07, right=0.82, bottom=0.12 / nrows, top=1 - 0.1 / nrows, wspace=0.25,
                        hspace=0.4)
    path = os.path.join(out_dir, "iterations_vs_tolerance.png")
    fig.savefig(path, dpi=80)
    plt.close(fig)
    return path


def fmt(x, digits=3):
    if not finite(x):
        return "-"
    if x == 0:
        return "0"
    if abs(x) >= 1e4 or abs(x) < 1e-3:
        return f"{x:.{digits - 1}e}"
    return f"{x:.{digits}g}"


def find(rows, scene, level, strategy, tol):
    for r in rows:
        if r["scene"] == scene and r["mesh_level"] == level and r["strategy"] == strategy and r["tolerance"] == tol:
            return r
    return None


def find_mesh(rows, scene, mesh, strategy, tol):
    for r in rows:
        if r["scene"] == scene and r["mesh"] == mesh and r["strategy"] == strategy and r["tolerance"] == tol:
            return r
    return None


def uzawa_target(rows, scene, level):
    """cev auto needs at most a tenth of uzawa's contact iterations at 1e-8."""
    cev = find(rows, scene, level, "cev-auto-exact", TABLE_TOLERANCE)
    uz = find(rows, scene, level, "uzawa", TABLE_TOLERANCE)
    if not cev or not uz or cev["status"] != "ok":
        return "not measured" if not cev or not uz else "not met", (
            f"cev auto: {cev['status'] if cev else 'no row'}" + (f" ({cev['reason']})" if cev and cev["reason"] else ""))
    if uz["status"] == "ok":
        ratio = cev["contact_iterations"] / max(uz["contact_iterations"], 1)
        return ("met" if ratio <= 0.1 else "not met"), (
            f"cev auto {cev['contact_iterations']}, uzawa {uz['contact_iterations']} contact iterations "
            f"(ratio {ratio:.3f})")
    # uzawa stopped short: compare over the steps it worked on (its count is a lower bound).
    steps = len(uz["step_solves"])
    cev_same = sum(cev["step_solves"][:steps])
    ratio = cev_same / max(uz["contact_iterations"], 1)
    return ("met" if ratio <= 0.1 else "not met"), (
        f"uzawa did not reach 1e-8 ({uz['status']}: {uz['reason']}); over its first {steps} step(s) it used "
        f"{uz['contact_iterations']} contact iterations, cev auto {cev_same} over the same steps "
        f"(ratio <= {ratio:.3f}; {cev['contact_iterations']} over all {len(cev['step_solves'])} steps)")


def write_markdown(rows, scenes, scene_names, out_dir, plots):
    lines = ["# What accuracy costs: contact strategies compared", "",
             "Written by `scripts/bench_plots.py` from `strategies.csv` (run `scripts/bench.sh`). "
             "Every number is measured on this machine by `grip_bench` (tests/bench/strategy_bench.cpp); "
             "times are medians over at least five runs on one core, failures are run once.", "",
             "Strategy names: `cev-<n>[-<epsilon source>][-paper]`: the contact error vector scheme with "
             "acceleration level n (`inf`: a Cholesky solve with the active block; `auto`: from the condition "
             "number), eps_1 from the exact eigenvalue or the eq. 30 warm-up, the default inner loop or (`-paper`) "
             "the paper's literal loop (capped at 300 contact iterations per step, increments not cut); `uzawa` "
             "(same cap); `penalty-k<f>`: penalty with k = f x the largest diagonal stiffness entry.", "",
             "Status: `ok` every step reached the tolerance; `not reached` every step ended but the contact error "
             "stayed above it (penalty); `limit` a step used its contact iterations; `failed` another failure "
             "(reason in the CSV); `timeout` the run's wall-time limit; `skipped` not run (a looser tolerance timed "
             "out).", ""]
    lines += ["## Targets", "", "| target | result | measured |", "|---|---|---|"]
    for scene in scene_names:
        level = middle_level(rows, scene)
        verdict, text = uzawa_target(rows, scene, level)
        mesh = next(r["mesh"] for r in rows if r["scene"] == scene and r["mesh_level"] == level)
        lines.append(f"| {scene} (mesh {mesh}): cev auto <= 1/10 of uzawa's contact iterations at 1e-8 | "
                     f"{verdict} | {text} |")
    for scene in scene_names:
        level = middle_level(rows, scene)
        r = find(rows, scene, level, DEFAULT_STRATEGY, TABLE_TOLERANCE)
        if not r:
            continue
        ratio = r["overhead_ratio"]
        verdict = "met" if finite(ratio) and ratio <= 3 else "not met" if finite(ratio) else "not measured"
        lines.append(f"| {scene} (mesh {r['mesh']}): overhead ratio <= 3 (cev, 1e-8) | {verdict} | "
                     f"{fmt(ratio)}: contact solves {fmt(r['contact_seconds'] * 1e3)} ms, one equilibrium solve per "
                     f"step with the converged forces {fmt(r['equilibrium_seconds'] * 1e3)} ms "
                     f"({r['contact_iterations']} solves over {len(r['step_solves'])} steps) |")
    for scene, mesh, limit in TIME_TARGETS:
        r = find_mesh(rows, scene, mesh, DEFAULT_STRATEGY, TABLE_TOLERANCE)
        if not r:
            continue
        t = r["median_seconds"]
        verdict = "met" if r["status"] == "ok" and t <= limit else "not met"
        lines.append(f"| the paper's {scene} scene ({mesh} elements, as shipped) under {limit * 1e3:.0f} ms | "
                     f"{verdict} | median {fmt(t * 1e3)} ms (min {fmt(r['min_seconds'] * 1e3)} ms, CPU "
                     f"{fmt(r['median_cpu_seconds'] * 1e3)} ms) over {r['runs']} runs |")
        if scene == "beam":
            per_step = r["contact_iterations"] / max(len(r["step_solves"]), 1)
            lines.append(f"| the paper's beam: at most 4 real solves per step | "
                         f"{'met' if per_step <= 4 else 'not met'} | {per_step:.2f} |")
        ssn = find_mesh(rows, scene, mesh, "ssn", TABLE_TOLERANCE)
        if ssn:
            faster = r["status"] == "ok" and r["median_cpu_seconds"] <= ssn["median_cpu_seconds"]
            lines.append(f"| the paper's {scene} scene: cev at least as fast as ssn | "
                         f"{'met' if faster else 'not met'} | CPU {fmt(r['median_cpu_seconds'] * 1e3)} ms against "
                         f"{fmt(ssn['median_cpu_seconds'] * 1e3)} ms ({ssn['status']}) |")
    lines.append("")
    for scene in scene_names:
        level = middle_level(rows, scene)
        mine = [r for r in rows if r["scene"] == scene and r["mesh_level"] == level
                and r["tolerance"] == TABLE_TOLERANCE]
        if not mine:
            continue
        info = scenes.get(scene, {})
        lines += [f"## {SCENE_TITLES.get(scene, scene)}: mesh {mine[0]['mesh']}, tolerance 1e-8", "",
                  f"Quantities: {info.get('quantities', '')}. Reference: {info.get('reference', '')}. "
                  f"Meshes: {info.get('meshes', '')}.", ""]
        if plots.get(scene):
            lines += [f"![error against time]({os.path.basename(plots[scene])})", ""]
        lines += ["| strategy | status | median ms | contact iter. | inner iter. | Newton iter. | factorizations "
                  "| err force | err peak | err point | err extent | overhead ratio |",
                  "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"]
        for r in mine:
            status = r["status"]
            if status not in ("ok", "skipped") and r["reason"]:
                status += f" ({r['reason'][:90]})"
            lines.append(
                f"| {r['strategy']} | {status} | {fmt(r['median_seconds'] * 1e3)} | {r['contact_iterations']} | "
                f"{r['inner_iterations']} | {r['newton_iterations']} | {r['factorizations']} | "
                f"{fmt(r['err_force'])} | {fmt(r['err_peak'])} | {fmt(r['err_point'])} | {fmt(r['err_extent'])} | "
                f"{fmt(r['overhead_ratio'])} |")
        lines.append("")
    lines += ["![contact iterations against tolerance](iterations_vs_tolerance.png)", ""]
    machine = os.path.join(out_dir, "machine.txt")
    if os.path.exists(machine):
        with open(machine) as f:
            lines += ["## Where it was measured", "", "```", f.read().rstrip(), "```", ""]
    path = os.path.join(out_dir, "strategies.md")
    with open(path, "w") as f:
        f.write("\n".join(lines))
    return path


def main():
    out_dir = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "bench", "results")
    rows = read_rows(os.path.join(out_dir, "strategies.csv"))
    scenes = read_scenes(os.path.join(out_dir, "scenes.csv"))
    scene_names = []
    for r in rows:
        if r["scene"] not in scene_names:
            scene_names.append(r["scene"])
    order = list(SCENE_TITLES)
    scene_names.sort(key=lambda s: order.index(s) if s in order else len(order))
    plots = {scene: plot_error_vs_time(rows, scenes, scene, out_dir) for scene in scene_names}
    written = [p for p in plots.values() if p]
    written.append(plot_iterations(rows, scene_names, out_dir))
    written.append(write_markdown(rows, scenes, scene_names, out_dir, plots))
    for p in written:
        print("wrote", os.path.normpath(p))


if __name__ == "__main__":
    main()
