// One study (docs/design.md#studies) followed through its event stream: the table of its jobs
// (levels or variants), per quantity its order, extrapolated value and the cheapest job under
// each threshold, and its plots: estimated error against h and against solve seconds (log-log),
// or for a sweep the quantity against the first swept parameter.
import { followStudy, getJson } from "./api.js";
import { drawXY } from "./charts.js";

const $ = (id) => document.getElementById(id);
const followed = { id: null, abort: null };

// Six significant digits, shortest form (1, 0.25, 1e-8, 0.0190738).
const num = (x) => (x === null || x === undefined ? "-" : Number.isFinite(x) ? String(+x.toPrecision(6)) : String(x));
const percent = (x) => `${+(x * 100).toPrecision(3)} %`;

// A cell showing `value` (numbers to 6 digits; the exact number in data-value).
function cell(row, value, tag = "td") {
  const td = document.createElement(tag);
  td.textContent = typeof value === "number" ? num(value) : value ?? "-";
  if (typeof value === "number") td.dataset.value = String(value);
  row.append(td);
  return td;
}

// A job's method and tolerance, as the series it belongs to ("" when the study has one).
const seriesName = (level) =>
  [level.method, level.tolerance !== undefined ? `tol ${level.tolerance}` : undefined].filter((x) => x != null).join(", ");

function levelsTable(study) {
  const table = $("study-levels");
  const sweep = study.kind === "sweep";
  const has = (key) => study.levels.some((l) => l[key] !== undefined);
  const columns = [
    ["level", (l) => l.level],
    ...(sweep ? (study.pointers || []).map((p, k) => [p, (l) => l.parameters?.[k]]) : [["h", (l) => l.h]]),
    ...(has("method") ? [["method", (l) => l.method]] : []),
    ...(has("tolerance") ? [["tolerance", (l) => l.tolerance]] : []),
    ["nodes", (l) => l.nodes],
    ["seconds", (l) => l.seconds],
    ["status", (l) => l.status],
  ];
  const head = document.createElement("tr");
  for (const [name] of columns) cell(head, name, "th").scope = "col";
  for (const q of study.quantities) {
    cell(head, q.name, "th").scope = "col";
    if (!sweep) cell(head, `${q.name} est. error`, "th").scope = "col";
  }
  table.tHead.replaceChildren(head);
  table.tBodies[0].replaceChildren(...study.levels.map((level, i) => {
    const row = document.createElement("tr");
    row.dataset.job = level.job ?? "";
    for (const [, value] of columns) cell(row, value(level));
    for (const q of study.quantities) {
      cell(row, level.outputs?.[q.name] ?? null).dataset.quantity = q.name;
      if (!sweep) cell(row, q.estimated_error?.[i] ?? null).dataset.error = q.name;
    }
    if (level.status === "failed") row.cells[columns.length - 1].className = "bad";
    return row;
  }));
}

// The cheapest job under each threshold, in words.
function cheapestText(c) {
  if (!c.level) return `below ${percent(c.below)}: none yet`;
  const l = c.level;
  const which = [`level ${l.level}`, l.method, l.tolerance !== undefined ? `tolerance ${l.tolerance}` : null].filter(Boolean).join(", ");
  return `below ${percent(c.below)}: ${which}, ${num(l.seconds)} s (est. error ${num(l.estimated_error)})`;
}

function quantityView(study, q) {
  const box = document.createElement("div");
  box.className = "quantity";
  box.dataset.quantity = q.name;
  const h = document.createElement("h3");
  h.textContent = q.name;
  box.append(h);
  const chart = (caption, label) => {
    const fig = document.createElement("figure");
    fig.className = "chart";
    const cap = document.createElement("figcaption");
    cap.textContent = caption;
    const svg = document.createElementNS("http://www.w3.org/2000/svg", "svg");
    svg.setAttribute("viewBox", "0 0 640 240");
    svg.setAttribute("role", "img");
    svg.setAttribute("aria-label", label);
    fig.append(cap, svg);
    box.append(fig);
    return svg;
  };

  if (study.kind === "sweep") {
    const pointer = study.pointers?.[0] ?? "parameter";
    // One series per value of the other swept parameters (a grid), one otherwise.
    const series = new Map();
    study.levels.forEach((l, i) => {
      const key = (l.parameters || []).slice(1).map((v, k) => `${study.pointers[k + 1]} = ${v}`).join(", ");
      if (!series.has(key)) series.set(key, { name: key || q.name, points: [] });
      series.get(key).points.push({ x: l.parameters?.[0], y: q.values?.[i], title: `variant ${l.level}: ${q.name} = ${num(q.values?.[i])}` });
    });
    const svg = chart(`${q.name} against ${pointer}`, `${q.name} against ${pointer}`);
    svg.classList.add("sweep-plot");
    drawXY(svg, [...series.values()], { xLabel: pointer, yLabel: q.name });
    return box;
  }

  const dl = document.createElement("dl");
  dl.className = "counts";
  const item = (term, value, key) => {
    const div = document.createElement("div");
    const dt = document.createElement("dt");
    const dd = document.createElement("dd");
    dt.textContent = term;
    dd.textContent = typeof value === "number" ? num(value) : value;
    if (typeof value === "number") dd.dataset.value = String(value);
    dd.dataset.key = key;
    div.append(dt, dd);
    dl.append(div);
  };
  item("order", q.order ?? "-", "order");
  item("extrapolated", q.extrapolated ?? "-", "extrapolated");
  item("asymptotic", q.asymptotic === true ? "yes" : q.asymptotic === false ? "no" : "not known", "asymptotic");
  if (q.reference) item("reference", seriesName(q.reference) || "-", "reference");
  box.append(dl);
  const ul = document.createElement("ul");
  ul.className = "links cheapest";
  for (const c of q.cheapest || []) {
    const li = document.createElement("li");
    li.textContent = cheapestText(c);
    li.dataset.below = String(c.below);
    ul.append(li);
  }
  box.append(ul);

  // One series per method and tolerance; a point per job with an estimate.
  const byH = new Map(), bySeconds = new Map();
  study.levels.forEach((l, i) => {
    const err = q.estimated_error?.[i];
    const name = seriesName(l) || q.name;
    const title = `level ${l.level}${seriesName(l) ? ", " + seriesName(l) : ""}: est. error ${num(err)}, ${num(l.seconds)} s`;
    for (const [map, x] of [[byH, l.h], [bySeconds, l.seconds]]) {
      if (!map.has(name)) map.set(name, { name, points: [] });
      map.get(name).points.push({ x, y: err, title });
    }
  });
  const errorH = chart(`${q.name}: estimated error against h (log-log)`, `${q.name} estimated error against h`);
  errorH.classList.add("error-h");
  drawXY(errorH, [...byH.values()], { xLabel: "h (coarsest mesh = 1)", yLabel: "est. relative error", xLog: true, yLog: true });
  const errorT = chart(`${q.name}: what accuracy costs, estimated error against solve seconds (log-log, a point per job)`,
                       `${q.name} estimated error against solve seconds`);
  errorT.classList.add("error-seconds");
  drawXY(errorT, [...bySeconds.values()], { xLabel: "solve seconds", yLabel: "est. relative error", xLog: true, yLog: true, lines: false });
  return box;
}

function answerText(answer) {
  if (!answer) return "";
  if (answer.reached)
    return `reached: level ${answer.level}, value ${num(answer.value)}, estimated error ${num(answer.estimated_error)}`;
  return `not reached: ${answer.reason}`;
}

function showStudy(study) {
  $("study-status").textContent = `${study.kind}, ${study.status}: ${study.levels.length} jobs, ` +
    `${study.levels.filter((l) => l.status === "successful").length} successful`;
  $("study-panel").dataset.status = study.status;
  $("study-answer").textContent = answerText(study.answer);
  $("study-answer").hidden = !study.answer;
  levelsTable(study);
  $("study-quantities").replaceChildren(...study.quantities.map((q) => quantityView(study, q)));
}

export function closeStudy() {
  followed.abort?.abort();
  followed.id = null;
  $("study-panel").hidden = true;
}

export async function openStudy(id) {
  if (id === followed.id) return;
  followed.abort?.abort();
  const abort = new AbortController();
  Object.assign(followed, { id, abort });
  $("study-panel").hidden = false;
  $("study-panel").dataset.state = "watching";
  $("study-shown-id").textContent = id;
  $("study-status").textContent = "";
  $("study-stream-status").textContent = "";
  $("study-answer").hidden = true;
  $("study-levels").tHead.replaceChildren();
  $("study-levels").tBodies[0].replaceChildren();
  $("study-quantities").replaceChildren();
  try {
    showStudy(await getJson(`/v1/studies/${encodeURIComponent(id)}`));
    if (abort.signal.aborted) return;
    await followStudy(id, {
      signal: abort.signal,
      onEvent: (seq, type, study) => {
        showStudy(study);
        $("study-panel").dataset.seq = String(seq);
        if (type === "study_finished") $("study-panel").dataset.state = "finished";
      },
      onState: (text) => { if (!abort.signal.aborted) $("study-stream-status").textContent = text; },
    });
    if (!abort.signal.aborted) $("study-stream-status").textContent = "stream ended";
  } catch (e) {
    if (abort.signal.aborted) return;
    $("study-status").textContent = e.status === 404 ? "no such study (deleted?)" : e.message;
    $("study-panel").dataset.state = "error";
  }
}
