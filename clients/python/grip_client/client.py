"""HTTP client for the grip service (standard library only).

    from grip_client import Client
    c = Client("http://127.0.0.1:8080")
    job = c.submit(scene_dict)            # or a path to a scene file
    for ev in job.events():               # SSE, reconnects with Last-Event-ID
        ...
    doc = job.wait()                      # the final job document (OGC status info)
    result = job.result()                 # the result JSON as a dict
    job.dismiss()
    job = c.submit(scene, meshes={"part.msh": "part.msh"})   # gmsh meshes uploaded first

Every HTTP error raises GripError, which carries the RFC 9457 problem document and its
`errors[]` of {pointer, detail}.
"""

from __future__ import annotations

import http.client
import json
import os
import socket
import time
import urllib.error
import urllib.parse
import urllib.request
from typing import Any, Dict, Iterator, List, Optional, Union

__all__ = ["Client", "Job", "Event", "GripError", "TERMINAL_EVENTS", "FINISHED_STATUSES",
           "gmsh_references"]

TERMINAL_EVENTS = ("job_finished", "job_failed")
FINISHED_STATUSES = ("successful", "failed", "dismissed")

_USER_AGENT = "grip-client-python/0.1"


class GripError(Exception):
    """An HTTP error answered by the service (or no answer at all: status 0).

    status   HTTP status code (0: the server could not be reached)
    problem  the problem+json document (dict), or {} when the body was not one
    errors   the problem's errors[]: [{"pointer": "/body/mesh/elements", "detail": "..."}]
    retry_after  seconds from a Retry-After header, or None
    """

    def __init__(self, status: int, problem: Optional[dict] = None, message: str = "",
                 retry_after: Optional[float] = None, url: str = ""):
        self.status = status
        self.problem = problem or {}
        self.errors: List[dict] = list(self.problem.get("errors") or [])
        self.retry_after = retry_after
        self.url = url
        title = self.problem.get("title") or message or "HTTP error"
        detail = self.problem.get("detail")
        text = f"{status} {title}" if status else title
        if detail and detail != title:
            text += f": {detail}"
        super().__init__(text)

    @property
    def pointers(self) -> List[str]:
        """The JSON pointers named by the problem's errors[]."""
        return [e.get("pointer", "") for e in self.errors]

    def describe(self) -> str:
        """The message and one line per error with its pointer, for printing."""
        lines = [str(self)]
        for e in self.errors:
            ptr = e.get("pointer", "")
            lines.append(f"  {ptr or '(document)'}: {e.get('detail', '')}")
        return "\n".join(lines)


class Event:
    """One event of a job: `id` (the per-job sequence, SSE id), `type`, `data` (dict).

    Types (schemas/event.schema.json): step_started {step, load_factor}; iteration {step,
    pass, m, trials (real solves: their sum is the job's contact iterations), n, alpha, v2 and
    v_inf (||v||_2 and ||v||_inf of the contact error vector, in the scene's length unit), open,
    stick, slip (contact point counts), newton_iterations, elapsed_ms (milliseconds since the
    step began)}; step_finished {step, load_factor, converged, contact_iterations,
    newton_iterations, seconds, reason and failure when not converged, ...}; job_finished;
    job_failed {reason, failure: {kind, message, step}}."""

    __slots__ = ("id", "type", "data")

    def __init__(self, id: Optional[int], type: str, data: dict):
        self.id = id
        self.type = type
        self.data = data

    def __getitem__(self, key: str) -> Any:
        return self.data[key]

    def get(self, key: str, default: Any = None) -> Any:
        return self.data.get(key, default)

    def __repr__(self) -> str:
        return f"Event(id={self.id!r}, type={self.type!r}, data={self.data!r})"


def _retry_after(headers) -> Optional[float]:
    value = headers.get("Retry-After") if headers is not None else None
    if not value:
        return None
    try:
        return float(value)
    except ValueError:
        return None


def _error_from_http(e: urllib.error.HTTPError, url: str) -> GripError:
    try:
        body = e.read()
    except Exception:  # noqa: BLE001 - the body is only a courtesy
        body = b""
    problem: dict = {}
    try:
        parsed = json.loads(body.decode("utf-8")) if body else {}
        if isinstance(parsed, dict):
            problem = parsed
    except (ValueError, UnicodeDecodeError):
        pass
    return GripError(e.code, problem, message=e.reason if isinstance(e.reason, str) else "",
                     retry_after=_retry_after(e.headers), url=url)


class Client:
    """A grip service at `url` (e.g. http://127.0.0.1:8080), with an optional bearer token."""

    def __init__(self, url: Optional[str] = None, token: Optional[str] = None,
                 timeout: float = 30.0, submit_retries: int = 3):
        url = url or os.environ.get("GRIP_URL") or "http://127.0.0.1:8080"
        if "://" not in url:
            url = "http://" + url
        self.url = url.rstrip("/")
        self.token = token if token is not None else (os.environ.get("GRIP_TOKEN") or None)
        self.timeout = timeout
        self.submit_retries = submit_retries

    # ---- plumbing

    def absolute(self, href: str) -> str:
        """A link's href (relative or absolute) as a full URL."""
        return urllib.parse.urljoin(self.url + "/", href)

    def _headers(self, extra: Optional[dict] = None) -> dict:
        h = {"User-Agent": _USER_AGENT}
        if self.token:
            h["Authorization"] = "Bearer " + self.token
        if extra:
            h.update(extra)
        return h

    def open(self, method: str, path: str, body: Optional[bytes] = None,
             headers: Optional[Dict[str, str]] = None,
             timeout: Optional[float] = None) -> http.client.HTTPResponse:
        """Sends a request and returns the open response; raises GripError on >= 400.
        `timeout` in seconds (default: the client's)."""
        url = self.absolute(path)
        req = urllib.request.Request(url, data=body, method=method, headers=self._headers(headers))
        try:
            return urllib.request.urlopen(req, timeout=timeout or self.timeout)
        except urllib.error.HTTPError as e:
            raise _error_from_http(e, url) from None
        except (urllib.error.URLError, ConnectionError, socket.timeout, http.client.HTTPException) as e:
            reason = getattr(e, "reason", e)
            raise GripError(0, message=f"cannot reach {url}: {reason}", url=url) from None

    def request(self, method: str, path: str, body: Optional[bytes] = None,
                headers: Optional[Dict[str, str]] = None, raw: bool = False) -> Any:
        """Sends a request; returns parsed JSON, or bytes when `raw` or not JSON."""
        with self.open(method, path, body, headers) as resp:
            data = resp.read()
            ctype = resp.headers.get("Content-Type", "")
        if raw:
            return data
        if "json" in ctype:
            return json.loads(data.decode("utf-8")) if data else None
        return data

    def get(self, path: str, **kw: Any) -> Any:
        """GET `path`: parsed JSON, or bytes (see request)."""
        return self.request("GET", path, **kw)

    # ---- service

    def health(self) -> dict:
        """{"status": "ok"} while the server runs."""
        return self.get("/v1/health")

    def examples(self) -> List[str]:
        """Names of the built-in example scenes (the paper's two first)."""
        return [item["name"] for item in self.get("/v1/examples").get("items", [])]

    def example(self, name: str) -> dict:
        """A built-in example scene (units in its `units`, e.g. kgf and cm)."""
        return self.get("/v1/examples/" + urllib.parse.quote(name))

    def schema(self, name: str) -> dict:
        """A JSON Schema by name: scene, result, event or job."""
        return self.get("/v1/schemas/" + urllib.parse.quote(name))

    # ---- meshes

    def upload_mesh(self, mesh: Union[bytes, str, os.PathLike]) -> dict:
        """Uploads a gmsh .msh file (its bytes, or a path) with POST /v1/meshes and returns what
        the server read: {"id", "nodes", "elements": {kind: count}, "physical_groups", ...}.
        The id is the SHA-256 of the bytes: the same file uploaded again is stored once."""
        if not isinstance(mesh, (bytes, bytearray)):
            with open(mesh, "rb") as f:
                mesh = f.read()
        return self.request("POST", "/v1/meshes", bytes(mesh),
                            {"Content-Type": "application/octet-stream"})

    def example_mesh(self, name: str) -> bytes:
        """The mesh file a built-in example names (e.g. hertz-t6.msh), as bytes."""
        return self.get("/v1/examples/" + urllib.parse.quote(name), raw=True)

    def with_meshes(self, scene: dict,
                    meshes: Dict[str, Union[bytes, str, os.PathLike]]) -> dict:
        """A copy of `scene` in which every gmsh mesh reference {"file": NAME} (body.mesh.gmsh,
        bodies[].mesh.gmsh, obstacles[].shape.gmsh) is {"id": ...} of the upload of
        meshes[NAME] (bytes or a path; NAME as the scene writes it, or its base name). Each
        file is uploaded once. A reference without a mesh raises ValueError naming its
        pointer."""
        out = json.loads(json.dumps(scene))
        ids: Dict[str, str] = {}
        missing = []
        for pointer, ref in gmsh_references(out):
            name = ref["file"]
            key = name if name in meshes else os.path.basename(name)
            if key not in meshes:
                missing.append(f"{pointer}/file: no mesh given for '{name}'")
                continue
            if key not in ids:
                ids[key] = self.upload_mesh(meshes[key])["id"]
            del ref["file"]
            ref["id"] = ids[key]
        if missing:
            raise ValueError("; ".join(missing))
        return out

    # ---- studies

    def study(self, scene: dict, levels: Optional[int] = None,
              meshes: Optional[List[dict]] = None, outputs: Optional[List[str]] = None,
              tolerances: Optional[List[float]] = None, methods: Optional[List[str]] = None,
              accuracy: Optional[dict] = None) -> dict:
        """Starts a study (POST /v1/studies): the scene at `levels` mesh levels (generated
        meshes: divisions x 2^j), or on each of `meshes` ({"id": ...} of uploads, coarse to
        fine), each level with every one of `methods` at every one of `tolerances` (contact
        methods and tolerances) where given; or, with `accuracy` ({"output", "relative",
        "levels"?, "budget_seconds"?}), refined until that output's estimated error is below
        `relative`. The scene names its quantities in `outputs`; `outputs` here picks some.
        Returns the study's document (its id, levels and table so far)."""
        body: Dict[str, Any] = {"scene": scene}
        if accuracy:
            body["accuracy"] = dict(accuracy)
        else:
            body["refine"] = {"meshes": meshes} if meshes else {"levels": levels}
        if tolerances:
            body["tolerances"] = list(tolerances)
        if methods:
            body["methods"] = list(methods)
        if outputs:
            body["outputs"] = list(outputs)
        return self.request("POST", "/v1/studies", json.dumps(body).encode("utf-8"),
                            {"Content-Type": "application/json"})

    def study_table(self, study_id: str) -> dict:
        """The study's table as far as its jobs have finished (GET /v1/studies/ID)."""
        return self.get("/v1/studies/" + urllib.parse.quote(study_id))

    def wait_study(self, study_id: str, poll: float = 0.5, timeout: Optional[float] = None) -> dict:
        """Polls the study until no level is queued or running; its final table."""
        deadline = None if timeout is None else time.monotonic() + timeout
        while True:
            doc = self.study_table(study_id)
            if doc.get("status") not in ("accepted", "running"):
                return doc
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"study {study_id} still {doc.get('status')}")
            time.sleep(poll)

    # ---- jobs

    def submit(self, scene: Union[dict, str, os.PathLike, bytes],
               idempotency_key: Optional[str] = None,
               meshes: Optional[Dict[str, Union[bytes, str, os.PathLike]]] = None) -> "Job":
        """Submits a scene (a dict, a path to a JSON file, or raw bytes) and returns its Job.
        `meshes`: the .msh files its gmsh references name, by name (see with_meshes), uploaded
        first.

        A 503 (queue full: nothing was accepted) is retried up to `submit_retries` times after
        its Retry-After."""
        if meshes:
            if not isinstance(scene, dict):
                if isinstance(scene, (bytes, bytearray)):
                    scene = json.loads(bytes(scene).decode("utf-8"))
                else:
                    with open(scene, "rb") as f:
                        scene = json.load(f)
            scene = self.with_meshes(scene, meshes)
        if isinstance(scene, (bytes, bytearray)):
            body = bytes(scene)
        elif isinstance(scene, dict):
            body = json.dumps(scene).encode("utf-8")
        else:
            with open(scene, "rb") as f:
                body = f.read()
        headers = {"Content-Type": "application/json"}
        if idempotency_key is not None:
            headers["Idempotency-Key"] = idempotency_key
        attempt = 0
        while True:
            try:
                with self.open("POST", "/v1/jobs", body, headers) as resp:
                    doc = json.loads(resp.read().decode("utf-8"))
                    replayed = resp.headers.get("Idempotent-Replayed") == "true"
                    location = resp.headers.get("Location")
                break
            except GripError as e:
                if e.status != 503 or attempt >= self.submit_retries:
                    raise
                attempt += 1
                time.sleep(min(e.retry_after or 1.0, 10.0))
        job = Job(self, doc["jobID"], doc)
        job.replayed = replayed
        job.location = location
        return job

    def job(self, job_id: str) -> "Job":
        """The job with this id (its document fetched now)."""
        job = Job(self, job_id)
        job.status()
        return job

    def jobs(self, status: Optional[str] = None, limit: Optional[int] = None,
             page_size: int = 50) -> Iterator["Job"]:
        """Jobs, newest first, following the `next` links page by page."""
        query = {"limit": str(page_size)}
        if status:
            query["status"] = status
        href: Optional[str] = "/v1/jobs?" + urllib.parse.urlencode(query)
        count = 0
        while href:
            page = self.get(href)
            for doc in page.get("jobs", []):
                if limit is not None and count >= limit:
                    return
                count += 1
                yield Job(self, doc["jobID"], doc)
            href = next((l["href"] for l in page.get("links", []) if l.get("rel") == "next"), None)


class Job:
    """A submitted job. `doc` is the last job document seen (OGC status info)."""

    def __init__(self, client: Client, job_id: str, doc: Optional[dict] = None):
        self.client = client
        self.id = job_id
        self.doc: dict = doc or {}
        self.replayed = False
        self.location: Optional[str] = None
        self.last_event_id: Optional[int] = None
        self.reconnects = 0

    def __repr__(self) -> str:
        return f"Job({self.id!r}, status={self.doc.get('status')!r})"

    @property
    def path(self) -> str:
        return "/v1/jobs/" + urllib.parse.quote(self.id)

    def status(self) -> dict:
        """Fetches and returns the job document: status, progress, message, timings, links."""
        self.doc = self.client.get(self.path)
        return self.doc

    @property
    def finished(self) -> bool:
        return self.doc.get("status") in FINISHED_STATUSES

    @property
    def failure(self) -> Optional[dict]:
        """Why the job failed or was dismissed, from the last job document seen: {kind, message,
        step} (schemas/result.schema.json#/definitions/failure); None otherwise. Branch on
        failure["kind"], never on the message's text."""
        return self.doc.get("failure")

    def events(self, last_event_id: Optional[int] = None, reconnect: bool = True,
               max_reconnects: int = 20, read_timeout: float = 60.0) -> Iterator[Event]:
        """The job's events from the SSE stream: past ones replayed, then live ones, until the
        terminal event (job_finished or job_failed).

        A dropped connection is reopened with Last-Event-ID = the last id received, so no
        event is missed or repeated. `last_event_id` starts after that id."""
        last = last_event_id
        retry_ms = 1000
        failures = 0
        while True:
            headers = {"Accept": "text/event-stream"}
            if last is not None:
                headers["Last-Event-ID"] = str(last)
            try:
                resp = self.client.open("GET", self.path + "/events", headers=headers,
                                        timeout=read_timeout)
            except GripError as e:
                # No answer, or too many streams / restarting server: wait and reopen.
                if reconnect and (e.status == 0 or e.status == 503) and failures < max_reconnects:
                    failures += 1
                    self.reconnects += 1
                    time.sleep(min(e.retry_after or retry_ms / 1000.0, 5.0))
                    continue
                raise
            ended = False
            try:
                with resp:
                    for ev, retry in _parse_sse(resp):
                        if retry is not None:
                            retry_ms = retry
                            continue
                        if ev.id is not None:
                            last = ev.id
                            self.last_event_id = ev.id
                        failures = 0
                        yield ev
                        if ev.type in TERMINAL_EVENTS:
                            ended = True
                            return
            except (ConnectionError, socket.timeout, http.client.HTTPException, OSError):
                pass  # dropped mid-stream: reconnect below
            if ended:
                return
            # The stream closed without a terminal event: a dropped connection, or a server
            # that stopped, or a job removed meanwhile.
            if not reconnect or failures >= max_reconnects:
                raise GripError(0, message=f"event stream of job {self.id} ended before its "
                                           f"terminal event (last id {last})")
            failures += 1
            self.reconnects += 1
            try:
                self.status()
            except GripError as e:
                if e.status == 404:
                    raise
            time.sleep(min(retry_ms / 1000.0, 5.0) if failures > 1 else 0.05)

    def wait(self, poll: float = 0.5, timeout: Optional[float] = None,
             use_events: bool = True) -> dict:
        """Waits until the job has finished and returns its final document.

        Follows the event stream; falls back to polling the document if streaming fails."""
        deadline = None if timeout is None else time.monotonic() + timeout
        if use_events and timeout is None:
            try:
                for _ in self.events():
                    pass
            except GripError as e:
                if e.status == 404:
                    raise
        while True:
            doc = self.status()
            if doc.get("status") in FINISHED_STATUSES:
                return doc
            if deadline is not None and time.monotonic() > deadline:
                raise TimeoutError(f"job {self.id} is still {doc.get('status')} after {timeout} s")
            time.sleep(poll)

    def result(self, format: str = "json", table: Optional[str] = None,
               step: Optional[int] = None) -> Union[dict, str, bytes]:
        """The result: a dict (json), CSV text (csv; `table` = steps | nodes | elements |
        contact_points | history) or VTK bytes (vtk: a tar of per-step files + .pvd, or one
        step's legacy file with `step`, from 1).

        The dict (schemas/result.schema.json) has `scene` (effective, defaults filled),
        `effects`, `mesh.cells`, `summary` and `steps[]`; per step `nodes[]` (deformed x, y and
        displacements in the scene's length unit, beam rotation theta in radians),
        `elements[]`, and `contact_points[]` with p_n, p_t (force; p_n <= 0 presses),
        sigma_n, sigma_t (force per length squared), gap and slip (length), state (open |
        stick | slip)."""
        query: Dict[str, str] = {}
        if format != "json":
            query["format"] = format
        if table:
            query["table"] = table
        if step is not None:
            query["step"] = str(step)
        path = self.path + "/result" + ("?" + urllib.parse.urlencode(query) if query else "")
        data = self.client.get(path, raw=True)
        if format == "json":
            return json.loads(data.decode("utf-8"))
        if format == "csv" or step is not None:
            return data.decode("utf-8")
        return data

    def convergence(self, format: str = "json") -> Union[dict, str]:
        """The whole contact error history: {"jobID", "status", "iterations": [row, ...]}, one
        row per contact iteration (the iteration event without its type: v2 and v_inf in the
        scene's length unit, elapsed_ms in milliseconds), or the same as CSV text."""
        data = self.client.get(self.path + "/convergence?format=" + format, raw=True)
        return json.loads(data.decode("utf-8")) if format == "json" else data.decode("utf-8")

    def dismiss(self) -> dict:
        """Cancels a queued or running job, removes a finished one; returns its document.

        A cancel that reached the server while the job was finishing can leave it finished
        (the server answers "dismissed" but keeps the job): then the removal is asked again."""
        self.doc = self.client.request("DELETE", self.path)
        for _ in range(5):
            if self.doc.get("status") != "dismissed" or self.doc.get("links") == []:
                break  # removed (no links left), or not a cancel
            try:
                now = self.client.get(self.path)
            except GripError as e:
                if e.status == 404:
                    break
                raise
            if now.get("status") not in ("successful", "failed"):
                break  # really cancelled (or still stopping)
            time.sleep(0.05)
            self.doc = self.client.request("DELETE", self.path)
        return self.doc


def gmsh_references(scene: Any, pointer: str = "") -> Iterator[tuple]:
    """(JSON pointer, object) of every gmsh mesh reference of a scene that names a file: the
    objects under a "gmsh" key with a string "file" (body.mesh.gmsh, bodies[].mesh.gmsh,
    obstacles[].shape.gmsh)."""
    if isinstance(scene, dict):
        for key, value in scene.items():
            here = pointer + "/" + key.replace("~", "~0").replace("/", "~1")
            if key == "gmsh" and isinstance(value, dict) and isinstance(value.get("file"), str):
                yield here, value
            else:
                yield from gmsh_references(value, here)
    elif isinstance(scene, list):
        for k, value in enumerate(scene):
            yield from gmsh_references(value, f"{pointer}/{k}")


def _parse_sse(resp) -> Iterator[tuple]:
    """Yields (Event, None) per event and (None, retry_ms) per retry field of an SSE stream."""
    event_type = ""
    data_lines: List[str] = []
    event_id: Optional[str] = None
    while True:
        raw = resp.readline()
        if not raw:
            return  # closed (an event not ended by a blank line is dropped, as per the spec)
        line = raw.decode("utf-8").rstrip("\r\n")
        if line == "":
            if data_lines:
                text = "\n".join(data_lines)
                try:
                    data: Any = json.loads(text)
                except ValueError:
                    data = {"text": text}
                if not isinstance(data, dict):
                    data = {"value": data}
                etype = event_type or data.get("type") or "message"
                eid = int(event_id) if event_id is not None and event_id.isdigit() else None
                yield Event(eid, etype, data), None
            event_type, data_lines, event_id = "", [], None
            continue
        if line.startswith(":"):
            continue  # comment: heartbeat
        field, _, value = line.partition(":")
        if value.startswith(" "):
            value = value[1:]
        if field == "data":
            data_lines.append(value)
        elif field == "event":
            event_type = value
        elif field == "id":
            event_id = value
        elif field == "retry" and value.isdigit():
            yield None, int(value)
