// The page: the job list, the submit form, and one job watched live (its contact error per
// iteration, its step table) and then shown (deformed body, contact stresses, downloads).
import { ApiError, dismissJob, download, followEvents, getBlob, getJson, setToken, submitScene, token, uploadMesh } from "./api.js";
import { STATE_COLOURS, bodyBounds, drawBody, drawConvergence, drawStress } from "./charts.js";
import { closeStudy, openStudy } from "./study.js";

const $ = (id) => document.getElementById(id);
const PAGE_SIZE = 10;

function cell(row, text, attrs = {}) {
  const td = document.createElement("td");
  td.textContent = text;
  for (const [k, v] of Object.entries(attrs)) td.setAttribute(k, v);
  row.append(td);
  return td;
}

function button(text, label, onClick) {
  const b = document.createElement("button");
  b.type = "button";
  b.textContent = text;
  if (label) b.setAttribute("aria-label", label);
  b.addEventListener("click", onClick);
  return b;
}

const seconds = (from, to) => Math.max(0, (Date.parse(to) - Date.parse(from)) / 1000);
function elapsed(job) {
  if (!job.started) return "-";
  const s = seconds(job.started, job.finished || new Date().toISOString());
  return s < 60 ? `${s.toFixed(1)} s` : `${Math.floor(s / 60)} min ${Math.round(s % 60)} s`;
}
// Converged steps (a failed job's too); while running, the step being solved.
function stepsText(job) {
  if (job.status === "running" && job.step) return `${job.step} of ${job.steps}`;
  return `${job.steps_completed ?? 0} of ${job.steps}`;
}

// A failure in a sentence, by its kind (schemas/result.schema.json#/definitions/failure).
function failureText(failure, reason) {
  switch (failure?.kind) {
    case "dismissed": return "dismissed";
    case "job_limit": return "stopped by this service's limit: " + failure.message;
    case "friction_limit": return "failed: the load exceeds what friction can hold: " + failure.message;
    case undefined: return "failed: " + reason;
    default: return `failed (${failure.kind}): ${failure.message}`;
  }
}

function showConnection(error) {
  $("connection").textContent =
    !error ? (token() ? "token in use" : "")
    : error.status === 401 ? "the server wants a bearer token"
    : error.status === 0 ? "server unreachable; retrying" : error.message;
}

// ---- job list: newest first, pages of PAGE_SIZE via the server's cursor, polled every 2 s.
const list = { cursors: [null], index: 0, next: null };

async function refreshJobs() {
  const cursor = list.cursors[list.index];
  let doc;
  try {
    doc = await getJson(`/v1/jobs?limit=${PAGE_SIZE}` + (cursor ? `&cursor=${encodeURIComponent(cursor)}` : ""));
  } catch (e) {
    showConnection(e);
    return;
  }
  showConnection(null);
  const next = (doc.links || []).find((l) => l.rel === "next");
  list.next = next ? new URL(next.href, location.href).searchParams.get("cursor") : null;
  const body = $("jobs-table").tBodies[0];
  body.replaceChildren();
  for (const job of doc.jobs) {
    const row = document.createElement("tr");
    row.dataset.job = job.jobID;
    if (job.jobID === watched.id) row.setAttribute("aria-current", "true");
    const open = button(job.jobID.slice(0, 8), `open job ${job.jobID}`, () => { location.hash = "job=" + job.jobID; });
    open.className = "link";
    cell(row, "").append(open);
    cell(row, job.status, { class: "status " + job.status, title: job.failure ? job.failure.kind : "" });
    cell(row, stepsText(job));
    cell(row, elapsed(job));
    cell(row, "").append(button("Dismiss", `dismiss job ${job.jobID}`, async () => {
      try {
        await dismissJob(job.jobID);
      } catch (e) {
        showConnection(e);
      }
      refreshJobs();
    }));
    body.append(row);
  }
  $("jobs-empty").hidden = doc.jobs.length > 0 || list.index > 0;
  $("jobs-newer").disabled = list.index === 0;
  $("jobs-older").disabled = !list.next;
  $("jobs-page").textContent = `page ${list.index + 1}`;
}

// ---- submit: examples, upload, paste; JSON errors found here, scene errors by the server
// (422, nothing queued), each next to the JSON pointer it names.
async function loadExamples() {
  try {
    const doc = await getJson("/v1/examples");
    for (const item of doc.items) $("example").append(new Option(item.name, item.href));
  } catch (e) {
    showConnection(e);
  }
}

function showErrors(errors) {
  const ul = $("submit-errors");
  ul.replaceChildren();
  for (const { pointer, detail } of errors) {
    const li = document.createElement("li");
    li.dataset.pointer = pointer ?? "";
    const code = document.createElement("code");
    code.className = "pointer";
    code.textContent = pointer || "(the whole scene)";
    li.append(code, " ", detail || "");
    ul.append(li);
  }
}

// Characteristic length the relative tolerance scales with: the mesh length when the scene
// gives one, else the extent of the undeformed nodes of the result (as the Python client).
function absoluteTolerance(scene, result) {
  const tol = scene?.solver?.contact?.tolerance ?? (scene ? 1e-8 : null);
  if (!(tol > 0)) return null;
  const length = scene?.body?.mesh?.length;
  if (length > 0) return tol * length;
  const first = result?.steps?.find((s) => s.nodes);
  if (!first) return null;
  const xs = first.nodes.map((n) => n.x - (n.u ?? n.ux ?? 0)), ys = first.nodes.map((n) => n.y - (n.w ?? n.uy ?? 0));
  return tol * Math.max(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys));
}

// The scene's gmsh mesh references that name a file (body.mesh.gmsh, bodies[].mesh.gmsh,
// obstacles[].shape.gmsh): [{pointer, ref}].
function gmshReferences(node, pointer = "", out = []) {
  if (Array.isArray(node)) node.forEach((v, k) => gmshReferences(v, `${pointer}/${k}`, out));
  else if (node && typeof node === "object") {
    for (const [key, value] of Object.entries(node)) {
      const here = `${pointer}/${key.replace(/~/g, "~0").replace(/\//g, "~1")}`;
      if (key === "gmsh" && value && typeof value.file === "string") out.push({ pointer: here, ref: value });
      else gmshReferences(value, here, out);
    }
  }
  return out;
}

// The example the editor holds (its mesh files are the server's), or null once another scene is loaded.
let loadedExample = null;

// Uploads the .msh files the scene names (the chosen ones by name; an example's from the
// server) and puts their ids in place of the names. Throws {errors} at the references' pointers.
async function attachMeshes(scene) {
  const chosen = new Map([...$("mesh-files").files].map((f) => [f.name, f]));
  const ids = new Map();
  const errors = [];
  for (const { pointer, ref } of gmshReferences(scene)) {
    const name = ref.file.split("/").pop();
    if (!ids.has(name)) {
      let file = chosen.get(name) || null;
      if (!file && loadedExample) file = await getBlob(`/v1/examples/${encodeURIComponent(name)}`);
      if (!file) {
        errors.push({ pointer: pointer + "/file", detail: `choose ${name} under "Its gmsh meshes (.msh)"` });
        continue;
      }
      $("submit-status").textContent = `uploading ${name}`;
      try {
        const doc = await uploadMesh(file);
        ids.set(name, doc.id);
      } catch (e) {
        if (!(e instanceof ApiError) || e.status !== 422) throw e;
        errors.push(...e.errors.map((x) => ({ pointer: pointer + "/file", detail: `${name}: ${x.detail}` })));
        continue;
      }
    }
    delete ref.file;
    ref.id = ids.get(name);
  }
  if (errors.length) throw Object.assign(new Error("mesh files"), { errors, problem: { title: "mesh files missing or refused" } });
  return ids.size;
}

async function submit(event) {
  event.preventDefault();
  let text = $("scene").value;
  $("submit-status").textContent = "";
  let scene;
  try {
    scene = JSON.parse(text);
  } catch (e) {
    showErrors([{ pointer: "", detail: "the scene is not JSON: " + e.message }]);
    return;
  }
  $("submit").disabled = true;
  try {
    if (await attachMeshes(scene)) text = JSON.stringify(scene);
    const job = await submitScene(text);
    showErrors([]);
    $("submit-status").textContent = `queued as ${job.jobID.slice(0, 8)}`;
    sessionStorage.setItem("grip.tolerance." + job.jobID, JSON.stringify(absoluteTolerance(scene, null)));
    location.hash = "job=" + job.jobID;
    refreshJobs();
  } catch (e) {
    $("submit-status").textContent = e.problem ? `not queued: ${e.problem.title || e.message}` : String(e);
    showErrors(e.errors?.length ? e.errors : [{ pointer: "", detail: e.message }]);
  } finally {
    $("submit").disabled = false;
  }
}

// ---- one job, watched through its event stream
const watched = { id: null, abort: null, points: [], lastStarted: 0, tolerance: null, result: null, bounds: null, drawQueued: false };

function queueConvergenceDraw() {
  if (watched.drawQueued) return;
  watched.drawQueued = true;
  // At most four redraws a second: a long job has thousands of points.
  setTimeout(() => {
    watched.drawQueued = false;
    drawConvergence($("conv-plot"), watched.points, watched.tolerance);
    $("conv-plot").dataset.points = String(watched.points.length);
  }, 250);
}

function resetWatch() {
  watched.points = [];
  watched.lastStarted = 0;
  watched.result = null;
  $("step-table").tBodies[0].replaceChildren();
  $("result-view").hidden = true;
  watched.trials = 0;
  $("count-iterations").textContent = "0";
  $("count-iterations").dataset.events = "0";
  for (const k of ["open", "stick", "slip", "v2"]) $("count-" + k).textContent = "-";
  drawConvergence($("conv-plot"), [], watched.tolerance);  // at once: no stale points
}

function onEvent(seq, type, data) {
  if (type === "step_started") {
    // A step that is not after the last one: the server ran the job again (after a restart
    // it discards the interrupted run's events); start over with the new run.
    if (data.step <= watched.lastStarted) {
      resetWatch();
      $("stream-status").textContent = "the server restarted the job; showing the new run";
    }
    watched.lastStarted = data.step;
    $("job-status").textContent = `running: step ${data.step}, load factor ${data.load_factor}`;
  } else if (type === "iteration") {
    watched.points.push({ seq, step: data.step, v2: data.v2 });
    // Contact iterations are real solves: the events' trials (the job's and the result's count).
    watched.trials += data.trials;
    $("count-iterations").textContent = String(watched.trials);
    $("count-iterations").dataset.events = String(watched.points.length);
    for (const k of ["open", "stick", "slip"]) $("count-" + k).textContent = String(data[k]);
    $("count-v2").textContent = data.v2 === null ? "-" : data.v2.toExponential(3);
    queueConvergenceDraw();
  } else if (type === "step_finished") {
    const row = document.createElement("tr");
    row.dataset.step = data.step;
    cell(row, String(data.step));
    cell(row, String(data.load_factor));
    cell(row, data.converged ? "yes" : "no: " + (data.reason || ""),
      { class: data.converged ? "" : "bad", title: data.failure ? data.failure.kind : "" });
    cell(row, String(data.contact_iterations));
    cell(row, String(data.newton_iterations));
    cell(row, data.seconds.toFixed(3));
    // Keep the newest step in sight unless the reader scrolled up.
    const box = $("step-table").parentElement;
    const atEnd = box.scrollHeight - box.scrollTop - box.clientHeight < 40;  // within a row of the end
    $("step-table").tBodies[0].append(row);
    if (atEnd) box.scrollTop = box.scrollHeight;
  } else if (type === "job_finished" || type === "job_failed") {
    $("job-status").textContent = type === "job_finished" ? "finished: every step solved" : failureText(data.failure, data.reason);
    $("job-panel").dataset.state = type;
    $("job-panel").dataset.failure = data.failure ? data.failure.kind : "";
    refreshJobs();
    if (data.failure?.kind !== "dismissed") showResult(watched.id);  // a dismissed job keeps no result
  }
}

async function openJob(id) {
  watched.abort?.abort();
  const abort = new AbortController();
  Object.assign(watched, { id, abort });
  $("job-panel").hidden = false;
  $("job-panel").dataset.state = "watching";
  $("job-id").textContent = id;
  $("job-status").textContent = "";
  $("stream-status").textContent = "";
  resetWatch();
  watched.tolerance = JSON.parse(sessionStorage.getItem("grip.tolerance." + id) || "null");
  for (const row of $("jobs-table").tBodies[0].rows) row.toggleAttribute("aria-current", row.dataset.job === id);
  try {
    const job = await getJson(`/v1/jobs/${encodeURIComponent(id)}`);
    if (abort.signal.aborted) return;
    $("job-status").textContent = `${job.status}: ${job.message || ""}`;
    await followEvents(id, {
      signal: abort.signal,
      onEvent,
      onState: (text) => { if (!abort.signal.aborted) $("stream-status").textContent = text; },
    });
    if (!abort.signal.aborted) $("stream-status").textContent = "stream ended";
  } catch (e) {
    if (abort.signal.aborted) return;
    $("job-status").textContent = e.status === 404 ? "no such job (dismissed?)" : e.message;
    $("job-panel").dataset.state = "error";
  }
}

async function showResult(id) {
  let result;
  try {
    result = await getJson(`/v1/jobs/${encodeURIComponent(id)}/result`);
  } catch (e) {
    $("result-summary").textContent = e.message;
    return;
  }
  if (watched.id !== id) return;
  watched.result = result;
  watched.tolerance = absoluteTolerance(result.scene, result);
  queueConvergenceDraw();
  watched.bounds = bodyBounds(result);
  const s = result.summary;
  $("result-summary").textContent =
    `${s.completed ? "completed" : "stopped: " + s.reason}; ${s.steps} steps, ${s.contact_iterations} contact ` +
    `iterations, ${s.newton_iterations} Newton iterations, ${s.factorizations} factorizations, ${s.seconds.toFixed(3)} s`;
  const slider = $("step-slider");
  slider.max = String(Math.max(1, result.steps.length));
  const withFields = result.steps.map((st) => !!st.nodes).lastIndexOf(true);
  slider.value = String(withFields >= 0 ? withFields + 1 : result.steps.length);
  showStep();
  const base = `/v1/jobs/${encodeURIComponent(id)}`;
  const links = [
    ["result (JSON)", `${base}/result`, `result-${id}.json`],
    ["nodes (CSV)", `${base}/result?format=csv&table=nodes`, `nodes-${id}.csv`],
    ["contact points (CSV)", `${base}/result?format=csv&table=contact_points`, `contact_points-${id}.csv`],
    ["steps (CSV)", `${base}/result?format=csv&table=steps`, `steps-${id}.csv`],
    ["convergence (CSV)", `${base}/convergence?format=csv`, `convergence-${id}.csv`],
    ["VTK files for ParaView (tar)", `${base}/result?format=vtk`, `grip-${id.slice(0, 8)}-vtk.tar`],
  ];
  $("downloads").replaceChildren(...links.map(([text, href, name]) => {
    const li = document.createElement("li");
    const a = document.createElement("a");
    a.href = href;
    a.download = name;
    a.textContent = text;
    // Plain links cannot carry the bearer token: fetch and save instead.
    a.addEventListener("click", (ev) => {
      if (!token()) return;
      ev.preventDefault();
      download(href, name).catch((e) => showConnection(e));
    });
    li.append(a);
    return li;
  }));
  $("result-view").hidden = false;
  $("job-panel").dataset.state = "result";
}

function showStep() {
  const result = watched.result;
  if (!result || !result.steps.length) return;
  const k = Number($("step-slider").value);
  const step = result.steps[k - 1];
  $("step-value").textContent = `${k} of ${result.steps.length} (load factor ${step.load_factor})`;
  $("body-view").dataset.step = String(k);
  drawBody($("body-view"), result, step, watched.bounds);
  drawStress($("stress-plot"), result, step);
}

// ---- wiring
// #job=ID or #study=ID: one of them shown in the main column.
function route() {
  const job = location.hash.match(/^#job=([^&]+)$/);
  const study = location.hash.match(/^#study=([^&]+)$/);
  if (job) closeStudy();
  if (job && decodeURIComponent(job[1]) !== watched.id) openJob(decodeURIComponent(job[1]));
  if (study) {
    watched.abort?.abort();
    watched.id = null;
    $("job-panel").hidden = true;
    openStudy(decodeURIComponent(study[1]));
  }
}

function init() {
  document.documentElement.dataset.stateColours = JSON.stringify(STATE_COLOURS);
  $("token").value = token();
  $("token-form").addEventListener("submit", (ev) => {
    ev.preventDefault();
    setToken($("token").value.trim());
    refreshJobs();
    if ($("example").options.length <= 1) loadExamples();
  });
  $("jobs-newer").addEventListener("click", () => { list.index = Math.max(0, list.index - 1); refreshJobs(); });
  $("jobs-older").addEventListener("click", () => {
    if (!list.next) return;
    list.cursors[list.index + 1] = list.next;
    list.index += 1;
    refreshJobs();
  });
  $("example").addEventListener("change", async () => {
    const href = $("example").value;
    if (!href) return;
    try {
      $("scene").value = JSON.stringify(await getJson(href), null, 2);
      loadedExample = href;
      showErrors([]);
    } catch (e) {
      showConnection(e);
    }
  });
  $("scene-file").addEventListener("change", async () => {
    const file = $("scene-file").files[0];
    if (file) {
      $("scene").value = await file.text();
      loadedExample = null;
    }
  });
  $("submit-form").addEventListener("submit", submit);
  $("study-form").addEventListener("submit", (ev) => {
    ev.preventDefault();
    const id = $("study-open-id").value.trim();
    if (id) location.hash = "study=" + encodeURIComponent(id);
  });
  $("step-slider").addEventListener("input", showStep);
  window.addEventListener("hashchange", route);
  loadExamples();
  refreshJobs();
  setInterval(() => { if (!document.hidden) refreshJobs(); }, 2000);
  route();
}

init();
