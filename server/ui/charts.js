// The page's drawings, in SVG: the contact error per iteration (log scale), the deformed body
// with obstacles and contact points, and the contact stresses along the contact. Colours are
// SVG attributes (the Content-Security-Policy forbids inline styles).

const SVG = "http://www.w3.org/2000/svg";

// Contact states; the same colours as the .key legend in style.css.
export const STATE_COLOURS = { open: "#8a8f98", stick: "#1f6fd1", slip: "#e8590c" };
const STEP_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#8c564b",
                      "#e377c2", "#17becf", "#bcbd22", "#ff7f0e", "#7f7f7f"];
export const stepColour = (step) => STEP_COLOURS[(step - 1) % STEP_COLOURS.length];

function el(parent, name, attrs = {}, text) {
  const node = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, v);
  if (text !== undefined) node.textContent = text;
  parent.append(node);
  return node;
}

function clear(svg) {
  while (svg.firstChild) svg.firstChild.remove();
}

const fmt = (x) => (x === null || x === undefined || !Number.isFinite(x) ? "-" : x.toExponential(3));

function box(svg) {
  const [, , w, h] = svg.getAttribute("viewBox").split(" ").map(Number);
  return { w, h, left: 62, right: w - 12, top: 12, bottom: h - 34 };
}

// points: [{seq, step, v2}] in arrival order; tolerance: absolute ||v||_2 tolerance or null.
// One <circle class="pt"> per point; values that are 0 or missing sit on the bottom axis.
export function drawConvergence(svg, points, tolerance) {
  clear(svg);
  const b = box(svg);
  const logs = points.filter((p) => p.v2 > 0).map((p) => Math.log10(p.v2));
  if (tolerance > 0) logs.push(Math.log10(tolerance));
  let lo = logs.length ? Math.floor(Math.min(...logs)) : -10;
  let hi = logs.length ? Math.ceil(Math.max(...logs)) : 0;
  if (hi - lo < 1) { lo -= 1; hi += 1; }
  const n = Math.max(points.length, 1);
  const x = (i) => b.left + ((i + 0.5) / n) * (b.right - b.left);
  const y = (v) => (v > 0 ? b.bottom - ((Math.log10(v) - lo) / (hi - lo)) * (b.bottom - b.top) : b.bottom);

  // Axes: decades on the left, iteration count below.
  const stride = Math.max(1, Math.ceil((hi - lo) / 8));
  for (let d = lo; d <= hi; d += stride) {
    const yy = b.bottom - ((d - lo) / (hi - lo)) * (b.bottom - b.top);
    el(svg, "line", { x1: b.left, x2: b.right, y1: yy, y2: yy, stroke: "#e3e5e8" });
    el(svg, "text", { x: b.left - 6, y: yy + 4, "text-anchor": "end", class: "tick" }, `1e${d}`);
  }
  el(svg, "line", { x1: b.left, x2: b.left, y1: b.top, y2: b.bottom, stroke: "#555" });
  el(svg, "line", { x1: b.left, x2: b.right, y1: b.bottom, y2: b.bottom, stroke: "#555" });
  el(svg, "text", { x: (b.left + b.right) / 2, y: b.h - 6, "text-anchor": "middle", class: "label" },
     `contact iteration (all steps): ${points.length}`);
  el(svg, "text", { x: 14, y: (b.top + b.bottom) / 2, "text-anchor": "middle", class: "label",
                    transform: `rotate(-90 14 ${(b.top + b.bottom) / 2})` }, "||v||₂");

  if (tolerance > 0) {
    const yt = y(tolerance);
    el(svg, "line", { id: "tolerance-line", x1: b.left, x2: b.right, y1: yt, y2: yt, stroke: "#c2255c",
                      "stroke-dasharray": "6 4", "data-value": tolerance });
    el(svg, "text", { x: b.right - 4, y: yt - 4, "text-anchor": "end", class: "tick tol" },
       `tolerance ${fmt(tolerance)}`);
  }

  if (points.some((p) => !(p.v2 > 0)))
    el(svg, "text", { x: b.left + 6, y: b.bottom - 6, class: "tick" }, "hollow on the axis: ||v||₂ = 0");

  // One polyline per step, then the markers on top.
  const byStep = new Map();
  points.forEach((p, i) => {
    if (!byStep.has(p.step)) byStep.set(p.step, []);
    byStep.get(p.step).push(`${x(i).toFixed(1)},${y(p.v2).toFixed(1)}`);
  });
  for (const [step, coords] of byStep)
    el(svg, "polyline", { points: coords.join(" "), fill: "none", stroke: stepColour(step), "stroke-width": 1.2 });
  const r = points.length > 400 ? 1.5 : 2.8;
  points.forEach((p, i) => {
    const c = el(svg, "circle", { class: p.v2 > 0 ? "pt" : "pt zero", cx: x(i).toFixed(1), cy: y(p.v2).toFixed(1), r,
                                  fill: p.v2 > 0 ? stepColour(p.step) : "white", stroke: stepColour(p.step),
                                  "data-step": p.step, "data-seq": p.seq ?? "" });
    el(c, "title", {}, `step ${p.step}, iteration ${i + 1}: ||v||_2 = ${fmt(p.v2)}`);
  });
}

// The undeformed position of a node row (beam: u, w; membrane and continuum: ux, uy).
function undeformed(n) {
  return [n.x - (n.u ?? n.ux ?? 0), n.y - (n.w ?? n.uy ?? 0)];
}

// The obstacle's outline as polylines in scene coordinates, moved by `offset`.
function obstacleOutlines(shape, offset) {
  const [dx, dy] = offset || [0, 0];
  const arc = (c, r, a0, a1) => {
    const pts = [];
    const k = Math.max(8, Math.ceil(Math.abs(a1 - a0) / 4));
    for (let i = 0; i <= k; i++) {
      const a = ((a0 + ((a1 - a0) * i) / k) * Math.PI) / 180;
      pts.push([c[0] + dx + r * Math.cos(a), c[1] + dy + r * Math.sin(a)]);
    }
    return pts;
  };
  const piece = (p) =>
    p.type === "segment" ? [[p.from[0] + dx, p.from[1] + dy], [p.to[0] + dx, p.to[1] + dy]]
    : p.type === "arc" ? arc(p.centre, p.radius, p.start_angle, p.end_angle)
    : p.type === "circle" ? arc(p.centre, p.radius, 0, 360) : [];
  if (shape.type === "profile") return (shape.pieces || []).map(piece);
  return [piece(shape)];
}

// Bounds of the body over every step with fields (so the view holds still on the slider).
export function bodyBounds(result) {
  let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
  for (const s of result.steps)
    for (const n of s.nodes || [])
      for (const [x, y] of [[n.x, n.y], undeformed(n)]) {
        if (!Number.isFinite(x) || !Number.isFinite(y)) continue;
        x0 = Math.min(x0, x); x1 = Math.max(x1, x); y0 = Math.min(y0, y); y1 = Math.max(y1, y);
      }
  if (!Number.isFinite(x0)) return null;
  const pad = 0.15 * Math.max(x1 - x0, y1 - y0, 1e-9);
  return { x0: x0 - pad, x1: x1 + pad, y0: y0 - pad, y1: y1 + pad };
}

// The deformed body of `step` (an entry of result.steps), the obstacles where that step has
// them, and one <circle class="cp"> per contact point, coloured by its state.
export function drawBody(svg, result, step, bounds) {
  clear(svg);
  const [, , W, H] = svg.getAttribute("viewBox").split(" ").map(Number);
  if (!bounds || !step.nodes) {
    el(svg, "text", { x: W / 2, y: H / 2, "text-anchor": "middle", class: "label" }, "no fields for this step");
    return;
  }
  const s = Math.min((W - 20) / (bounds.x1 - bounds.x0), (H - 20) / (bounds.y1 - bounds.y0));
  const ox = (W - s * (bounds.x1 - bounds.x0)) / 2, oy = (H - s * (bounds.y1 - bounds.y0)) / 2;
  const px = (x) => ox + s * (x - bounds.x0);
  const py = (y) => H - oy - s * (y - bounds.y0);
  const path = (pts) => pts.map(([x, y], i) => `${i ? "L" : "M"}${px(x).toFixed(1)},${py(y).toFixed(1)}`).join("");

  const clip = el(el(svg, "defs"), "clipPath", { id: "body-clip" });
  el(clip, "rect", { x: 0, y: 0, width: W, height: H });
  const g = el(svg, "g", { "clip-path": "url(#body-clip)" });

  const offsets = new Map((step.obstacles || []).map((o) => [o.name, o.offset]));
  for (const ob of result.scene.obstacles || [])
    for (const pts of obstacleOutlines(ob.shape, offsets.get(ob.name)))
      el(g, "path", { class: "obstacle", d: path(pts), fill: "none", stroke: "#6c7480", "stroke-width": 3,
                      "data-obstacle": ob.name });

  const nodes = new Map(step.nodes.map((n) => [n.node, n]));
  for (const cell of result.mesh.cells) {
    const rows = cell.map((id) => nodes.get(id)).filter(Boolean);
    if (rows.length !== cell.length) continue;
    const closed = rows.length > 2 ? "Z" : "";
    el(g, "path", { class: "undeformed", d: path(rows.map(undeformed)) + closed, fill: "none",
                    stroke: "#9aa3ad", "stroke-dasharray": "2 3" });
    el(g, "path", { class: "cell", d: path(rows.map((n) => [n.x, n.y])) + closed,
                    fill: rows.length > 2 ? "#dbe7f5" : "none", stroke: "#1d2733", "stroke-width": rows.length > 2 ? 1 : 2.5 });
  }

  for (const cp of step.contact_points || []) {
    const c = el(g, "circle", { class: "cp", cx: px(cp.x).toFixed(1), cy: py(cp.y).toFixed(1), r: 4,
                                fill: STATE_COLOURS[cp.state] || "black", stroke: "white", "stroke-width": 1,
                                "data-state": cp.state, "data-node": cp.node, "data-obstacle": cp.obstacle });
    el(c, "title", {}, `node ${cp.node} (${cp.obstacle}): ${cp.state}, sigma_n = ${fmt(cp.sigma_n)}, ` +
                       `sigma_t = ${fmt(cp.sigma_t)}, gap = ${fmt(cp.gap)}`);
  }
}

// sigma_n and sigma_t of the step's contact points against their undeformed x.
export function drawStress(svg, result, step) {
  clear(svg);
  const b = box(svg);
  const nodes = new Map((step.nodes || []).map((n) => [n.node, n]));
  const rows = (step.contact_points || [])
    .map((cp) => ({ cp, s: nodes.has(cp.node) ? undeformed(nodes.get(cp.node))[0] : cp.x }))
    .filter((r) => Number.isFinite(r.s))
    .sort((a, c) => a.s - c.s);
  if (!rows.length) {
    el(svg, "text", { x: b.w / 2, y: b.h / 2, "text-anchor": "middle", class: "label" }, "no contact points in this step");
    return;
  }
  const vals = rows.flatMap((r) => [r.cp.sigma_n, r.cp.sigma_t]).filter(Number.isFinite);
  let lo = Math.min(0, ...vals), hi = Math.max(0, ...vals);
  if (hi - lo === 0) { lo -= 1; hi += 1; }
  const pad = 0.05 * (hi - lo);
  lo -= pad; hi += pad;
  const s0 = rows[0].s, s1 = rows[rows.length - 1].s === s0 ? s0 + 1 : rows[rows.length - 1].s;
  const x = (s) => b.left + ((s - s0) / (s1 - s0)) * (b.right - b.left);
  const y = (v) => b.bottom - ((v - lo) / (hi - lo)) * (b.bottom - b.top);
  const units = result.scene.units || {};
  const stressUnit = units.force && units.length ? ` [${units.force}/${units.length}²]` : "";

  for (const v of [lo + pad, 0, hi - pad]) {
    el(svg, "line", { x1: b.left, x2: b.right, y1: y(v), y2: y(v), stroke: v === 0 ? "#555" : "#e3e5e8" });
    el(svg, "text", { x: b.left - 6, y: y(v) + 4, "text-anchor": "end", class: "tick" }, v === 0 ? "0" : v.toPrecision(3));
  }
  el(svg, "line", { x1: b.left, x2: b.left, y1: b.top, y2: b.bottom, stroke: "#555" });
  el(svg, "text", { x: b.left, y: b.h - 6, class: "tick" }, s0.toPrecision(4));
  el(svg, "text", { x: b.right, y: b.h - 6, "text-anchor": "end", class: "tick" }, s1.toPrecision(4));
  el(svg, "text", { x: (b.left + b.right) / 2, y: b.h - 6, "text-anchor": "middle", class: "label" },
     `undeformed x${units.length ? " [" + units.length + "]" : ""}; stress${stressUnit}`);

  for (const [key, colour] of [["sigma_n", "#0b7285"], ["sigma_t", "#c2255c"]]) {
    const pts = rows.filter((r) => Number.isFinite(r.cp[key]));
    el(svg, "polyline", { class: key, fill: "none", stroke: colour, "stroke-width": 1.8,
                          points: pts.map((r) => `${x(r.s).toFixed(1)},${y(r.cp[key]).toFixed(1)}`).join(" ") });
    for (const r of pts) {
      const c = el(svg, "circle", { class: `${key}-pt`, cx: x(r.s).toFixed(1), cy: y(r.cp[key]).toFixed(1), r: 2.2,
                                    fill: colour, "data-node": r.cp.node });
      el(c, "title", {}, `node ${r.cp.node}: ${key} = ${fmt(r.cp[key])}`);
    }
  }
}

// Points against points, each axis linear or log10 (a study's error against h or against solve
// seconds, a sweep's quantity against its parameter). series: [{name, points: [{x, y, title}]}],
// one colour each, joined by a line when `lines`. Points that a log axis cannot show (<= 0, not
// finite) are left out. One <circle class="pt"> per point drawn; the svg's data-points counts them.
export function drawXY(svg, series, { xLabel, yLabel, xLog = false, yLog = false, lines = true }) {
  clear(svg);
  const b = box(svg);
  const ok = (v, log) => Number.isFinite(v) && (!log || v > 0);
  const shown = series.map((s) => ({ ...s, points: s.points.filter((p) => ok(p.x, xLog) && ok(p.y, yLog)) }));
  const all = shown.flatMap((s) => s.points);
  svg.dataset.points = String(all.length);
  if (!all.length) {
    el(svg, "text", { x: b.w / 2, y: b.h / 2, "text-anchor": "middle", class: "label" }, "nothing to plot yet");
    return;
  }
  // An axis in the plot's units (log10 for a log axis); decades as ticks on a log axis.
  const axis = (values, log) => {
    const t = values.map((v) => (log ? Math.log10(v) : v));
    let lo = Math.min(...t), hi = Math.max(...t);
    if (log) { lo = Math.floor(lo); hi = Math.ceil(hi); if (hi - lo < 1) hi = lo + 1; }
    if (!log && hi === lo) { lo -= Math.abs(lo) * 0.1 || 1; hi += Math.abs(hi) * 0.1 || 1; }
    const ticks = log ? Array.from({ length: hi - lo + 1 }, (_, k) => lo + k).filter((d, k, a) => k % Math.ceil(a.length / 8) === 0)
                      : [lo, (lo + hi) / 2, hi];  // the data's ends and middle
    if (!log) { const pad = 0.05 * (hi - lo); lo -= pad; hi += pad; }
    return { lo, hi, log, ticks, t: (v) => (log ? Math.log10(v) : v), label: (d) => (log ? `1e${d}` : d.toPrecision(3)) };
  };
  const ax = axis(all.map((p) => p.x), xLog), ay = axis(all.map((p) => p.y), yLog);
  const x = (v) => b.left + ((ax.t(v) - ax.lo) / (ax.hi - ax.lo)) * (b.right - b.left);
  const y = (v) => b.bottom - ((ay.t(v) - ay.lo) / (ay.hi - ay.lo)) * (b.bottom - b.top);
  for (const d of ay.ticks) {
    const yy = b.bottom - ((d - ay.lo) / (ay.hi - ay.lo)) * (b.bottom - b.top);
    el(svg, "line", { x1: b.left, x2: b.right, y1: yy, y2: yy, stroke: "#e3e5e8" });
    el(svg, "text", { x: b.left - 6, y: yy + 4, "text-anchor": "end", class: "tick" }, ay.label(d));
  }
  for (const d of ax.ticks) {
    const xx = b.left + ((d - ax.lo) / (ax.hi - ax.lo)) * (b.right - b.left);
    el(svg, "line", { x1: xx, x2: xx, y1: b.top, y2: b.bottom, stroke: "#eef0f2" });
    el(svg, "text", { x: xx, y: b.bottom + 14, "text-anchor": "middle", class: "tick" }, ax.label(d));
  }
  el(svg, "line", { x1: b.left, x2: b.left, y1: b.top, y2: b.bottom, stroke: "#555" });
  el(svg, "line", { x1: b.left, x2: b.right, y1: b.bottom, y2: b.bottom, stroke: "#555" });
  el(svg, "text", { x: (b.left + b.right) / 2, y: b.h - 4, "text-anchor": "middle", class: "label" }, xLabel);
  el(svg, "text", { x: 14, y: (b.top + b.bottom) / 2, "text-anchor": "middle", class: "label",
                    transform: `rotate(-90 14 ${(b.top + b.bottom) / 2})` }, yLabel);
  shown.forEach((s, k) => {
    const colour = STEP_COLOURS[k % STEP_COLOURS.length];
    const pts = [...s.points].sort((p, q) => p.x - q.x);
    if (lines && pts.length > 1)
      el(svg, "polyline", { points: pts.map((p) => `${x(p.x).toFixed(1)},${y(p.y).toFixed(1)}`).join(" "),
                            fill: "none", stroke: colour, "stroke-width": 1.4 });
    for (const p of pts) {
      const c = el(svg, "circle", { class: "pt", cx: x(p.x).toFixed(1), cy: y(p.y).toFixed(1), r: 3.2, fill: colour,
                                    "data-series": s.name, "data-x": p.x, "data-y": p.y });
      el(c, "title", {}, p.title || `${s.name}: ${fmt(p.x)}, ${fmt(p.y)}`);
    }
    if (shown.length > 1) {  // the key, top right, one line per series (text colour is the stylesheet's)
      el(svg, "circle", { cx: b.right - 8, cy: b.top + 8 + 14 * k, r: 3.2, fill: colour });
      el(svg, "text", { x: b.right - 16, y: b.top + 12 + 14 * k, "text-anchor": "end", class: "tick" }, s.name);
    }
  });
}
