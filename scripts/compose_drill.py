#!/usr/bin/env python3
"""The compose drill's client (scripts/compose-drill.sh): CLIENTS threads submit JOBS small jobs
each through HAProxy (an Idempotency-Key each, so a retried submission never makes a second
job), one every PACE seconds so that the submissions span the faults, follow them to the end by
polling, and retry what is refused with Retry-After. Meanwhile the shell script kills a replica
and stops PostgreSQL for a while.

Every answer is counted by status; exit status 1 when a 5xx came without Retry-After, when a
job did not finish successfully, or when the store holds another number of jobs than were
submitted (each job exactly once).
    python3 scripts/compose_drill.py http://127.0.0.1:8080 tests/load/small-job.json [CLIENTS JOBS PACE]
"""
import collections
import json
import sys
import threading
import time
import urllib.error
import urllib.request
import uuid

api, scene_path = sys.argv[1], sys.argv[2]
clients = int(sys.argv[3]) if len(sys.argv) > 3 else 2
jobs_each = int(sys.argv[4]) if len(sys.argv) > 4 else 50
pace = float(sys.argv[5]) if len(sys.argv) > 5 else 0.3
scene = open(scene_path, "rb").read()
lock = threading.Lock()
statuses = collections.Counter()
problems = collections.Counter()  # 5xx answers by their problem type (grip's or HAProxy's own)
start = time.time()
spans = collections.defaultdict(lambda: [None, None])  # status -> first and last second it came
bare_5xx = []  # (method, path, status) of 5xx answers without Retry-After
failures = []


def call(method, path, body=None, headers=None):
    """One request; (status, headers, body) or (0, {}, b"") when the connection failed."""
    req = urllib.request.Request(api + path, data=body, method=method, headers=headers or {})
    try:
        with urllib.request.urlopen(req, timeout=30) as r:
            status, hdrs, data = r.status, r.headers, r.read()
    except urllib.error.HTTPError as e:
        status, hdrs, data = e.code, e.headers, e.read()
    except (urllib.error.URLError, ConnectionError, TimeoutError):
        status, hdrs, data = 0, {}, b""
    with lock:
        statuses[status] += 1
        span = spans[status]
        span[0] = span[0] if span[0] is not None else time.time() - start
        span[1] = time.time() - start
        if status >= 500:
            try:
                problems[json.loads(data).get("type", "?")] += 1
            except ValueError:
                problems["(not JSON)"] += 1
        if status >= 500 and not hdrs.get("Retry-After"):
            bare_5xx.append((method, path, status))
    return status, hdrs, data


def patiently(method, path, body=None, headers=None, ok=(200, 201)):
    for _ in range(600):
        status, hdrs, data = call(method, path, body, headers)
        if status in ok:
            return json.loads(data)
        wait = float(hdrs.get("Retry-After", 1)) if status else 1.0
        time.sleep(min(wait, 5.0))
    raise RuntimeError(f"{method} {path}: no answer in time")


def client(n, ids):
    for i in range(jobs_each):
        key = f"drill-{n}-{i}-{uuid.uuid4()}"
        doc = patiently("POST", "/v1/jobs", scene,
                        {"Content-Type": "application/json", "Idempotency-Key": key})
        ids.append(doc["jobID"])
        time.sleep(pace)
    for job in ids:
        while True:
            doc = patiently("GET", f"/v1/jobs/{job}")
            if doc["status"] in ("successful", "failed", "dismissed"):
                break
            time.sleep(0.2)
        if doc["status"] != "successful":
            with lock:
                failures.append((job, doc["status"], doc.get("message")))


all_ids = [[] for _ in range(clients)]
threads = [threading.Thread(target=client, args=(n, all_ids[n])) for n in range(clients)]
for t in threads:
    t.start()
for t in threads:
    t.join()
submitted = {j for ids in all_ids for j in ids}
stored = set()
cursor = ""
while True:
    page = patiently("GET", "/v1/jobs?limit=1000" + cursor)
    stored.update(j["jobID"] for j in page["jobs"])
    nxt = [l["href"] for l in page["links"] if l["rel"] == "next"]
    if not nxt:
        break
    cursor = "&cursor=" + nxt[0].split("cursor=")[1]
print(f"answers by status: {dict(sorted(statuses.items()))} (0: connection failed)")
print("first and last second of each status: " +
      ", ".join(f"{k}: {v[0]:.1f}-{v[1]:.1f}" for k, v in sorted(spans.items())))
print(f"5xx by problem type: {dict(problems)}")
print(f"5xx without Retry-After: {len(bare_5xx)} {bare_5xx[:5]}")
print(f"jobs: {len(submitted)} submitted, {len(stored & submitted)} stored, "
      f"{len(stored - submitted)} stored that no client made, {len(failures)} not successful {failures[:3]}")
sys.exit(1 if bare_5xx or failures or stored != submitted else 0)
