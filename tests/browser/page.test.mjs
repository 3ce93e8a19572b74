// The page of `grip serve` in a real browser: Debian's headless Chromium driven by
// puppeteer-core (tests/browser/package-lock.json, installed by scripts/setup.sh with npm ci).
// Against a live `grip serve` on a free loopback port: a running job watched live and across a
// server restart, the beam example submitted and shown, a bad scene's pointer errors, gmsh
// meshes uploaded beside a scene, studies followed (table and plots). Screenshots go to
// $GRIP_ARTIFACTS (default build/browser-artifacts), never committed.
//   GRIP_BINARY=build/apps/grip node --test tests/browser/page.test.mjs
import { test, before, after } from "node:test";
import assert from "node:assert/strict";
import { spawn } from "node:child_process";
import { createServer, connect } from "node:net";
import { mkdtempSync, mkdirSync, readFileSync, rmSync, openSync, writeFileSync } from "node:fs";
import { createHash } from "node:crypto";
import { tmpdir } from "node:os";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";
import puppeteer from "puppeteer-core";

const REPO = resolve(dirname(fileURLToPath(import.meta.url)), "../..");
const GRIP = process.env.GRIP_BINARY || join(REPO, "build/apps/grip");
const CHROMIUM = process.env.CHROMIUM || "/usr/bin/chromium";
const ARTIFACTS = process.env.GRIP_ARTIFACTS || join(REPO, "build/browser-artifacts");
const example = (name) => JSON.parse(readFileSync(join(REPO, "schemas/examples", name + ".json"), "utf8"));
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// ---- a throwaway `grip serve`: temp folder, loopback, the port read from its log.
class Server {
  constructor(extraArgs = []) {
    this.dir = mkdtempSync(join(tmpdir(), "grip-browser-"));
    this.port = 0;
    this.extraArgs = extraArgs;
  }
  async start() {
    const log = join(this.dir, `server-${Date.now()}.log`);
    const fd = openSync(log, "w");
    this.proc = spawn(GRIP, ["serve", "--host", "127.0.0.1", "--port", String(this.port),
                             "--db", join(this.dir, "jobs.sqlite"), "--workers", "2", "--grace", "0",
                             "--heartbeat", "1", "--schemas", join(REPO, "schemas"), ...this.extraArgs],
                      { stdio: ["ignore", fd, fd], cwd: this.dir });
    const deadline = Date.now() + 30000;
    while (Date.now() < deadline) {
      const m = readFileSync(log, "utf8").match(/listening on http:\/\/[0-9.]+:(\d+)/);
      if (m) {
        this.port = Number(m[1]);
        this.url = `http://127.0.0.1:${this.port}`;
        return;
      }
      if (this.proc.exitCode !== null) break;
      await sleep(50);
    }
    throw new Error("grip serve did not start:\n" + readFileSync(log, "utf8"));
  }
  async stop() {
    if (!this.proc || this.proc.exitCode !== null) return;
    const exited = new Promise((r) => this.proc.once("exit", r));
    this.proc.kill("SIGTERM");
    let timer;
    await Promise.race([exited, new Promise((r) => { timer = setTimeout(r, 20000); })]);
    clearTimeout(timer);  // a pending timer would keep node running
    if (this.proc.exitCode === null) this.proc.kill("SIGKILL");
  }
  async api(path, init = {}) {
    if (this.token) init = { ...init, headers: { ...init.headers, Authorization: "Bearer " + this.token } };
    const res = await fetch(this.url + path, init);
    const text = await res.text();
    return { status: res.status, headers: res.headers, body: text.startsWith("{") ? JSON.parse(text) : text };
  }
  submit(scene) {
    return this.api("/v1/jobs", { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(scene) });
  }
  // Every event of a finished job from its SSE replay: [{seq, type, data}].
  async events(id) {
    const text = (await this.api(`/v1/jobs/${id}/events`)).body;
    return text.split("\n\n").filter((b) => b.includes("data:")).map((b) => {
      const f = Object.fromEntries(b.split("\n").map((l) => [l.slice(0, l.indexOf(":")), l.slice(l.indexOf(":") + 2)]));
      return { seq: Number(f.id), type: f.event, data: JSON.parse(f.data) };
    });
  }
}

// A loopback TCP proxy to the server that cuts the first event stream after `cutAfter` bytes
// of its response: those bytes are passed on, the rest is held back, and half a second later
// (time for the page to read them) both sockets are destroyed. Records every request head.
async function cuttingProxy(target, cutAfter) {
  const proxy = { heads: [], cut: false };
  proxy.server = createServer((client) => {
    const upstream = connect(target, "127.0.0.1");
    let limit = null;
    let sent = 0;
    // The browser keeps connections alive: every request head on one, each a GET without body.
    client.on("data", (d) => {
      for (const head of d.toString("latin1").split("\r\n\r\n").filter((h) => /^[A-Z]+ \S+ HTTP/.test(h))) {
        proxy.heads.push(head);
        if (/^GET [^ ]*\/events/.test(head) && !proxy.cut) { proxy.cut = true; limit = cutAfter; sent = 0; }
      }
      upstream.write(d);
    });
    upstream.on("data", (d) => {
      if (limit !== null && sent >= limit) return;  // cut: held back
      if (limit !== null && sent + d.length >= limit) {
        client.write(d.subarray(0, limit - sent));
        sent = limit;
        // A FIN, not a reset: a reset makes the receiving kernel drop what the page has not
        // read yet, and the page would then rightly restart from nothing.
        setTimeout(() => { client.end(); upstream.destroy(); }, 500);
        return;
      }
      sent += d.length;
      client.write(d);
    });
    for (const [a, b] of [[client, upstream], [upstream, client]]) {
      a.on("end", () => b.end());
      a.on("error", () => b.destroy());
    }
  });
  await new Promise((r) => proxy.server.listen(0, "127.0.0.1", r));
  proxy.url = `http://127.0.0.1:${proxy.server.address().port}`;
  return proxy;
}

// A beam of many elements: about ten contact iterations a second, for minutes.
function slowBeam() {
  const s = example("beam-on-cylinder");
  s.body.mesh.elements = 1500;
  s.body.loads[0].node = 1500;
  s.steps = 400;
  return s;
}

const server = new Server();
let browser, page;
const problems = [];  // console errors, page errors, CSP violations

before(async () => {
  mkdirSync(ARTIFACTS, { recursive: true });
  await server.start();
  browser = await puppeteer.launch({
    executablePath: CHROMIUM,
    headless: true,
    // Chromium's sandbox refuses to run as root (containers, CI); as any other user it stays on.
    args: process.getuid?.() === 0 ? ["--no-sandbox"] : [],
  });
  page = await browser.newPage();
  await page.setViewport({ width: 1280, height: 800 });
  page.on("console", (m) => { if (m.type() === "error") problems.push("console: " + m.text()); });
  page.on("pageerror", (e) => problems.push("page error: " + e.message));
  await page.evaluateOnNewDocument(() => {
    document.addEventListener("securitypolicyviolation", (e) => console.error(`CSP violation: ${e.violatedDirective} ${e.blockedURI}`));
  });
});

after(async () => {
  await browser?.close();
  await server.stop();
  rmSync(server.dir, { recursive: true, force: true });
});

const count = (selector) => page.$$eval(selector, (els) => els.length);
// The plot redraws at most every 250 ms: wait until it holds every iteration event so far.
const plotCaughtUp = (tab) => tab.waitForFunction(() =>
  document.getElementById("conv-plot").dataset.points === document.getElementById("count-iterations").dataset.events);
const text = (selector) => page.$eval(selector, (el) => el.textContent);

test("the page is served with ETag, caching and CSP; JSON clients still get the landing document", async () => {
  const html = await server.api("/", { headers: { Accept: "text/html,application/xhtml+xml,*/*;q=0.8" } });
  assert.equal(html.status, 200);
  assert.match(html.headers.get("content-type"), /^text\/html/);
  assert.match(html.headers.get("content-security-policy"), /default-src 'none'; script-src 'self'/);
  assert.equal(html.headers.get("cache-control"), "no-cache");
  const etag = html.headers.get("etag");
  assert.match(etag, /^"[0-9a-f]{20}"$/);
  assert.equal((await server.api("/ui", { headers: { "If-None-Match": etag } })).status, 304);
  const js = await server.api("/ui/app.js");
  assert.match(js.headers.get("content-type"), /^text\/javascript/);
  assert.notEqual(js.headers.get("etag"), etag);
  const landing = await server.api("/", { headers: { Accept: "application/json" } });
  assert.equal(landing.body.title, "grip");
  assert.equal((await server.api("/ui/missing.js")).status, 404);
});

test("a running job: the plot grows live, and resumes across a server restart without gaps", async () => {
  const started = Date.now();
  const job = (await server.submit(slowBeam())).body;
  await page.goto(`${server.url}/#job=${job.jobID}`);
  await page.waitForFunction(() => document.querySelectorAll("#conv-plot circle.pt").length >= 8, { timeout: 30000 });
  assert.equal(await text("#job-id"), job.jobID);
  assert.match(await text("#job-status"), /running: step \d+/);
  const rows = await count("#step-table tbody tr");
  assert.ok(rows >= 1, "steps finished so far are in the table");
  await page.screenshot({ path: join(ARTIFACTS, "running.png"), fullPage: true });

  // Restart the server mid-stream: the page loses its stream, retries, and resumes with
  // Last-Event-ID; the interrupted run's events are discarded by the server and the job runs
  // again, so the page starts the plot over with the new run.
  const seqBefore = await page.$$eval("#conv-plot circle.pt", (els) => Math.max(...els.map((e) => Number(e.dataset.seq))));
  await server.stop();
  await page.waitForFunction(() => /connection lost/.test(document.getElementById("stream-status").textContent), { timeout: 15000 });
  await server.start();  // same port, same database
  await page.waitForFunction(() => /restarted the job/.test(document.getElementById("stream-status").textContent), { timeout: 30000 });
  // The new run's points: numbered after the old run's (event ids are never reused).
  await page.waitForFunction((before) => {
    const pts = [...document.querySelectorAll("#conv-plot circle.pt")];
    return pts.length >= 4 && Number(pts[0].dataset.seq) > before;
  }, { timeout: 30000 }, seqBefore);
  await page.screenshot({ path: join(ARTIFACTS, "running-after-restart.png"), fullPage: true });

  // Dismiss from the list; the page ends with job_failed (dismissed), holding exactly the
  // server's iteration events of the run.
  await page.waitForSelector(`#jobs-table tr[data-job="${job.jobID}"] button[aria-label^="dismiss"]`);
  // Clicked inside the page in one go: the list re-renders its rows every 2 s, and a click
  // from outside (find, scroll, then press) can land on a row that was just replaced.
  await page.$eval(`#jobs-table tr[data-job="${job.jobID}"] button[aria-label^="dismiss"]`, (b) => b.click());
  await page.waitForFunction(() => document.getElementById("job-panel").dataset.state !== "watching", { timeout: 30000 });
  assert.equal(await page.$eval("#job-panel", (e) => e.dataset.failure), "dismissed");
  assert.match(await text("#job-status"), /dismissed/);
  assert.equal((await server.api(`/v1/jobs/${job.jobID}`)).body.status, "dismissed");
  await plotCaughtUp(page);
  const serverSeqs = (await server.events(job.jobID)).filter((e) => e.type === "iteration").map((e) => e.seq);
  const pageSeqs = await page.$$eval("#conv-plot circle.pt", (els) => els.map((e) => Number(e.dataset.seq)));
  assert.deepEqual(pageSeqs, serverSeqs);
  console.log(`# running job, restart and dismissal: ${((Date.now() - started) / 1000).toFixed(1)} s, ${pageSeqs.length} points after the restart`);
});

test("the beam example: submitted from the page, watched to the end, its result drawn", async () => {
  await page.bringToFront();
  await page.goto(server.url + "/ui");
  await page.waitForFunction(() => document.querySelectorAll("#example option").length > 1);
  await page.select("#example", "/v1/examples/beam-on-cylinder");
  await page.waitForFunction(() => document.getElementById("scene").value.includes("beam-on-cylinder"));
  await page.click("#submit");
  await page.waitForFunction(() => document.getElementById("job-panel").dataset.state === "result", { timeout: 60000 });
  await plotCaughtUp(page);
  const id = await text("#job-id");
  const result = (await server.api(`/v1/jobs/${id}/result`)).body;
  const events = await server.events(id);

  // One point per iteration event, in order, each in its step's colour.
  const iterations = events.filter((e) => e.type === "iteration");
  assert.ok(iterations.length > 20);
  const points = await page.$$eval("#conv-plot circle.pt", (els) => els.map((e) => ({ seq: Number(e.dataset.seq), step: Number(e.dataset.step) })));
  assert.deepEqual(points, iterations.map((e) => ({ seq: e.seq, step: e.data.step })));
  // The count shown is the job's: real solves, the events' trials.
  const solves = iterations.reduce((n, e) => n + e.data.trials, 0);
  assert.equal(solves, result.summary.contact_iterations);
  assert.equal(await page.$eval("#count-iterations", (e) => Number(e.textContent)), solves);
  // The tolerance line: 1e-8 x the beam's 30 cm.
  const tol = await page.$eval("#tolerance-line", (e) => Number(e.dataset.value));
  assert.ok(Math.abs(tol - 30e-8) < 1e-15, `tolerance ${tol}`);

  // The step table equals the result's steps.
  const table = await page.$$eval("#step-table tbody tr", (rows) => rows.map((r) => [...r.cells].map((c) => c.textContent)));
  assert.equal(table.length, result.steps.length);
  table.forEach((row, k) => {
    const s = result.steps[k];
    assert.equal(Number(row[0]), s.step);
    assert.equal(Number(row[1]), s.load_factor);
    assert.equal(row[2], s.converged ? "yes" : `no: ${s.reason}`);
    assert.equal(Number(row[3]), s.contact_iterations);
    assert.equal(Number(row[4]), s.newton_iterations);
  });

  // The table followed the steps: its last row is in sight.
  assert.ok(await page.$eval("#step-table", (t) => {
    const box = t.parentElement;
    return box.scrollHeight - box.scrollTop - box.clientHeight < 2;
  }), "the step table is scrolled to its last row");

  // Contact points: one per candidate of the step shown, coloured as the legend says for its state.
  const legend = await page.evaluate(() => Object.fromEntries(["open", "stick", "slip"].map((s) =>
    [s, getComputedStyle(document.querySelector(`#result-view .key.${s}`), "::before").backgroundColor])));
  const rgb = (hex) => `rgb(${[1, 3, 5].map((i) => parseInt(hex.slice(i, i + 2), 16)).join(", ")})`;
  async function checkStep(k) {
    assert.equal(await page.$eval("#body-view", (e) => Number(e.dataset.step)), k);
    const drawn = await page.$$eval("#body-view circle.cp", (els) => els.map((e) =>
      ({ node: Number(e.dataset.node), state: e.dataset.state, fill: e.getAttribute("fill") })));
    const expected = result.steps[k - 1].contact_points;
    assert.equal(drawn.length, expected.length);
    drawn.forEach((d, i) => {
      assert.equal(d.node, expected[i].node);
      assert.equal(d.state, expected[i].state);
      assert.equal(rgb(d.fill), legend[d.state], `node ${d.node} (${d.state}) drawn ${d.fill}`);
    });
    return new Set(drawn.map((d) => d.state));
  }
  const last = result.steps.length;
  const statesLast = await checkStep(last);
  assert.ok(statesLast.size >= 2, `the last step shows several states: ${[...statesLast]}`);
  assert.equal(await count("#stress-plot circle.sigma_n-pt"), result.steps[last - 1].contact_points.length);
  await page.screenshot({ path: join(ARTIFACTS, "finished.png"), fullPage: true });

  // The step slider by keyboard: Home goes to step 1.
  await page.focus("#step-slider");
  await page.keyboard.press("Home");
  await checkStep(1);

  // Downloads: JSON, CSV and VTK links that answer.
  const links = await page.$$eval("#downloads a", (as) => as.map((a) => a.getAttribute("href")));
  for (const want of ["/result", "format=csv&table=nodes", "format=csv&table=contact_points", "/convergence?format=csv", "format=vtk"])
    assert.ok(links.some((h) => h.includes(want)), `a download link with ${want}`);
  for (const href of links) assert.equal((await server.api(href)).status, 200, href);

  // Phone width: everything fits across.
  await page.setViewport({ width: 390, height: 844 });
  await sleep(200);
  assert.ok(await page.evaluate(() => document.documentElement.scrollWidth <= window.innerWidth + 1), "no sideways scrolling at 390 px");
  await page.screenshot({ path: join(ARTIFACTS, "finished-phone.png"), fullPage: true });
  await page.setViewport({ width: 1280, height: 800 });
});

test("a bad scene: errors next to the pointers the server names, nothing queued", async () => {
  await page.bringToFront();
  await page.goto(server.url + "/ui");
  const before = (await server.api("/v1/jobs?limit=1000")).body.jobs.length;
  const bad = example("beam-on-cylinder");
  bad.body.material.young = -1;
  bad.obstacles[0].friction = "high";
  const expected = (await server.submit(bad)).body;  // the API's own answer, for comparison
  assert.equal(expected.status, 422);

  await page.$eval("#scene", (e, t) => { e.value = t; }, JSON.stringify(bad, null, 2));
  await page.click("#submit");
  await page.waitForSelector("#submit-errors li");
  const shown = await page.$$eval("#submit-errors li", (lis) => lis.map((li) =>
    ({ pointer: li.dataset.pointer, code: li.querySelector("code.pointer").textContent, text: li.textContent })));
  assert.deepEqual(shown.map((s) => s.pointer), expected.errors.map((e) => e.pointer));
  assert.ok(shown.some((s) => s.code === "/body/material/young"));
  assert.ok(shown.some((s) => s.code === "/obstacles/0/friction"));
  shown.forEach((s, i) => assert.ok(s.text.includes(expected.errors[i].detail)));
  await page.screenshot({ path: join(ARTIFACTS, "bad-scene.png"), fullPage: true });

  // Upload: the file's text lands in the editor.
  const input = await page.$("#scene-file");
  await input.uploadFile(join(REPO, "schemas/examples/sliding-block.json"));
  await page.waitForFunction(() => document.getElementById("scene").value.includes("sliding"));
  assert.equal(await page.$eval("#scene", (e) => e.value), readFileSync(join(REPO, "schemas/examples/sliding-block.json"), "utf8"));

  // Not JSON at all: found by the page, never sent.
  await page.$eval("#scene", (e) => { e.value = "{\"body\": "; });
  await page.click("#submit");
  await page.waitForFunction(() => /not JSON/.test(document.getElementById("submit-errors").textContent));
  assert.equal((await server.api("/v1/jobs?limit=1000")).body.jobs.length, before);
});

test("gmsh meshes: an example's mesh and a chosen .msh are uploaded and named by their ids", async () => {
  await page.bringToFront();
  await page.goto(server.url + "/ui");
  const sha256 = (path) => createHash("sha256").update(readFileSync(path)).digest("hex");
  const until = (state) => page.waitForFunction((s) => document.getElementById("job-panel").dataset.state === s, { timeout: 60000 }, state);

  // hertz-t6 names its mesh as a file: the page uploads the server's copy and submits its id.
  await page.waitForFunction(() => document.querySelectorAll("#example option").length > 1);
  await page.select("#example", "/v1/examples/hertz-t6");
  await page.waitForFunction(() => document.getElementById("scene").value.includes("hertz-t6.msh"));
  await page.click("#submit");
  await until("result");
  let id = await text("#job-id");
  let result = (await server.api(`/v1/jobs/${id}/result`)).body;
  const hertzId = sha256(join(REPO, "schemas/examples/hertz-t6.msh"));
  assert.deepEqual(result.scene.body.mesh.gmsh, { id: hertzId, surfaces: [] });
  assert.equal(result.summary.completed, true);
  assert.equal((await server.api(`/v1/meshes/${hertzId}`)).body.elements.t6 > 0, true);
  // Its 6-node triangles drawn by their corners, one path per cell.
  assert.equal(await count("#body-view path.cell"), result.mesh.cells.length);
  await page.screenshot({ path: join(ARTIFACTS, "gmsh-example.png"), fullPage: true });

  // A scene of one's own naming block.msh: refused at its pointer until the file is chosen.
  const block = example("sliding-block");
  delete block.body.element;
  block.body.mesh = { gmsh: { file: "block.msh" } };
  const input = await page.$("#scene-file");
  const sceneFile = join(server.dir, "block-scene.json");
  writeFileSync(sceneFile, JSON.stringify(block));
  await input.uploadFile(sceneFile);  // another scene: the example's files no longer apply
  await page.waitForFunction(() => document.getElementById("scene").value.includes("block.msh"));
  const jobsBefore = (await server.api("/v1/jobs?limit=1000")).body.jobs.length;
  await page.click("#submit");
  await page.waitForSelector("#submit-errors li[data-pointer='/body/mesh/gmsh/file']");
  assert.match(await text("#submit-errors"), /choose block\.msh/);
  assert.equal((await server.api("/v1/jobs?limit=1000")).body.jobs.length, jobsBefore);

  const blockMsh = join(REPO, "tests/data/gmsh/block.msh");
  await (await page.$("#mesh-files")).uploadFile(blockMsh);
  await page.click("#submit");
  await page.waitForFunction((old) => document.getElementById("job-id").textContent !== old, { timeout: 30000 }, id);
  await until("result");
  id = await text("#job-id");
  result = (await server.api(`/v1/jobs/${id}/result`)).body;
  assert.equal(result.scene.body.mesh.gmsh.id, sha256(blockMsh));
  assert.equal(result.mesh.cells.length, 200);  // gmsh's 20 x 10 quadrilaterals
  assert.equal((await server.api("/v1/jobs?limit=1000")).body.jobs.length, jobsBefore + 1);
  assert.equal(await page.$$eval("#submit-errors li", (lis) => lis.length), 0);
});

// The page cannot resume what it never read: when the browser surfaces nothing of the cut
// response before its end (Chromium does that for a part of a chunk now and then), the page
// rightly starts again from the first event. So the cut is tried again, up to five times, until
// the page reconnects with Last-Event-ID; every attempt must show every event once.
test("a stream dropped mid-way resumes with Last-Event-ID: every event once, none missing", async () => {
  const heads = [];
  for (let attempt = 1; attempt <= 5; attempt++) {
    const resumedAt = await cutStreamOnce();
    heads.push(resumedAt.head);
    if (resumedAt.id > 0) return;
  }
  assert.fail(`no attempt reconnected with Last-Event-ID:\n${heads.join("\n----\n")}`);
});

async function cutStreamOnce() {
  const job = (await server.submit(example("beam-on-cylinder"))).body;
  const proxy = await cuttingProxy(server.port, 6000);
  const tab = await browser.newPage();
  try {
    await tab.goto(`${proxy.url}/#job=${job.jobID}`);
    await tab.waitForFunction(() => document.getElementById("job-panel").dataset.state === "result", { timeout: 60000 });
    await plotCaughtUp(tab);
    const streams = proxy.heads.filter((h) => /^GET [^ ]*\/events/.test(h));
    assert.ok(streams.length >= 2, `the page reconnected: ${streams.length} stream requests`);
    const resumedAt = Number(streams[1].match(/last-event-id: (\d+)/i)?.[1] || 0);
    const serverSeqs = (await server.events(job.jobID)).filter((e) => e.type === "iteration").map((e) => e.seq);
    const pageSeqs = await tab.$$eval("#conv-plot circle.pt", (els) => els.map((e) => Number(e.dataset.seq)));
    if (resumedAt > 0) assert.ok(pageSeqs.some((q) => q < resumedAt) && pageSeqs.some((q) => q > resumedAt), "points on both sides of the cut");
    assert.deepEqual(pageSeqs, serverSeqs);
    const steps = await tab.$$eval("#step-table tbody tr", (rows) => rows.map((r) => Number(r.dataset.step)));
    assert.deepEqual(steps, Array.from({ length: 20 }, (_, k) => k + 1));
    return { id: resumedAt, head: streams[1] };
  } finally {
    await tab.close();
    proxy.server.close();
  }
}

test("the job list: newest first, ten to a page, Older and Newer", async () => {
  const tiny = example("beam-on-cylinder");
  Object.assign(tiny, { steps: 2 });
  Object.assign(tiny.body.mesh, { elements: 4 });
  tiny.body.loads[0].node = 4;
  for (let i = 0; i < 11; i++) assert.equal((await server.submit(tiny)).status, 201);
  const all = (await server.api("/v1/jobs?limit=1000")).body.jobs.map((j) => j.jobID);
  assert.ok(all.length > 10);
  await page.bringToFront();
  await page.goto(server.url + "/ui");
  const rows = () => page.$$eval("#jobs-table tbody tr", (trs) => trs.map((tr) => tr.dataset.job));
  await page.waitForFunction(() => document.querySelectorAll("#jobs-table tbody tr").length === 10);
  assert.deepEqual(await rows(), all.slice(0, 10));
  await page.click("#jobs-older");
  await page.waitForFunction(() => document.getElementById("jobs-page").textContent === "page 2");
  assert.deepEqual(await rows(), all.slice(10, 20));
  await page.click("#jobs-newer");
  await page.waitForFunction(() => document.getElementById("jobs-page").textContent === "page 1");
  assert.deepEqual(await rows(), all.slice(0, 10));
});

test("with a bearer token: the page asks for it, keeps it in sessionStorage, and works", async () => {
  const secured = new Server(["--token", "page-test-token"]);
  await secured.start();
  const tab = await browser.newPage();
  try {
    await tab.goto(secured.url + "/");  // the page itself needs no token
    await tab.waitForFunction(() => /wants a bearer token/.test(document.getElementById("connection").textContent));
    await tab.type("#token", "page-test-token");
    await tab.click("#token-form button");
    await tab.waitForFunction(() => document.querySelectorAll("#example option").length > 1);
    assert.equal(await tab.evaluate(() => sessionStorage.getItem("grip.token")), "page-test-token");
    await tab.select("#example", "/v1/examples/beam-on-cylinder");
    await tab.waitForFunction(() => document.getElementById("scene").value.includes("beam-on-cylinder"));
    await tab.click("#submit");
    await tab.waitForFunction(() => document.getElementById("job-panel").dataset.state === "result", { timeout: 60000 });
    // The result can be shown before the last iteration events are drawn: wait for them.
    await tab.waitForFunction(() => document.querySelectorAll("#conv-plot circle.pt").length > 20, { timeout: 10000 });
    // A reload keeps the token (same tab).
    await tab.reload();
    await tab.waitForFunction(() => document.querySelectorAll("#jobs-table tbody tr").length === 1);
  } finally {
    await tab.close();
    await secured.stop();
    rmSync(secured.dir, { recursive: true, force: true });
  }
});

// Lame's thick cylinder (axisymmetric, inner pressure), as tests/integration/studies_test.cpp.
function cylinder() {
  return {
    body: {
      model: "continuum", kinematics: "linear", analysis: "axisymmetric", element: "q4",
      material: { young: 1000, poisson: 0.3, law: "saint_venant_kirchhoff" },
      mesh: { rectangle: { origin: [1, 0], size: [1, 0.5], divisions: [2, 1] } },
      contact_set: "right",
      supports: [{ set: "bottom", fix: ["y"] }, { set: "top", fix: ["y"] }],
      loads: [{ set: "left", traction: [10, 0] }],
    },
    obstacles: [{ name: "far", shape: { type: "segment", from: [100, 50], to: [200, 50] } }],
    steps: 1,
    solver: { contact: { reach: 0.01 } },
    outputs: [
      { name: "u_inner", kind: "displacement", at: [1, 0], component: "x" },
      { name: "u_outer", kind: "displacement", at: [2, 0], component: "x" },
    ],
  };
}

test("a study: its table as GET /v1/studies/{id} says, its error plots a point per job with an estimate", async () => {
  const post = async (request) => {
    const r = await server.api("/v1/studies", { method: "POST", headers: { "Content-Type": "application/json" }, body: JSON.stringify(request) });
    assert.equal(r.status, 201, JSON.stringify(r.body));
    return r.body.id;
  };
  await page.bringToFront();
  await page.goto(server.url + "/ui");
  const openFinished = async (id) => {
    await page.$eval("#study-open-id", (e) => { e.value = ""; });
    await page.type("#study-open-id", id);
    await page.click("#study-form button");
    await page.waitForFunction((sid) => document.getElementById("study-shown-id").textContent === sid &&
      document.getElementById("study-panel").dataset.state === "finished", { timeout: 60000 }, id);
    const study = (await server.api(`/v1/studies/${id}`)).body;
    assert.equal(study.status, "successful");
    return study;
  };
  const withEstimate = (q) => q.estimated_error.filter((e) => Number.isFinite(e) && e > 0).length;
  const plotted = (q, plot) => count(`#study-quantities .quantity[data-quantity="${q}"] svg.${plot} circle.pt`);

  // Three levels of the cylinder: every number of the table is the server's.
  const study = await openFinished(await post({ scene: cylinder(), refine: { levels: 3 } }));
  assert.equal(await page.evaluate(() => location.hash), `#study=${study.id}`);
  assert.equal(await page.$eval("#job-panel", (e) => e.hidden), true);
  const rows = await page.$$eval("#study-levels tbody tr", (trs) => trs.map((tr) => ({
    job: tr.dataset.job,
    cells: [...tr.cells].map((c) => c.textContent),
    values: [...tr.cells].map((c) => c.dataset.value),
    outputs: Object.fromEntries([...tr.querySelectorAll("td[data-quantity]")].map((c) => [c.dataset.quantity, Number(c.dataset.value)])),
    errors: Object.fromEntries([...tr.querySelectorAll("td[data-error]")].map((c) => [c.dataset.error, Number(c.dataset.value)])),
  })));
  assert.equal(rows.length, 3);
  const head = await page.$$eval("#study-levels thead th", (ths) => ths.map((th) => th.textContent));
  assert.deepEqual(head, ["level", "h", "nodes", "seconds", "status", "u_inner", "u_inner est. error", "u_outer", "u_outer est. error"]);
  study.levels.forEach((level, i) => {
    assert.equal(rows[i].job, level.job);
    assert.equal(Number(rows[i].cells[0]), level.level);
    assert.equal(Number(rows[i].cells[1]), level.h);
    assert.equal(Number(rows[i].cells[2]), level.nodes);
    assert.equal(Number(rows[i].values[3]), level.seconds);
    assert.equal(rows[i].cells[4], "successful");
    assert.deepEqual(rows[i].outputs, level.outputs);
    for (const q of study.quantities) assert.equal(rows[i].errors[q.name], q.estimated_error[i]);
  });
  for (const q of study.quantities) {
    const summary = await page.$$eval(`#study-quantities .quantity[data-quantity="${q.name}"] dd`, (dds) =>
      Object.fromEntries(dds.map((d) => [d.dataset.key, d.dataset.value ?? d.textContent])));
    assert.equal(Number(summary.order), q.order);
    assert.equal(Number(summary.extrapolated), q.extrapolated);
    assert.equal(summary.asymptotic, "not known");  // three levels: nothing tells
    const cheapest = await page.$$eval(`#study-quantities .quantity[data-quantity="${q.name}"] .cheapest li`, (lis) => lis.map((li) => li.textContent));
    assert.equal(cheapest.length, 3);
    q.cheapest.forEach((c, k) => assert.match(cheapest[k], c.level ? new RegExp(`level ${c.level.level},`) : /none/));
    assert.equal(withEstimate(q), 3);
    assert.equal(await plotted(q.name, "error-h"), withEstimate(q));
    assert.equal(await plotted(q.name, "error-seconds"), withEstimate(q));
  }
  // The error against h: the finest level lowest, as the estimates say.
  const ys = await page.$$eval('.quantity[data-quantity="u_inner"] svg.error-h circle.pt', (cs) => cs.map((c) => [Number(c.dataset.x), Number(c.dataset.y)]));
  assert.deepEqual(ys.sort((a, b) => a[0] - b[0]).map((p) => p[1]), [...study.quantities[0].estimated_error].reverse());
  await page.screenshot({ path: join(ARTIFACTS, "study.png"), fullPage: true });

  // Two tolerances: a series each in the error plots, a point per job.
  const tolerances = await openFinished(await post({ scene: cylinder(), refine: { levels: 3 }, tolerances: [1e-4, 1e-8] }));
  assert.equal(await count("#study-levels tbody tr"), 6);
  for (const q of tolerances.quantities) {
    assert.equal(await plotted(q.name, "error-h"), withEstimate(q));
    assert.equal(await plotted(q.name, "error-seconds"), withEstimate(q));
    const series = await page.$$eval(`.quantity[data-quantity="${q.name}"] svg.error-h circle.pt`, (cs) => [...new Set(cs.map((c) => c.dataset.series))]);
    assert.deepEqual(series.sort(), ["tol 0.0001", "tol 1e-8"]);
  }

  // A sweep of the inner pressure: the quantity against it, linear in the load.
  const sweep = await openFinished(await post({ scene: cylinder(), sweep: [{ pointer: "/body/loads/0/traction/0", values: [5, 10, 20] }] }));
  const points = await page.$$eval('.quantity[data-quantity="u_inner"] svg.sweep-plot circle.pt', (cs) => cs.map((c) => [Number(c.dataset.x), Number(c.dataset.y)]));
  assert.deepEqual(points, sweep.levels.map((l, i) => [l.parameters[0], sweep.quantities[0].values[i]]));

  // An accuracy study: its answer.
  const accuracy = await openFinished(await post({ scene: cylinder(), accuracy: { output: "u_inner", relative: 0.01 } }));
  assert.equal(accuracy.answer.reached, true);
  const six = (x) => String(+x.toPrecision(6));
  assert.equal(await text("#study-answer"), `reached: level ${accuracy.answer.level}, value ${six(accuracy.answer.value)}, ` +
    `estimated error ${six(accuracy.answer.estimated_error)}`);
});

test("no console errors, page errors or CSP violations", () => {
  assert.deepEqual(problems.filter((p) => !/Failed to load resource|ERR_CONNECTION_REFUSED|net::ERR/.test(p)), []);
});
