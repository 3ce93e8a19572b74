#!/usr/bin/env python3
"""Many small jobs from a few clients on one replica: does any wait for a lease to expire?
(issue 34: with 8 clients, 14 of about 16,500 jobs were taken for lost by their own replica's
lease renewal and ran again only when their 10 s lease expired; bench/results/hostile-clients.md)

Each client submits tests/load/small-job.json, follows the job's event stream to its terminal
event, reads the job document, and submits the next. Per job: the time from `created` to
`finished` beyond `solve_seconds`, and `attempts`.
    python3 bench/lease_race.py PORT [JOBS [CLIENTS]]     (defaults 20000, 8)
against a running `grip serve` started with a large --per-client (all clients are 127.0.0.1).
"""
import http.client
import json
import sys
import threading
import time
import uuid
from datetime import datetime

PORT = int(sys.argv[1])
JOBS = int(sys.argv[2]) if len(sys.argv) > 2 else 20000
CLIENTS = int(sys.argv[3]) if len(sys.argv) > 3 else 8
ROOT = __file__.rsplit("/bench/", 1)[0]
with open(f"{ROOT}/tests/load/small-job.json", "rb") as f:
    SCENE = json.dumps(json.load(f)).encode()

lock = threading.Lock()
taken = 0
rows = []  # (beyond solve s, attempts, solve s)
problems = []
reconnects = 0  # keep-alive connections found closed by the server


def when(text):
    return datetime.strptime(text, "%Y-%m-%dT%H:%M:%S.%fZ").timestamp()


class Api:
    """A keep-alive connection, opened again when the server has closed it (the request is
    sent again: GETs, and POSTs with an Idempotency-Key)."""

    def __init__(self):
        self.c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=120)

    def call(self, method, path, body=None, headers=None):
        for attempt in range(3):
            try:
                self.c.request(method, path, body, headers or {})
                r = self.c.getresponse()
                return r, r.read()
            except (http.client.HTTPException, ConnectionError):
                global reconnects
                reconnects += 1
                self.c.close()
                self.c = http.client.HTTPConnection("127.0.0.1", PORT, timeout=120)
        raise RuntimeError(f"{method} {path}: no answer in 3 connections")


def client():
    global taken
    api = Api()
    while True:
        with lock:
            if taken >= JOBS:
                return
            taken += 1
        headers = {"Content-Type": "application/json", "Idempotency-Key": str(uuid.uuid4())}
        r, body = api.call("POST", "/v1/jobs", SCENE, headers)
        if r.status == 503:
            with lock:
                taken -= 1
            time.sleep(float(r.getheader("Retry-After", "1")))
            continue
        if r.status != 201:
            problems.append(f"submit: {r.status} {body[:200]!r}")
            continue
        job = json.loads(body)["jobID"]
        for attempt in range(3):  # the stream to the terminal event (replayed from the start)
            stream = http.client.HTTPConnection("127.0.0.1", PORT, timeout=120)
            try:
                stream.request("GET", f"/v1/jobs/{job}/events")
                if any(line.startswith(b"event: job_") for line in stream.getresponse()):
                    break  # job_finished or job_failed
            except (http.client.HTTPException, ConnectionError):
                pass
            finally:
                stream.close()
        _, body = api.call("GET", f"/v1/jobs/{job}")
        doc = json.loads(body)
        if doc.get("status") != "successful":
            problems.append(f"{job}: {doc.get('status')} {doc.get('message')}")
            continue
        beyond = when(doc["finished"]) - when(doc["created"]) - doc["solve_seconds"]
        with lock:
            rows.append((beyond, doc["attempts"], doc["solve_seconds"]))


t0 = time.time()
threads = [threading.Thread(target=client) for _ in range(CLIENTS)]
for t in threads:
    t.start()
for t in threads:
    t.join()
span = time.time() - t0
beyond = sorted(r[0] for r in rows)
solve = sorted(r[2] for r in rows)
pick = lambda v, q: v[min(len(v) - 1, int(q * len(v)))]
print(f"{len(rows)} jobs successful of {JOBS}, {CLIENTS} clients, {span:.0f} s ({len(rows) / span:.1f} jobs/s)")
print(f"solve p50 {pick(solve, 0.5) * 1000:.1f} ms, max {solve[-1] * 1000:.1f} ms")
print(f"created to finished beyond the solve: p50 {pick(beyond, 0.5) * 1000:.1f} ms, "
      f"p99 {pick(beyond, 0.99) * 1000:.1f} ms, p99.9 {pick(beyond, 0.999) * 1000:.1f} ms, max {beyond[-1] * 1000:.1f} ms")
print(f"jobs over 1 s beyond their solve: {sum(b > 1 for b in beyond)}; run more than once: "
      f"{sum(r[1] != 1 for r in rows)}")
print(f"keep-alive connections found closed and opened again: {reconnects}")
for p in problems[:20]:
    print("problem:", p)
