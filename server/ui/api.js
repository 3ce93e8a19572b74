// The service's HTTP API as the page uses it: JSON calls with the bearer token, problem
// documents (RFC 9457) as ApiError, and the event stream read with fetch (EventSource cannot
// send an Authorization header), resumed with Last-Event-ID after a dropped connection.

const TOKEN_KEY = "grip.token";

export function token() {
  return sessionStorage.getItem(TOKEN_KEY) || "";
}

export function setToken(value) {
  if (value) sessionStorage.setItem(TOKEN_KEY, value);
  else sessionStorage.removeItem(TOKEN_KEY);
}

function headers(extra = {}) {
  const h = { Accept: "application/json", ...extra };
  if (token()) h.Authorization = "Bearer " + token();
  return h;
}

// An HTTP error: status (0: no answer), the problem document and its errors[] of {pointer, detail}.
export class ApiError extends Error {
  constructor(status, problem) {
    super(problem.detail || problem.title || `HTTP ${status}`);
    this.status = status;
    this.problem = problem;
    this.errors = Array.isArray(problem.errors) ? problem.errors : [];
  }
}

async function send(method, path, body, type = "application/json") {
  let res;
  try {
    res = await fetch(path, {
      method,
      headers: headers(body === undefined ? {} : { "Content-Type": type }),
      body,
      cache: "no-store",
    });
  } catch (e) {
    throw new ApiError(0, { title: "No answer", detail: "the server did not answer (" + e.message + ")" });
  }
  const text = await res.text();
  let doc = {};
  try {
    doc = text ? JSON.parse(text) : {};
  } catch {
    doc = { detail: text.slice(0, 200) };
  }
  if (!res.ok) throw new ApiError(res.status, doc);
  return doc;
}

export const getJson = (path) => send("GET", path);
export const dismissJob = (id) => send("DELETE", `/v1/jobs/${encodeURIComponent(id)}`);
// `text` is sent as it is: the server's own parser names the problems.
export const submitScene = (text) => send("POST", "/v1/jobs", text);
// A gmsh .msh file (a File or Blob) as its bytes: answered with its id and what was read.
export const uploadMesh = (blob) => send("POST", "/v1/meshes", blob, "application/octet-stream");

// A file the server serves (an example's mesh), as a Blob; null when it has none by that name.
export async function getBlob(path) {
  const res = await fetch(path, { headers: headers({ Accept: "*/*" }), cache: "no-store" });
  if (res.status === 404) return null;
  if (!res.ok) throw new ApiError(res.status, { detail: `${path}: ${res.status}` });
  return res.blob();
}

// A download with the token: fetched, then saved from a blob URL.
export async function download(path, filename) {
  const res = await fetch(path, { headers: headers({ Accept: "*/*" }), cache: "no-store" });
  if (!res.ok) throw new ApiError(res.status, { detail: `download failed (${res.status})` });
  const url = URL.createObjectURL(await res.blob());
  const a = document.createElement("a");
  a.href = url;
  a.download = filename;
  document.body.append(a);
  a.click();
  a.remove();
  setTimeout(() => URL.revokeObjectURL(url), 10000);
}

const sleep = (ms, signal) =>
  new Promise((resolve) => {
    const t = setTimeout(resolve, ms);
    signal?.addEventListener("abort", () => { clearTimeout(t); resolve(); }, { once: true });
  });

// Splits an event-stream text into complete events; returns [events, the unfinished rest].
function parseEvents(buffer) {
  const events = [];
  const blocks = buffer.replace(/\r\n?/g, "\n").split("\n\n");
  const rest = blocks.pop();
  for (const block of blocks) {
    const ev = { id: null, type: "message", data: "" };
    let hasData = false;
    for (const line of block.split("\n")) {
      if (!line || line.startsWith(":")) continue;  // ": ping" heartbeat
      const colon = line.indexOf(":");
      const field = colon < 0 ? line : line.slice(0, colon);
      const value = colon < 0 ? "" : line.slice(colon + 1).replace(/^ /, "");
      if (field === "id") ev.id = Number(value);
      else if (field === "event") ev.type = value;
      else if (field === "data") { ev.data += (hasData ? "\n" : "") + value; hasData = true; }
      else if (field === "retry") ev.retry = Number(value);
    }
    if (hasData || ev.retry) events.push(ev);
  }
  return [events, rest];
}

// Follows an event stream (`path`) until an event of `endTypes`, or until `signal` aborts. Calls
// onEvent(seq, type, data) once per event in order, and onState(text) when the connection
// drops or comes back. After a drop it reconnects with Last-Event-ID = the last event seen,
// so no event of a job is lost or repeated (a study's stream sends its whole table again);
// it keeps trying while the server is away.
async function followStream(path, endTypes, { onEvent, onState, signal }) {
  let last = 0;
  let retryMs = 1000;
  let failures = 0;
  while (!signal.aborted) {
    let ended = false;
    try {
      const h = headers({ Accept: "text/event-stream" });
      if (last > 0) h["Last-Event-ID"] = String(last);
      const res = await fetch(path, { headers: h, signal, cache: "no-store" });
      if (res.status === 404 || res.status === 401) {
        const doc = await res.json().catch(() => ({}));
        throw new ApiError(res.status, doc);
      }
      if (res.ok) {
        if (failures > 0) onState(`connected again; resumed after event ${last}`);
        else onState("connected");
        failures = 0;
        const reader = res.body.pipeThrough(new TextDecoderStream()).getReader();
        let buffer = "";
        for (;;) {
          const { value, done } = await reader.read();
          if (done) break;
          let events;
          [events, buffer] = parseEvents(buffer + value);
          for (const ev of events) {
            if (ev.retry) retryMs = ev.retry;
            if (!ev.data) continue;
            if (ev.id !== null) last = ev.id;
            const data = JSON.parse(ev.data);
            onEvent(ev.id, ev.type, data);
            if (endTypes.includes(ev.type)) ended = true;
          }
          if (ended) { reader.cancel().catch(() => {}); return; }
        }
      } else {
        const wait = Number(res.headers.get("Retry-After"));
        if (wait > 0) await sleep(wait * 1000, signal);
      }
    } catch (e) {
      if (signal.aborted) return;
      if (e instanceof ApiError) throw e;
    }
    failures += 1;
    onState(`connection lost after event ${last}; reconnecting (attempt ${failures})`);
    await sleep(Math.min(retryMs * failures, 5000), signal);
  }
}

// A job's events, until job_finished or job_failed.
export const followEvents = (id, options) =>
  followStream(`/v1/jobs/${encodeURIComponent(id)}/events`, ["job_finished", "job_failed"], options);

// A study's table (docs/design.md#studies): a `study` event each time it changes, then
// `study_finished`; each event's data is the whole table, as GET /v1/studies/{id}.
export const followStudy = (id, options) =>
  followStream(`/v1/studies/${encodeURIComponent(id)}/events`, ["study_finished"], options);
