"""PNG plots of a grip result (matplotlib, Agg backend; imported only by `plot`).

Each figure function takes the result dict (GET /v1/jobs/{id}/result) and returns
`(figure, data)`: `data` holds exactly the series handed to matplotlib, so that a test (or a
user) can compare them with the result's numbers.

    convergence(result)        ||v||_2 against contact iteration, log scale, one colour per step
    shapes(result)             deformed shapes at several steps with the obstacles (Figs. 4, 6)
    strain(result)             strain along the sheet (membrane; Fig. 5)
    contact_stress(result, "normal" | "friction")   contact stress along the body (Figs. 7, 8)
    load_deflection(result)    load against end deflection (bodies with loads; Fig. 9)
    punch_force(result)        the moving tool's force against its travel (punch stretching)
    radial_strains(result)     meridional, hoop and thickness strains over the radius at
                               several punch depths (axisymmetric membrane)

`write_all(result, out_dir, prefix)` writes every figure that applies and returns
{name: path}.
"""

from __future__ import annotations

import math
import os
from typing import Dict, List, Optional, Sequence, Tuple

_plt = None


def pyplot():
    """matplotlib.pyplot with the Agg backend (no display needed)."""
    global _plt
    if _plt is None:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt

        _plt = plt
    return _plt


# ---- reading the result


def body_model(result: dict) -> str:
    return result.get("scene", {}).get("body", {}).get("model", "")


def units(result: dict) -> Dict[str, str]:
    u = result.get("scene", {}).get("units") or {}
    return {"force": u.get("force", ""), "length": u.get("length", "")}


def _unit(text: str) -> str:
    return f" [{text}]" if text else ""


def stress_unit(result: dict) -> str:
    u = units(result)
    if u["force"] and u["length"]:
        if (u["force"], u["length"]) == ("N", "mm"):
            return "MPa"
        return f"{u['force']}/{u['length']}²"
    return ""


def field_steps(result: dict) -> List[dict]:
    """Steps whose fields (nodes) were recorded."""
    return [s for s in result.get("steps", []) if s.get("nodes")]


def find_step(result: dict, step: Optional[int]) -> dict:
    """The step numbered `step` (1-based, as in the result), or the last one with fields."""
    steps = field_steps(result)
    if not steps:
        raise ValueError("the result has no step with node fields")
    if step is None:
        return steps[-1]
    for s in steps:
        if s.get("step") == step:
            return s
    raise ValueError(f"the result has no fields for step {step}")


def displacement_keys(result: dict) -> Tuple[str, str]:
    """Names of the node displacement columns: (u, w) for a beam, (ux, uy) otherwise."""
    steps = field_steps(result)
    row = steps[0]["nodes"][0] if steps else {}
    return ("u", "w") if "w" in row and "ux" not in row else ("ux", "uy")


def node_xy(step: dict) -> Tuple[List[float], List[float]]:
    return [n["x"] for n in step["nodes"]], [n["y"] for n in step["nodes"]]


def initial_xy(result: dict, step: dict) -> Tuple[List[float], List[float]]:
    """Undeformed node positions: deformed minus displacement."""
    ku, kv = displacement_keys(result)
    return ([n["x"] - n[ku] for n in step["nodes"]], [n["y"] - n[kv] for n in step["nodes"]])


def body_ranges(result: dict, step: dict) -> List[Tuple[Optional[str], int, int]]:
    """(name, first node, node count) of each body: the result's `bodies[]` in a scene of
    several bodies (their rows follow each other in `nodes`), else one nameless body."""
    bodies = result.get("bodies") or []
    if not bodies:
        return [(None, 0, len(step["nodes"]))]
    return [(b["name"], b["first_node"], b["nodes"]) for b in bodies]


def contact_names(result: dict) -> List[str]:
    """What contact points pair with: the obstacles, then the contact pairs between bodies."""
    scene = result.get("scene", {})
    names = [o["name"] for o in scene.get("obstacles", [])]
    names += [c["name"] for c in scene.get("contacts", []) if c.get("name") and c["name"] not in names]
    return names


def characteristic_length(result: dict) -> float:
    """The body length the contact tolerance is relative to (the mesh length; else the extent
    of the undeformed nodes)."""
    mesh = result.get("scene", {}).get("body", {}).get("mesh", {})
    if isinstance(mesh.get("length"), (int, float)):
        return float(mesh["length"])
    steps = field_steps(result)
    if not steps:
        return 1.0
    x0, y0 = initial_xy(result, steps[0])
    return max(max(x0) - min(x0), max(y0) - min(y0)) or 1.0


def tolerance(result: dict) -> Optional[float]:
    """The absolute ||v||_2 tolerance: solver.contact.tolerance x the body length."""
    tol = result.get("scene", {}).get("solver", {}).get("contact", {}).get("tolerance")
    if not isinstance(tol, (int, float)):
        return None
    return float(tol) * characteristic_length(result)


def moving_obstacle(result: dict) -> Optional[str]:
    """Name of the first obstacle that moves over the run, if any."""
    for s in result.get("steps", []):
        for o in s.get("obstacles", []) or []:
            if any(abs(v) > 0 for v in o.get("offset", [0, 0])):
                return o["name"]
    return None


def total_load(result: dict) -> Tuple[float, Optional[int]]:
    """|sum of load forces| at factor 1 and the node of the first load (None: no loads)."""
    loads = result.get("scene", {}).get("body", {}).get("loads") or []
    fx = sum(l.get("force", [0, 0])[0] for l in loads)
    fy = sum(l.get("force", [0, 0])[1] for l in loads)
    node = loads[0].get("node") if loads else None
    return math.hypot(fx, fy), node


def step_label(result: dict, step: dict) -> str:
    """What a step means physically: the travel of the moving obstacle, or the load."""
    u = units(result)
    mover = moving_obstacle(result)
    if mover:
        for o in step.get("obstacles", []) or []:
            if o["name"] == mover:
                travel = math.hypot(*o["offset"])
                return f"{mover} travel {travel:.3g}{' ' + u['length'] if u['length'] else ''}"
    total, _ = total_load(result)
    lf = step.get("load_factor", 0.0)
    if total > 0:
        return f"F = {lf * total:.4g}{' ' + u['force'] if u['force'] else ''}"
    return f"load factor {lf:.3g}"


def pick_steps(result: dict, count: Optional[int] = None) -> List[dict]:
    """About five or six evenly spaced steps with fields, ending with the last."""
    steps = field_steps(result)
    n = len(steps)
    if n == 0:
        return []
    if count is None:
        count = next((c for c in (6, 5, 4) if n % c == 0), min(n, 5))
    count = max(1, min(count, n))
    picks = sorted({max(1, round(n * k / count)) for k in range(1, count + 1)})
    return [steps[i - 1] for i in picks]


# ---- obstacles


def _arc_points(centre, radius, a0, a1, offset, n=200):
    out_x, out_y = [], []
    for k in range(n + 1):
        a = math.radians(a0 + (a1 - a0) * k / n)
        out_x.append(centre[0] + offset[0] + radius * math.cos(a))
        out_y.append(centre[1] + offset[1] + radius * math.sin(a))
    return out_x, out_y


def obstacle_outline(shape: dict, offset: Sequence[float] = (0.0, 0.0)) -> Tuple[List[float], List[float]]:
    """Points of an obstacle's surface (circle, segment, arc, profile), moved by `offset`."""
    kind = shape.get("type")
    if kind == "circle":
        return _arc_points(shape["centre"], shape["radius"], 0.0, 360.0, offset, 360)
    if kind == "segment":
        a, b = shape["from"], shape["to"]
        return [a[0] + offset[0], b[0] + offset[0]], [a[1] + offset[1], b[1] + offset[1]]
    if kind == "arc":
        a0, a1 = shape["start_angle"], shape["end_angle"]
        if a1 < a0:
            a1 += 360.0
        return _arc_points(shape["centre"], shape["radius"], a0, a1, offset)
    if kind == "profile":
        xs: List[float] = []
        ys: List[float] = []
        for piece in shape.get("pieces", []):
            px, py = obstacle_outline(piece, offset)
            xs += px
            ys += py
        return xs, ys
    return [], []


def obstacle_offsets(step: Optional[dict]) -> Dict[str, List[float]]:
    if not step:
        return {}
    return {o["name"]: list(o.get("offset", [0.0, 0.0])) for o in step.get("obstacles", []) or []}


def draw_obstacles(ax, result: dict, step: Optional[dict], color="0.35", alpha=1.0, label=True,
                   linestyle="-"):
    """Draws every obstacle of the effective scene at the step's offsets; returns the lines."""
    offsets = obstacle_offsets(step)
    lines = []
    for o in result.get("scene", {}).get("obstacles", []):
        x, y = obstacle_outline(o.get("shape", {}), offsets.get(o.get("name"), (0.0, 0.0)))
        if not x:
            continue
        (line,) = ax.plot(x, y, color=color, lw=1.2, alpha=alpha, linestyle=linestyle,
                          label=o.get("name") if label else None)
        lines.append(line)
    return lines


def _body_limits(ax, xs: Sequence[float], ys: Sequence[float], margin=0.12):
    x0, x1 = min(xs), max(xs)
    y0, y1 = min(ys), max(ys)
    span = max(x1 - x0, y1 - y0, 1e-9)
    ax.set_xlim(x0 - margin * span, x1 + margin * span)
    ax.set_ylim(y0 - margin * span, y1 + margin * span)


def beam_band(step: dict, obstacle: Optional[str] = None):
    """For a beam: (lower, upper) surface polylines from the contact points (lower surface)
    mirrored about the centre line; None when the points do not cover every node."""
    nodes = step.get("nodes", [])
    pts = [c for c in step.get("contact_points", []) or [] if obstacle in (None, c["obstacle"])]
    by_node = {}
    for c in pts:
        by_node.setdefault(c["node"], c)
    if len(by_node) != len(nodes):
        return None
    lower = [(by_node[i]["x"], by_node[i]["y"]) for i in range(len(nodes))]
    upper = [(2 * n["x"] - lx, 2 * n["y"] - ly) for n, (lx, ly) in zip(nodes, lower)]
    return lower, upper


# ---- figures


def convergence(result: dict, history: Optional[List[dict]] = None):
    """||v||_2 against the contact iteration (counted over the whole run), log scale, one
    colour per load step, with the tolerance line. Iterations with ||v||_2 = 0 (nothing in
    contact) cannot be shown on a log scale: they are counted but not drawn.

    `history`: the iteration events (GET .../convergence), when the result has no history.
    data = {"steps": {k: {"iteration": [...], "v2": [...]}}, "tolerance": float | None,
            "zero": number of iterations with ||v||_2 = 0}"""
    plt = pyplot()
    per_step: Dict[int, List[float]] = {}
    if history is None:
        for s in result.get("steps", []):
            per_step[s["step"]] = [h["v2"] for h in s.get("history", []) or []]
    else:
        for h in history:
            per_step.setdefault(h["step"], []).append(h["v2"])
    fig, ax = plt.subplots(figsize=(8, 4.8))
    cmap = plt.get_cmap("viridis")
    count = 0
    zero = 0
    data = {"steps": {}, "tolerance": tolerance(result), "zero": 0}
    nsteps = max(len(per_step), 1)
    for idx, (k, values) in enumerate(sorted(per_step.items())):
        it, v = [], []
        for value in values:
            count += 1
            if value > 0:
                it.append(count)
                v.append(value)
            else:
                zero += 1
        data["steps"][k] = {"iteration": it, "v2": v}
        if v:
            ax.plot(it, v, "-o", ms=2.5, lw=1.0, color=cmap(idx / max(nsteps - 1, 1)),
                    label=f"step {k}", gid=f"step-{k}")
    data["zero"] = zero
    if data["tolerance"]:
        ax.axhline(data["tolerance"], color="crimson", ls="--", lw=1.0, gid="tolerance",
                   label=f"tolerance {data['tolerance']:.2e}")
    ax.set_yscale("log")
    ax.set_xlabel("contact iteration (whole run)")
    ax.set_ylabel(r"$\Vert v \Vert_2$")
    name = result.get("scene", {}).get("name", "")
    ax.set_title(f"Contact error history{': ' + name if name else ''}")
    ax.grid(True, which="both", alpha=0.25)
    if nsteps <= 12:
        ax.legend(fontsize=7, ncol=2)
    else:
        sm = plt.cm.ScalarMappable(cmap=cmap, norm=plt.Normalize(min(per_step), max(per_step)))
        fig.colorbar(sm, ax=ax, label="load step")
        if data["tolerance"]:
            ax.legend(handles=[l for l in ax.get_lines() if l.get_gid() == "tolerance"], fontsize=8)
    fig.tight_layout()
    return fig, data


def shapes(result: dict, steps: Optional[Sequence[int]] = None):
    """Undeformed and deformed shapes at several steps, each with the obstacles at that step's
    position (the paper's Figs. 4 and 6).

    data = {"initial": {"x", "y"}, "steps": {k: {"x", "y", "offsets", "label"}}}"""
    plt = pyplot()
    chosen = pick_steps(result) if steps is None else [find_step(result, k) for k in steps]
    if not chosen:
        raise ValueError("the result has no step with node fields")
    fig, ax = plt.subplots(figsize=(9, 6))
    cmap = plt.get_cmap("plasma")
    x0, y0 = initial_xy(result, chosen[0])
    data = {"initial": {"x": x0, "y": y0}, "steps": {}}
    # One line per body (several bodies: gids and labels carry the body's name).
    ranges = body_ranges(result, chosen[0])

    def per_body(xs, ys, gid, **style):
        label = style.pop("label", None)
        for name, first, count in ranges:
            ax.plot(xs[first:first + count], ys[first:first + count], **style,
                    label=label if name is None else f"{label}, {name}" if label else None,
                    gid=gid if name is None else f"{gid}-{name}")

    per_body(x0, y0, "initial", color="0.6", ls="--", lw=1.2, label="undeformed")
    draw_obstacles(ax, result, None, color="0.75", label=False, linestyle=":")
    allx, ally = list(x0), list(y0)
    for i, s in enumerate(chosen):
        colour = cmap(0.1 + 0.8 * i / max(len(chosen) - 1, 1))
        x, y = node_xy(s)
        label = step_label(result, s)
        data["steps"][s["step"]] = {"x": x, "y": y, "offsets": obstacle_offsets(s), "label": label}
        if ranges[0][0] is not None:
            data["steps"][s["step"]]["bodies"] = {
                name: {"x": x[first:first + count], "y": y[first:first + count]} for name, first, count in ranges}
        if body_model(result) in ("timoshenko_beam", "reissner_beam"):
            band = beam_band(s)
            if band:  # the beam's lower and upper surfaces, thin
                for surface in band:
                    ax.plot([p[0] for p in surface], [p[1] for p in surface], color=colour,
                            lw=0.6, alpha=0.7)
        per_body(x, y, f"step-{s['step']}", marker="o", ms=2.5, lw=1.6, color=colour, label=label)
        if moving_obstacle(result):
            draw_obstacles(ax, result, s, color=colour, alpha=0.6, label=False)
        allx += x
        ally += y
    if not moving_obstacle(result):
        draw_obstacles(ax, result, chosen[-1])
    else:
        # The fixed obstacles once, in grey.
        mover = moving_obstacle(result)
        fixed = dict(result)
        fixed["scene"] = dict(result["scene"])
        fixed["scene"]["obstacles"] = [o for o in result["scene"]["obstacles"] if o["name"] != mover]
        draw_obstacles(ax, fixed, chosen[-1])
    _body_limits(ax, allx, ally)
    ax.set_aspect("equal", adjustable="box")
    u = units(result)
    ax.set_xlabel("x" + _unit(u["length"]))
    ax.set_ylabel("y" + _unit(u["length"]))
    name = result.get("scene", {}).get("name", "")
    ax.set_title(f"Deformed shapes{': ' + name if name else ''}")
    ax.legend(fontsize=8, loc="best")
    ax.grid(True, alpha=0.2)
    fig.tight_layout()
    return fig, data


def strain(result: dict, step: Optional[int] = None):
    """True strains along the sheet against the undeformed position s0 of each element
    (membrane; the paper's Fig. 5 at punch travel 30 mm).

    data = {"step", "s0", "major_strain", "thickness_strain", "peak": {"s0", "major_strain"}}"""
    plt = pyplot()
    s = find_step(result, step)
    els = s.get("elements") or []
    if not els or "major_strain" not in els[0]:
        raise ValueError("the result has no membrane strains (elements.major_strain)")
    s0 = [e["s0"] for e in els]
    major = [e["major_strain"] for e in els]
    thick = [e["thickness_strain"] for e in els]
    k = max(range(len(major)), key=lambda i: major[i])
    # The stretch where the strain is within 1 % of its peak (a plateau in a free wall).
    near = [i for i, e in enumerate(major) if e >= major[k] - 0.01 * abs(major[k])]
    data = {"step": s["step"], "label": step_label(result, s), "s0": s0, "major_strain": major,
            "thickness_strain": thick,
            "peak": {"s0": s0[k], "major_strain": major[k],
                     "within_1_percent": [s0[near[0]], s0[near[-1]]]}}
    fig, ax = plt.subplots(figsize=(8, 4.8))
    ax.plot(s0, major, "-o", ms=3, color="tab:blue", label="major (meridional) true strain",
            gid="major_strain")
    ax.plot(s0, thick, "-s", ms=3, color="tab:orange", label="thickness true strain",
            gid="thickness_strain")
    ax.axhline(0, color="0.5", lw=0.6)
    lo, hi = data["peak"]["within_1_percent"]
    where = f"s0 = {s0[k]:.3g}" if lo == hi else f"s0 from {lo:.3g} to {hi:.3g}"
    ax.annotate(f"peak {major[k]:.3f}, {where}", (s0[k], major[k]),
                xytext=(10, 10), textcoords="offset points", fontsize=8,
                arrowprops={"arrowstyle": "->", "lw": 0.8})
    # Where each tool touches the sheet (points not open), as bands along s0.
    _contact_bands(ax, result, s, s0, els)
    u = units(result)
    ax.set_xlabel("undeformed position along the sheet s0" + _unit(u["length"]))
    ax.set_ylabel("true strain")
    ax.set_title(f"Strain distribution, {data['label']}")
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig, data


def _contact_bands(ax, result, step, s0, els):
    """Shades the undeformed stretch of the sheet in contact with each obstacle."""
    nodes = step.get("nodes", [])
    if len(nodes) != len(els) + 1:
        return
    # Node s0 from element mid-points (uniform or not): ends of each element.
    node_s0 = [0.0] * len(nodes)
    node_s0[0] = 2 * s0[0] - (s0[1] if len(s0) > 1 else 2 * s0[0])
    node_s0[0] = max(node_s0[0], 0.0)
    for i, m in enumerate(s0):
        node_s0[i + 1] = 2 * m - node_s0[i]
    colours = ["tab:green", "tab:red", "tab:purple", "tab:brown"]
    for j, o in enumerate(result.get("scene", {}).get("obstacles", [])):
        touching = sorted({c["node"] for c in step.get("contact_points", []) or []
                           if c["obstacle"] == o["name"] and c["state"] != "open"})
        if not touching:
            continue
        lo, hi = node_s0[touching[0]], node_s0[touching[-1]]
        ax.axvspan(lo, hi, color=colours[j % len(colours)], alpha=0.08,
                   label=f"in contact with {o['name']}")


def contact_series(result: dict, step: dict, obstacle: str, key: str):
    """Per contact point of `obstacle` in node order: undeformed position along the body (x0 of
    the node), deformed point (x, y), normal, state and the value of `key`."""
    x0, _ = initial_xy(result, step)
    pts = sorted((c for c in step.get("contact_points", []) or [] if c["obstacle"] == obstacle),
                 key=lambda c: c["node"])
    return {"node": [c["node"] for c in pts], "x0": [x0[c["node"]] for c in pts],
            "x": [c["x"] for c in pts], "y": [c["y"] for c in pts],
            "normal": [c["normal"] for c in pts], "state": [c["state"] for c in pts],
            key: [c[key] for c in pts]}


def sign_changes(x: Sequence[float], values: Sequence[float], states: Sequence[str]) -> List[float]:
    """Positions (mid-way between neighbours) where a stress changes sign among the points in
    contact."""
    idx = [i for i, st in enumerate(states) if st != "open" and values[i] != 0.0]
    out = []
    for a, b in zip(idx, idx[1:]):
        if values[a] * values[b] < 0:
            out.append(0.5 * (x[a] + x[b]))
    return out


def contact_stress(result: dict, component: str = "normal", step: Optional[int] = None):
    """Normal (sigma_n) or frictional (sigma_t) contact stress, i.e. contact force / tributary
    area, (top) drawn on the deformed shape with the obstacles and (bottom) along the body
    against the undeformed position x0 of each point (the paper's Figs. 7 and 8).

    On the shape, normal stress is drawn along the obstacle normal; frictional stress as arrows
    along the force it puts on the body: f = p_t * xi with xi = rot90(n), the obstacle's
    counter-clockwise tangent. Paper signs: sigma_n <= 0 presses.

    data = {"step", "component", "obstacles": {name: {"x0", "sigma", "x", "y", "state",
            "sign_changes": [x0...], "force_x": [...]}}}"""
    plt = pyplot()
    key = {"normal": "sigma_n", "friction": "sigma_t"}[component]
    s = find_step(result, step)
    names = contact_names(result)
    data = {"step": s["step"], "label": step_label(result, s), "component": component,
            "key": key, "obstacles": {}}
    fig, (ax_shape, ax_line) = plt.subplots(2, 1, figsize=(9, 8.5),
                                            gridspec_kw={"height_ratios": [1.25, 1]})
    x, y = node_xy(s)
    if body_model(result) in ("timoshenko_beam", "reissner_beam"):
        band = beam_band(s)
        if band:
            lower, upper = band
            poly = lower + upper[::-1]
            ax_shape.fill([p[0] for p in poly], [p[1] for p in poly], color="tab:blue",
                          alpha=0.2, lw=0)
    for name, first, count in body_ranges(result, s):
        ax_shape.plot(x[first:first + count], y[first:first + count], "-", lw=1.4,
                      color="tab:blue" if name is None else None,
                      label="body (deformed)" if name is None else f"{name} (deformed)")
    draw_obstacles(ax_shape, result, s)
    allx, ally = list(x), list(y)
    peak = max((abs(c[key]) for c in s.get("contact_points", []) or []), default=0.0)
    span = max(max(x) - min(x), max(y) - min(y), 1e-9)
    scale = 0.15 * span / peak if peak > 0 else 0.0
    colours = ["tab:red", "tab:green", "tab:purple", "tab:brown"]
    for j, name in enumerate(names):
        ser = contact_series(result, s, name, key)
        if not ser["node"]:
            continue
        col = colours[j % len(colours)]
        sigma = ser[key]
        tang = [(-n[1], n[0]) for n in ser["normal"]]
        entry = {"x0": ser["x0"], "sigma": sigma, "x": ser["x"], "y": ser["y"],
                 "node": ser["node"], "state": ser["state"],
                 "sign_changes": sign_changes(ser["x0"], sigma, ser["state"])}
        if component == "friction":
            entry["force_x"] = [v * t[0] for v, t in zip(sigma, tang)]
        data["obstacles"][name] = entry
        ax_line.plot(ser["x0"], sigma, "-o", ms=3, color=col, label=f"{key} on {name}",
                     gid=f"{key}-{name}")
        act = [i for i, st in enumerate(ser["state"]) if st != "open"]
        if not act or scale == 0.0:
            continue
        if component == "normal":
            # Stress diagram: the surface pushed out along the normal by |sigma| (into the body).
            dx = [ser["x"][i] - scale * abs(sigma[i]) * ser["normal"][i][0] for i in act]
            dy = [ser["y"][i] - scale * abs(sigma[i]) * ser["normal"][i][1] for i in act]
            for i, ex, ey in zip(act, dx, dy):
                ax_shape.plot([ser["x"][i], ex], [ser["y"][i], ey], color=col, lw=0.8)
            ax_shape.plot(dx, dy, "-", color=col, lw=1.2, label=f"|{key}| on {name}")
            allx += dx
            ally += dy
        else:
            u = [scale * sigma[i] * tang[i][0] for i in act]
            v = [scale * sigma[i] * tang[i][1] for i in act]
            ax_shape.quiver([ser["x"][i] for i in act], [ser["y"][i] for i in act], u, v,
                            angles="xy", scale_units="xy", scale=1.0, color=col, width=0.003,
                            label=f"friction on the body from {name}")
            allx += [ser["x"][i] + du for i, du in zip(act, u)]
            ally += [ser["y"][i] + dv for i, dv in zip(act, v)]
        for xc in entry["sign_changes"]:
            ax_line.axvline(xc, color=col, ls=":", lw=1.0)
            ax_line.annotate(f"sign change at x0 = {xc:.3g}", (xc, 0), xytext=(5, 12),
                             textcoords="offset points", fontsize=8, color=col)
    _body_limits(ax_shape, allx, ally, margin=0.08)
    ax_shape.set_aspect("equal", adjustable="box")
    un = units(result)
    su = stress_unit(result)
    what = "Normal" if component == "normal" else "Frictional"
    ax_shape.set_title(f"{what} contact stress on the deformed shape, {data['label']}")
    ax_shape.set_xlabel("x" + _unit(un["length"]))
    ax_shape.set_ylabel("y" + _unit(un["length"]))
    ax_shape.legend(fontsize=8, loc="best")
    ax_shape.grid(True, alpha=0.2)
    ax_line.axhline(0, color="0.5", lw=0.6)
    ax_line.set_xlabel("undeformed position x0" + _unit(un["length"]))
    if component == "normal":
        ax_line.set_ylabel(r"$\sigma_n$ (<= 0 presses)" + _unit(su))
    else:
        ax_line.set_ylabel(r"$\sigma_t$ (along $\xi$, ccw tangent of the obstacle)" + _unit(su))
    ax_line.grid(True, alpha=0.25)
    ax_line.legend(fontsize=8)
    fig.tight_layout()
    return fig, data


def load_deflection(result: dict, node: Optional[int] = None):
    """Load against the displacements of the loaded end (the paper's Fig. 9): the vertical
    deflection -w (or -uy) and the horizontal -u (or -ux), from the unloaded origin.

    data = {"node", "load": [0, ...], "deflection": [0, ...], "horizontal": [0, ...]}"""
    plt = pyplot()
    total, load_node = total_load(result)
    steps = field_steps(result)
    if total <= 0 or not steps:
        raise ValueError("the scene has no loads: no load-deflection curve")
    if node is None:
        node = load_node if load_node is not None else len(steps[0]["nodes"]) - 1
    ku, kv = displacement_keys(result)
    load = [0.0] + [s["load_factor"] * total for s in steps]
    defl = [0.0] + [-s["nodes"][node][kv] for s in steps]
    horiz = [0.0] + [-s["nodes"][node][ku] for s in steps]
    data = {"node": node, "load": load, "deflection": defl, "horizontal": horiz}
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.plot(defl, load, "-o", ms=3, label=f"vertical  -{kv} (node {node})", gid="deflection")
    ax.plot(horiz, load, "-s", ms=3, label=f"horizontal -{ku} (node {node})", gid="horizontal")
    u = units(result)
    ax.set_xlabel("end displacement" + _unit(u["length"]))
    ax.set_ylabel("load F" + _unit(u["force"]))
    ax.set_title("Load against end deflection")
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig, data


def tool_force(step: dict, obstacle: str) -> Tuple[float, float]:
    """The force the body puts on `obstacle` in a step: minus the sum of the contact forces
    on the body, p_n (-n) + p_t t with t = (-n_y, n_x) (docs/design.md#scenes-results-and-events)."""
    fx = fy = 0.0
    for c in step.get("contact_points") or []:
        if c["obstacle"] != obstacle:
            continue
        nx, ny = c["normal"]
        fx += c["p_n"] * nx + c["p_t"] * ny
        fy += c["p_n"] * ny - c["p_t"] * nx
    return fx, fy


def tool_travel(step: dict, obstacle: str) -> float:
    for o in step.get("obstacles", []) or []:
        if o["name"] == obstacle:
            return math.hypot(*o["offset"])
    return 0.0


def punch_force(result: dict):
    """The moving tool's force along its travel against the travel (punch stretching; a total
    over the circle in axisymmetry).

    data = {"obstacle", "travel": [0, ...], "force": [0, ...]}"""
    plt = pyplot()
    mover = moving_obstacle(result)
    steps = [s for s in field_steps(result) if s.get("contact_points") is not None]
    if not mover or not steps:
        raise ValueError("the result has no moving obstacle with contact points")
    travel, force = [0.0], [0.0]
    for s in steps:
        d = tool_travel(s, mover)
        off = next(o["offset"] for o in s["obstacles"] if o["name"] == mover)
        fx, fy = tool_force(s, mover)
        travel.append(d)
        # The force resisting the motion: along the unit travel direction, opposed.
        force.append(-(fx * off[0] + fy * off[1]) / d if d > 0 else 0.0)
    data = {"obstacle": mover, "travel": travel, "force": force}
    fig, ax = plt.subplots(figsize=(7, 5))
    ax.plot(travel, force, "-o", ms=3, gid="force", label=f"{mover} force")
    u = units(result)
    ax.set_xlabel(f"{mover} travel" + _unit(u["length"]))
    ax.set_ylabel(f"{mover} force" + _unit(u["force"]))
    ax.set_title(f"{mover.capitalize()} force against travel")
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=8)
    fig.tight_layout()
    return fig, data


def radial_strains(result: dict, depths: Sequence[float] = (10.0, 20.0, 30.0)):
    """Meridional, hoop and thickness true strains against the initial radius at the steps
    where the moving tool has travelled each of `depths` (the nearest recorded step).

    data = {"steps": {step: {"travel", "r0", "meridional_strain", "hoop_strain",
    "thickness_strain"}}}"""
    plt = pyplot()
    steps = field_steps(result)
    if not steps or "hoop_strain" not in (steps[-1].get("elements") or [{}])[0]:
        raise ValueError("the result has no axisymmetric membrane strains (elements.hoop_strain)")
    mover = moving_obstacle(result)
    picked = []
    for d in depths:
        s = min(steps, key=lambda st: abs(tool_travel(st, mover) - d)) if mover else steps[-1]
        if s not in picked:
            picked.append(s)
    fig, ax = plt.subplots(figsize=(8, 6))
    data = {"steps": {}}
    styles = {"meridional_strain": "-", "hoop_strain": "--", "thickness_strain": ":"}
    cmap = plt.get_cmap("viridis")
    for i, s in enumerate(picked):
        els = s["elements"]
        r0 = [e["s0"] for e in els]  # the blank is flat: s0 is the initial radius
        entry = {"travel": tool_travel(s, mover) if mover else None, "r0": r0}
        color = cmap(i / max(len(picked) - 1, 1))
        for key, ls in styles.items():
            entry[key] = [e[key] for e in els]
            ax.plot(r0, entry[key], ls, color=color, lw=1.3, gid=f"{key}-{s['step']}",
                    label=f"{key.split('_')[0]}, {step_label(result, s)}")
        data["steps"][s["step"]] = entry
    ax.axhline(0, color="0.5", lw=0.6)
    u = units(result)
    ax.set_xlabel("initial radius r0" + _unit(u["length"]))
    ax.set_ylabel("true strain")
    ax.set_title("Strains over the radius")
    ax.grid(True, alpha=0.25)
    ax.legend(fontsize=7, ncol=len(picked), loc="upper center", bbox_to_anchor=(0.5, -0.14))
    fig.tight_layout()
    return fig, data


# ---- all at once

FIGURES = ("convergence", "shapes", "strain", "contact_normal", "contact_friction",
           "load_deflection", "punch_force", "radial_strains")


def applicable(result: dict) -> List[str]:
    """The figures that this result can give."""
    names = ["convergence"]
    if not field_steps(result):
        return names
    names.append("shapes")
    last = field_steps(result)[-1]
    if (last.get("elements") or [{}])[0].get("major_strain") is not None:
        names.append("strain")
    if (last.get("elements") or [{}])[0].get("hoop_strain") is not None:
        names.append("radial_strains")
        if moving_obstacle(result) and last.get("contact_points") is not None:
            names.append("punch_force")
    if last.get("contact_points"):
        names.append("contact_normal")
        if any(c.get("sigma_t", 0) != 0 for c in last["contact_points"]) or any(
                o.get("friction", 0) > 0 for o in result.get("scene", {}).get("obstacles", [])
                + result.get("scene", {}).get("contacts", [])):
            names.append("contact_friction")
    if total_load(result)[0] > 0:
        names.append("load_deflection")
    return names


def make(result: dict, name: str, history=None, step: Optional[int] = None):
    if name == "convergence":
        return convergence(result, history)
    if name == "shapes":
        return shapes(result)
    if name == "strain":
        return strain(result, step)
    if name == "contact_normal":
        return contact_stress(result, "normal", step)
    if name == "contact_friction":
        return contact_stress(result, "friction", step)
    if name == "load_deflection":
        return load_deflection(result)
    if name == "punch_force":
        return punch_force(result)
    if name == "radial_strains":
        return radial_strains(result)
    raise ValueError(f"unknown figure {name!r}; figures: {', '.join(FIGURES)}")


def write_all(result: dict, out_dir: str, prefix: str = "", names: Optional[Dict[str, str]] = None,
              history=None, step: Optional[int] = None, dpi: int = 110):
    """Writes each applicable figure as a PNG; returns {figure: (path, data)}.

    `names` maps a figure to its file stem (default: prefix + figure)."""
    plt = pyplot()
    os.makedirs(out_dir, exist_ok=True)
    written = {}
    for name in applicable(result):
        fig, data = make(result, name, history, step)
        stem = (names or {}).get(name, prefix + name)
        path = os.path.join(out_dir, stem + ".png")
        fig.savefig(path, dpi=dpi)
        plt.close(fig)
        written[name] = (path, data)
    return written
