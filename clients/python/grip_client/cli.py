"""Command line: python3 -m grip_client [--url URL] [--token TOKEN] COMMAND ...

Exit codes: 0 success, 1 a job failed (or was dismissed), 2 usage or HTTP error (the
problem's pointers are printed on stderr).
"""

from __future__ import annotations

import argparse
import copy
import csv
import io
import itertools
import json
import os
import sys
import tarfile
from typing import Any, Dict, List, Optional, Sequence, TextIO

from .client import Client, GripError, Job, gmsh_references

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2

# What to do about a failure, by its kind (schemas/result.schema.json#/definitions/failure).
FAILURE_ADVICE = {
    "friction_limit": "the load exceeds what friction can hold: no finer load steps help",
    "no_equilibrium": "no static equilibrium carries this load: add a support or a contact",
    "newton_diverged": "an equilibrium solve diverged: try more, smaller load steps",
    "invalid_state": "the body reached a state its model refuses: try smaller load steps",
    "contact_budget": "raise solver.contact.max_iterations, or take smaller load steps",
    "contact_stalled": "the contact iteration stalled: try smaller load steps or another method",
    "check_failed": "the solution failed the solver's own physics checks: take smaller load steps",
    "missed_contact": "a node outside the contact set entered an obstacle: widen body.contact_set",
    "penalty_inexact": "penalty could not meet the tolerance: raise its stiffness or use cev",
    "job_limit": "a limit of this service: ask its operator, or split the scene",
    "dismissed": "the job was dismissed",
    "invalid_scene": "the stored scene could not be read: submit it again",
    "exception": "an internal error: report it with the job id",
}


def failure_text(failure: Optional[dict], reason: str = "") -> str:
    """`reason [kind: advice]` for a failure member (or the reason alone without one)."""
    if not failure:
        return reason
    kind = failure.get("kind", "")
    advice = FAILURE_ADVICE.get(kind)
    return f"{failure.get('message', reason)} [{kind}" + (f": {advice}]" if advice else "]")

PAPER_SCENES = ("sheet-stretching", "beam-on-cylinder")
# File stems of the paper's figures (documented in clients/python/README.md).
PAPER_NAMES = {
    "sheet-stretching": {"shapes": "fig4_sheet_shapes", "strain": "fig5_sheet_strain",
                         "contact_normal": "sheet_normal_stress",
                         "contact_friction": "sheet_friction_stress",
                         "convergence": "sheet_convergence"},
    "beam-on-cylinder": {"shapes": "fig6_beam_shapes", "contact_normal": "fig7_beam_normal_stress",
                         "contact_friction": "fig8_beam_friction_stress",
                         "load_deflection": "fig9_beam_load_deflection",
                         "convergence": "beam_convergence"},
}


class UsageError(Exception):
    pass


# ---- scene paths (sweep --set) and result paths (sweep --output)


def split_path(path: str) -> List[Any]:
    """'obstacles.0.friction', 'obstacles[0].friction' or '/obstacles/0/friction' as keys,
    with list indexes (negative allowed) as ints."""
    if path.startswith("/"):
        parts = [p.replace("~1", "/").replace("~0", "~") for p in path[1:].split("/")]
    else:
        parts = [p for p in path.replace("[", ".").replace("]", "").split(".") if p != ""]
    if not parts:
        raise UsageError(f"empty path '{path}'")
    out: List[Any] = []
    for p in parts:
        try:
            out.append(int(p))
        except ValueError:
            out.append(p)
    return out


def get_path(doc: Any, path: str) -> Any:
    cur = doc
    for key in split_path(path):
        if isinstance(cur, list) and isinstance(key, int):
            cur = cur[key]
        elif isinstance(cur, dict):
            cur = cur[str(key)]
        else:
            raise KeyError(path)
    return cur


def set_path(doc: Any, path: str, value: Any) -> None:
    """Sets a value in a scene, creating missing objects on the way."""
    keys = split_path(path)
    cur = doc
    for i, key in enumerate(keys):
        last = i == len(keys) - 1
        if isinstance(cur, list):
            if not isinstance(key, int) or not -len(cur) <= key < len(cur):
                raise UsageError(f"--set {path}: no element {key} in a list of {len(cur)}")
            if last:
                cur[key] = value
            else:
                cur = cur[key]
        elif isinstance(cur, dict):
            key = str(key)
            if last:
                cur[key] = value
            else:
                if key not in cur or not isinstance(cur[key], (dict, list)):
                    cur[key] = {}
                cur = cur[key]
        else:
            raise UsageError(f"--set {path}: '{key}' is below a value, not an object")


def split_values(text: str) -> List[str]:
    """Comma-separated values; commas inside brackets, braces or quotes do not split."""
    out, depth, quote, cur = [], 0, False, ""
    for ch in text:
        if ch == '"':
            quote = not quote
        elif not quote and ch in "[{":
            depth += 1
        elif not quote and ch in "]}":
            depth -= 1
        if ch == "," and depth == 0 and not quote:
            out.append(cur)
            cur = ""
        else:
            cur += ch
    out.append(cur)
    return [v.strip() for v in out]


def parse_value(text: str) -> Any:
    try:
        return json.loads(text)
    except ValueError:
        return text


def parse_set(spec: str):
    path, eq, values = spec.partition("=")
    if not eq or not path or values == "":
        raise UsageError(f"--set expects path=v1,v2,...; got '{spec}'")
    split_path(path)
    return path, [parse_value(v) for v in split_values(values)]


# ---- output helpers


def fmt(v: Any) -> str:
    if isinstance(v, float):
        return f"{v:.6g}"
    if v is None:
        return ""
    if isinstance(v, (dict, list)):
        return json.dumps(v)
    return str(v)


def table(rows: Sequence[Sequence[Any]], header: Sequence[str], out: TextIO) -> None:
    cells = [list(header)] + [[fmt(v) for v in r] for r in rows]
    widths = [max(len(r[i]) for r in cells) for i in range(len(header))]
    for k, r in enumerate(cells):
        out.write("  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip() + "\n")
        if k == 0:
            out.write("  ".join("-" * w for w in widths) + "\n")


def progress_bar(done: int, total: int, width: int = 20) -> str:
    if total <= 0:
        return "[" + "?" * width + "]"
    filled = min(width, round(width * done / total))
    return "[" + "#" * filled + "." * (width - filled) + f"] {done}/{total}"


def load_scene(client: Client, spec: str) -> dict:
    """A scene from a file, or `example:NAME` from the server's built-in examples."""
    if spec.startswith("example:"):
        return client.example(spec[len("example:"):])
    try:
        with open(spec, "r", encoding="utf-8") as f:
            return json.load(f)
    except OSError as e:
        raise UsageError(f"cannot read {spec}: {e.strerror}") from None
    except ValueError as e:
        raise UsageError(f"{spec} is not JSON: {e}") from None


def scene_meshes(client: Client, spec: str, scene: dict, given: Sequence[str]) -> Dict[str, Any]:
    """The .msh files for a scene's gmsh references {"file": NAME}, by NAME: each --mesh PATH
    under its base name; a name without one is read as grip solve reads it, beside the scene
    file (example:NAME: the server's example file)."""
    meshes: Dict[str, Any] = {}
    for path in given:
        if not os.path.isfile(path):
            raise UsageError(f"--mesh {path}: no such file")
        meshes[os.path.basename(path)] = path
    used = set()
    for pointer, ref in gmsh_references(scene):
        name = ref["file"]
        if name in meshes or os.path.basename(name) in meshes:
            used.add(name if name in meshes else os.path.basename(name))
            continue
        if spec.startswith("example:"):
            meshes[name] = client.example_mesh(name)
        else:
            beside = os.path.join(os.path.dirname(os.path.abspath(spec)), name)
            if not os.path.isfile(beside):
                raise UsageError(f"{spec}: {pointer}/file names '{name}': give it with --mesh "
                                 f"(not found beside the scene either)")
            meshes[name] = beside
    unused = sorted(set(os.path.basename(p) for p in given) - used)
    if unused:
        raise UsageError(f"--mesh {', '.join(unused)}: the scene names no such file (its gmsh "
                         f"references: {', '.join(r['file'] for _, r in gmsh_references(scene)) or 'none'})")
    return meshes


def load_scene_with_meshes(client: Client, spec: str, given: Sequence[str]) -> dict:
    """The scene with its gmsh mesh files uploaded (POST /v1/meshes) and named by their ids."""
    scene = load_scene(client, spec)
    meshes = scene_meshes(client, spec, scene, given)
    return client.with_meshes(scene, meshes) if meshes else scene


# ---- watching


class Watcher:
    """Prints a job's events: a live line per iteration (step, m, ||v||, stick/slip/open) with a
    progress bar over the steps; a summary line per step. On a terminal the live line is
    rewritten in place; otherwise each iteration gets its own line."""

    def __init__(self, out: TextIO, total_steps: int, live: Optional[bool] = None,
                 raw: bool = False):
        self.out = out
        self.total = total_steps
        self.live = out.isatty() if live is None else live
        self.raw = raw
        self.done = 0
        self.dirty = False

    def _line(self, text: str, final: bool) -> None:
        if self.live:
            self.out.write("\r\x1b[K" + text + ("\n" if final else ""))
            self.dirty = not final
        else:
            self.out.write(text + "\n")
        self.out.flush()

    def event(self, ev) -> None:
        if self.raw:
            self.out.write(json.dumps(dict(ev.data, id=ev.id)) + "\n")
            self.out.flush()
            return
        d = ev.data
        bar = progress_bar(self.done, self.total)
        if ev.type == "iteration":
            self._line(f"{bar}  step {d.get('step')}  m {d.get('m'):>3}  pass {d.get('pass', 1)}"
                       f"  ||v|| {d.get('v2', 0.0):.3e}  stick {d.get('stick')}  slip "
                       f"{d.get('slip')}  open {d.get('open')}", final=False)
        elif ev.type == "step_started":
            self._line(f"{bar}  step {d.get('step')} started, load factor "
                       f"{d.get('load_factor', 0):.4g}", final=False)
        elif ev.type == "step_finished":
            if d.get("converged"):
                self.done += 1
            status = ("converged" if d.get("converged")
                      else f"FAILED: {failure_text(d.get('failure'), d.get('reason', ''))}")
            self._line(f"{progress_bar(self.done, self.total)}  step {d.get('step')} {status}: "
                       f"{d.get('contact_iterations')} contact iterations, "
                       f"{d.get('newton_iterations')} Newton, {d.get('seconds', 0):.3g} s",
                       final=True)
        elif ev.type == "job_finished":
            self._line(f"job finished: {self.done} of {self.total} steps", final=True)
        elif ev.type == "job_failed":
            failure = d.get("failure") or {}
            what = "job dismissed" if failure.get("kind") == "dismissed" else "job failed"
            self._line(f"{what}: {failure_text(failure, d.get('reason', ''))}", final=True)


def watch_job(job: Job, out: TextIO, raw: bool = False, live: Optional[bool] = None) -> int:
    doc = job.doc if job.doc.get("steps") is not None else job.status()
    w = Watcher(out, int(doc.get("steps") or 0), live=live, raw=raw)
    last_type = None
    for ev in job.events():
        w.event(ev)
        last_type = ev.type
    if last_type == "job_finished":
        return EXIT_OK
    return EXIT_FAILED


# ---- commands


def cmd_submit(client: Client, args, out: TextIO) -> int:
    scene = load_scene_with_meshes(client, args.scene, args.mesh)
    job = client.submit(scene, idempotency_key=args.key)
    if args.json:
        out.write(json.dumps(job.doc, indent=2) + "\n")
    else:
        out.write(job.id + ("  (replayed: the same Idempotency-Key was used before)"
                            if job.replayed else "") + "\n")
    out.flush()
    if args.watch:
        return watch_job(job, out)
    return EXIT_OK


def cmd_watch(client: Client, args, out: TextIO) -> int:
    job = client.job(args.id)
    return watch_job(job, out, raw=args.json)


def describe_job(doc: dict) -> List[List[Any]]:
    keys = ["jobID", "status", "progress", "message", "steps", "steps_completed", "nodes", "created",
            "started", "finished", "iterations", "solve_seconds", "attempts"]
    rows = [[k, doc[k]] for k in keys if k in doc]
    if doc.get("failure"):
        rows.append(["failure", failure_text(doc["failure"])])
    return rows


def cmd_status(client: Client, args, out: TextIO) -> int:
    doc = client.job(args.id).doc
    if args.json:
        out.write(json.dumps(doc, indent=2) + "\n")
    else:
        for k, v in describe_job(doc):
            out.write(f"{k:14} {fmt(v)}\n")
    return EXIT_FAILED if doc.get("status") in ("failed", "dismissed") else EXIT_OK


def cmd_list(client: Client, args, out: TextIO) -> int:
    jobs = list(client.jobs(status=args.status, limit=args.limit))
    if args.json:
        out.write(json.dumps([j.doc for j in jobs], indent=2) + "\n")
        return EXIT_OK
    rows = [[j.id, j.doc.get("status"), f"{j.doc.get('steps_completed', 0)} of {j.doc.get('steps')}",
             (j.doc.get("failure") or {}).get("kind", ""), j.doc.get("created"), j.doc.get("message")]
            for j in jobs]
    table(rows, ["jobID", "status", "steps", "failure", "created", "message"], out)
    return EXIT_OK


def _safe_extract(data: bytes, dest: str) -> List[str]:
    names = []
    with tarfile.open(fileobj=io.BytesIO(data), mode="r:") as tar:
        for m in tar.getmembers():
            target = os.path.realpath(os.path.join(dest, m.name))
            if not m.isfile() or not target.startswith(os.path.realpath(dest) + os.sep):
                continue
            os.makedirs(os.path.dirname(target), exist_ok=True)
            with tar.extractfile(m) as src, open(target, "wb") as dst:
                dst.write(src.read())
            names.append(target)
    return names


CSV_TABLES = ("steps", "nodes", "elements", "contact_points", "master_points", "history")


def cmd_result(client: Client, args, out: TextIO) -> int:
    job = Job(client, args.id)
    formats = ["json", "csv", "vtk"] if args.format == "all" else args.format.split(",")
    bad = [f for f in formats if f not in ("json", "csv", "vtk")]
    if bad:
        raise UsageError(f"--format: unknown {', '.join(bad)} (json, csv, vtk or all)")
    os.makedirs(args.output, exist_ok=True)
    written: List[str] = []
    if "json" in formats:
        result = job.result()
        path = os.path.join(args.output, "result.json")
        with open(path, "w", encoding="utf-8") as f:
            json.dump(result, f, indent=1)
        written.append(path)
    if "csv" in formats:
        for t in CSV_TABLES:
            text = job.result("csv", table=t)
            if not text.strip():
                continue
            path = os.path.join(args.output, t + ".csv")
            with open(path, "w", encoding="utf-8", newline="") as f:
                f.write(text)
            written.append(path)
    if "vtk" in formats:
        written += _safe_extract(job.result("vtk"), os.path.join(args.output, "vtk"))
    for p in written:
        out.write(p + "\n")
    return EXIT_OK


def cmd_dismiss(client: Client, args, out: TextIO) -> int:
    doc = Job(client, args.id).dismiss()
    out.write(f"{doc.get('jobID', args.id)}  {doc.get('status')}  {doc.get('message', '')}\n")
    return EXIT_OK


def _history_for(job: Job, result: dict):
    if any(s.get("history") for s in result.get("steps", [])):
        return None
    return job.convergence().get("iterations", [])


def cmd_plot(client: Client, args, out: TextIO) -> int:
    try:
        from . import plots
        plots.pyplot()
    except ImportError as e:
        out.flush()
        sys.stderr.write(f"plot needs matplotlib ({e}). On Debian: apt-get install "
                         "python3-matplotlib, then run /usr/bin/python3, or a venv made with "
                         "--system-site-packages; elsewhere: pip install 'grip-client[plot]'. "
                         "Every other command works without it.\n")
        return EXIT_USAGE
    if args.paper:
        return plot_paper(client, args, out, plots)
    if not args.id:
        raise UsageError("plot needs a job ID, or --paper")
    job = client.job(args.id)
    result = job.result()
    written = plots.write_all(result, args.output, history=_history_for(job, result),
                              step=args.step)
    for name, (path, _) in written.items():
        out.write(f"{path}  ({name})\n")
    return EXIT_OK


def paper_highlights(scene: str, written: Dict[str, Any]) -> Dict[str, Any]:
    """What the figures show, in numbers: where the strain peaks on the sheet, where the
    frictional stress changes sign on the beam."""
    h: Dict[str, Any] = {}
    if "strain" in written:
        d = written["strain"][1]
        h["strain_peak"] = d["peak"]
        h["strain_at_pole"] = d["major_strain"][0]
    if "contact_friction" in written:
        d = written["contact_friction"][1]
        h["friction_sign_changes"] = {name: e["sign_changes"] for name, e in d["obstacles"].items()}
    if "load_deflection" in written:
        d = written["load_deflection"][1]
        h["end_deflection"] = {"load": d["load"][-1], "vertical": d["deflection"][-1],
                               "horizontal": d["horizontal"][-1]}
    return h


def plot_paper(client: Client, args, out: TextIO, plots) -> int:
    """Runs the paper's two scenes (the server's built-in examples) and writes every figure."""
    jobs = {}
    for name in PAPER_SCENES:
        jobs[name] = client.submit(client.example(name))
        out.write(f"{name}: job {jobs[name].id}\n")
    out.flush()
    summary: Dict[str, Any] = {}
    code = EXIT_OK
    for name, job in jobs.items():
        doc = job.wait()
        if doc.get("status") != "successful":
            out.write(f"{name}: {doc.get('status')}: {doc.get('message', '')}\n")
            code = EXIT_FAILED
            continue
        result = job.result()
        written = plots.write_all(result, args.output, names=PAPER_NAMES[name],
                                  history=_history_for(job, result))
        summary[name] = {"job": job.id,
                         "files": {k: os.path.basename(p) for k, (p, _) in written.items()},
                         "highlights": paper_highlights(name, written)}
        for fig, (path, _) in written.items():
            out.write(f"{path}  ({name}: {fig})\n")
    with open(os.path.join(args.output, "paper-summary.json"), "w", encoding="utf-8") as f:
        json.dump(summary, f, indent=2)
    for name, s in summary.items():
        for k, v in s["highlights"].items():
            out.write(f"{name}: {k}: {json.dumps(v)}\n")
    return code


def cmd_sweep(client: Client, args, out: TextIO) -> int:
    base = load_scene_with_meshes(client, args.scene, args.mesh)  # each mesh uploaded once
    sets = [parse_set(s) for s in args.set]
    outputs = args.output or ["summary.contact_iterations", "summary.newton_iterations"]
    variants = []
    for combo in itertools.product(*[values for _, values in sets]):
        scene = copy.deepcopy(base)
        for (path, _), value in zip(sets, combo):
            set_path(scene, path, value)
        variants.append((combo, scene))
    jobs = []
    for combo, scene in variants:
        jobs.append((combo, client.submit(scene)))
        sys.stderr.write(f"submitted {jobs[-1][1].id}: "
                         + ", ".join(f"{p}={fmt(v)}" for (p, _), v in zip(sets, combo)) + "\n")
    rows = []
    code = EXIT_OK
    for combo, job in jobs:
        doc = job.wait()
        values: List[Any] = []
        if doc.get("status") == "successful":
            result = job.result()
            for o in outputs:
                try:
                    values.append(get_path(result, o))
                except (KeyError, IndexError, TypeError):
                    values.append(None)
        else:
            code = EXIT_FAILED
            values = [None] * len(outputs)
        rows.append(list(combo) + [doc.get("status")] + values + [job.id])
    header = [p for p, _ in sets] + ["status"] + outputs + ["jobID"]
    if args.json:
        out.write(json.dumps([dict(zip(header, r)) for r in rows], indent=2) + "\n")
    else:
        table(rows, header, out)
    if args.csv:
        with open(args.csv, "w", encoding="utf-8", newline="") as f:
            w = csv.writer(f)
            w.writerow(header)
            for r in rows:
                w.writerow([json.dumps(v) if isinstance(v, (dict, list)) else v for v in r])
    return code


def cmd_study(client: Client, args, out: TextIO) -> int:
    scene = load_scene_with_meshes(client, args.scene, args.mesh)
    accuracy = None
    if args.accuracy:
        name, _, relative = args.accuracy.partition("=")
        accuracy = {"output": name, "relative": float(relative or 0)}
    doc = client.study(scene, levels=args.levels, outputs=args.output or None,
                       tolerances=args.tolerance or None, methods=args.method or None,
                       accuracy=accuracy)
    sys.stderr.write(f"study {doc['id']}: {len(doc['levels'])} levels\n")
    doc = client.wait_study(doc["id"], timeout=args.timeout)
    if args.json:
        out.write(json.dumps(doc, indent=2) + "\n")
    else:
        names = [q["name"] for q in doc["quantities"]]
        rows = []
        for k, level in enumerate(doc["levels"]):
            row: List[Any] = [level["level"], level.get("method"), level.get("tolerance"),
                              level["nodes"], level.get("seconds"), level["status"]]
            for q in doc["quantities"]:
                row += [q["values"][k], q["estimated_error"][k]]
            rows.append(row)
        table(rows, ["level", "method", "tolerance", "nodes", "seconds", "status"]
              + [h for n in names for h in (n, n + " error")], out)
        out.write("\n")
        summary = []

        def job_name(c: Optional[dict]) -> Optional[str]:
            if not c:
                return None
            parts = [f"level {c['level']}"] + [f"{c[k]}" for k in ("method", "tolerance") if k in c]
            return ", ".join(parts) + f" ({c['seconds']:.3g} s)"
        for q in doc["quantities"]:
            cheapest = [job_name(c["level"]) for c in q["cheapest"]]
            summary.append([q["name"], q["order"], q["extrapolated"], q["asymptotic"]] + cheapest)
        table(summary, ["quantity", "order", "extrapolated", "asymptotic"]
              + [f"cheapest < {100 * b:g} %" for b in doc["thresholds"]], out)
        answer = doc.get("answer")
        if answer:
            out.write("\n")
            if answer.get("reached"):
                out.write(f"accurate: {doc['accuracy']['output']} = {answer['value']} at level "
                          f"{answer['level']} (job {answer['job']}), estimated error "
                          f"{answer['estimated_error']:.3g}\n")
            else:
                out.write(f"not reached: {answer.get('reason')}\n")
    return EXIT_OK if doc["status"] == "successful" else EXIT_FAILED


# ---- parser


def build_parser() -> argparse.ArgumentParser:
    common = argparse.ArgumentParser(add_help=False)
    common.add_argument("--url", default=argparse.SUPPRESS,
                        help="service URL (default: $GRIP_URL, else http://127.0.0.1:8080)")
    common.add_argument("--token", default=argparse.SUPPRESS,
                        help="bearer token (default: $GRIP_TOKEN)")
    # `grip-client` when installed (console script), else the module.
    prog = "grip-client" if os.path.basename(sys.argv[0]) == "grip-client" else "python3 -m grip_client"
    p = argparse.ArgumentParser(prog=prog, parents=[common],
                                description="Submit, follow, fetch and plot grip jobs.",
                                epilog="Exit codes: 0 success, 1 a job failed, 2 usage or HTTP "
                                       "error (with the problem's pointers).")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True

    s = sub.add_parser("submit", parents=[common], help="submit a scene, print the job ID")
    s.add_argument("scene", help="scene JSON file, or example:NAME (a built-in example)")
    s.add_argument("--watch", action="store_true", help="then follow it as `watch` does")
    s.add_argument("--key", help="Idempotency-Key: resubmitting with it returns the same job")
    s.add_argument("--json", action="store_true", help="print the job document")
    s.add_argument("--mesh", action="append", default=[], metavar="PART.msh",
                   help="a gmsh mesh the scene names as {\"file\": \"PART.msh\"}: uploaded (POST "
                        "/v1/meshes) and named by its id (repeatable; default: the files beside "
                        "the scene)")
    s.set_defaults(func=cmd_submit)

    s = sub.add_parser("watch", parents=[common],
                       help="follow a job's events: a live line per iteration, a bar per step")
    s.add_argument("id")
    s.add_argument("--json", action="store_true", help="print the events as NDJSON")
    s.set_defaults(func=cmd_watch)

    s = sub.add_parser("status", parents=[common], help="a job's status, progress and timings")
    s.add_argument("id")
    s.add_argument("--json", action="store_true", help="print the job document")
    s.set_defaults(func=cmd_status)

    s = sub.add_parser("list", parents=[common], help="jobs, newest first (follows paging)")
    s.add_argument("--status", choices=["accepted", "running", "successful", "failed", "dismissed"])
    s.add_argument("--limit", type=int, default=50, help="at most this many jobs (default 50)")
    s.add_argument("--json", action="store_true")
    s.set_defaults(func=cmd_list)

    s = sub.add_parser("result", parents=[common], help="download a job's result into a folder")
    s.add_argument("id")
    s.add_argument("-o", "--output", required=True, help="folder")
    s.add_argument("--format", default="json",
                   help="json, csv, vtk, a comma list, or all (default json)")
    s.set_defaults(func=cmd_result)

    s = sub.add_parser("dismiss", parents=[common], help="cancel a job, or remove a finished one")
    s.add_argument("id")
    s.set_defaults(func=cmd_dismiss)

    s = sub.add_parser("plot", parents=[common],
                       help="PNG figures of a job (needs matplotlib), or --paper")
    s.add_argument("id", nargs="?")
    s.add_argument("-o", "--output", required=True, help="folder for the PNG files")
    s.add_argument("--step", type=int, help="step for strain and contact stress (default: last)")
    s.add_argument("--paper", action="store_true",
                   help="run the paper's two scenes and write Figs. 4-9 and the convergence plots")
    s.set_defaults(func=cmd_plot)

    s = sub.add_parser("sweep", parents=[common],
                       help="submit variants of a scene, wait, tabulate outputs")
    s.add_argument("scene", help="scene JSON file, or example:NAME")
    s.add_argument("--set", action="append", required=True, metavar="PATH=V1,V2,...",
                   help="scene path (obstacles.0.friction or /obstacles/0/friction) and values; "
                        "several --set give every combination")
    s.add_argument("--output", action="append", metavar="PATH",
                   help="result path to tabulate, e.g. steps.-1.nodes.-1.w (repeatable; default "
                        "summary.contact_iterations and summary.newton_iterations)")
    s.add_argument("--mesh", action="append", default=[], metavar="PART.msh",
                   help="a gmsh mesh the scene names, uploaded once for every variant (as submit)")
    s.add_argument("--csv", help="also write the table as CSV")
    s.add_argument("--json", action="store_true", help="print the table as JSON")
    s.set_defaults(func=cmd_sweep)

    s = sub.add_parser("study", parents=[common],
                       help="a refinement study: the scene's outputs on finer meshes, their "
                            "observed order, Richardson value and what each accuracy costs")
    s.add_argument("scene", help="scene JSON file (with outputs), or example:NAME")
    s.add_argument("--levels", type=int, default=3, help="mesh levels, divisions x 2^j (default 3)")
    s.add_argument("--tolerance", type=float, action="append", metavar="T",
                   help="a contact tolerance to run every level at (repeatable)")
    s.add_argument("--method", action="append", choices=["cev", "uzawa", "penalty", "ssn"],
                   help="a contact method to run every level with (repeatable)")
    s.add_argument("--accuracy", metavar="NAME=RELATIVE",
                   help="refine until output NAME's estimated error is below RELATIVE "
                        "(instead of --levels)")
    s.add_argument("--output", action="append", metavar="NAME",
                   help="one of the scene's outputs to study (repeatable; default all)")
    s.add_argument("--mesh", action="append", default=[], metavar="PART.msh",
                   help="a gmsh mesh the scene names, uploaded first (as submit)")
    s.add_argument("--timeout", type=float, help="give up waiting after this many seconds")
    s.add_argument("--json", action="store_true", help="print the study's document")
    s.set_defaults(func=cmd_study)
    return p


def main(argv: Optional[Sequence[str]] = None, out: Optional[TextIO] = None,
         err: Optional[TextIO] = None) -> int:
    out = out or sys.stdout
    err = err or sys.stderr
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as e:  # argparse: 2 on usage errors, 0 on --help
        return int(e.code or 0)
    client = Client(getattr(args, "url", None), token=getattr(args, "token", None))
    try:
        return args.func(client, args, out)
    except UsageError as e:
        err.write(f"usage error: {e}\n")
        return EXIT_USAGE
    except GripError as e:
        out.flush()
        err.write(f"error: {e.describe()}\n")
        return EXIT_USAGE
    except KeyboardInterrupt:
        err.write("interrupted\n")
        return 130
