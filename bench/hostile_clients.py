#!/usr/bin/env python3
"""Hostile clients against a running `grip serve` (issue 34; bench/results/hostile-clients.md).

Attacks, one after the other, each measured from a well-behaved client on 127.0.0.1 while the
attackers connect from 127.0.1.x (all of 127/8 reaches lo on Linux):
  1. 500 slow-loris connections (a byte of the head every 0.4 s, reopened when closed) and
     500 idle keep-alive connections (one request, then silence; reopened when closed), for
     DURATION seconds: /v1/health latency, and a small job's time from submission to its end
     beyond its solve time.
  2. A POST without Content-Length: seconds until answered, and the status.
  3. 32 event streams opened and dropped on a queued job: ms until a new stream is accepted.
    python3 bench/hostile_clients.py PORT [DURATION [attack|post|streams]]
The server is best started with --workers 1 (attack 3 needs the worker busy); attack 3 submits
a long job and dismisses it afterwards.
"""
import json
import multiprocessing
import socket
import statistics
import sys
import time
import urllib.request

PORT = int(sys.argv[1])
DURATION = float(sys.argv[2]) if len(sys.argv) > 2 else 8.0
BASE = f"http://127.0.0.1:{PORT}"
ROOT = __file__.rsplit("/bench/", 1)[0]


def http(method, path, body=None, timeout=60):
    req = urllib.request.Request(BASE + path, data=body, method=method,
                                 headers={"Content-Type": "application/json"} if body else {})
    try:
        with urllib.request.urlopen(req, timeout=timeout) as r:
            return r.status, r.read()
    except urllib.error.HTTPError as e:
        return e.code, e.read()
    except OSError as e:
        return 0, str(e).encode()


def connect(source):
    s = socket.socket()
    s.setblocking(True)
    try:
        s.bind((source, 0))
        s.connect(("127.0.0.1", PORT))
        s.setblocking(False)
        return s
    except OSError:
        s.close()
        return None


def gone(s):
    try:
        data = s.recv(65536)
        return data == b"" or len(data) > 0
    except BlockingIOError:
        return False
    except OSError:
        return True


def timed_health():
    """GET /v1/health on a new connection: (status, ms to connect, ms from request to answer)."""
    t = time.perf_counter()
    try:
        s = socket.create_connection(("127.0.0.1", PORT), timeout=120)
        connected = time.perf_counter()
        s.sendall(b"GET /v1/health HTTP/1.1\r\nHost: grip\r\nConnection: close\r\n\r\n")
        head = s.recv(64)
        answered = time.perf_counter()
        s.close()
    except OSError:
        return 0, 0.0, (time.perf_counter() - t) * 1000
    status = int(head.split()[1]) if head.startswith(b"HTTP/1.1 ") else 0
    return status, (connected - t) * 1000, (answered - connected) * 1000


def small_scene():
    scene = json.load(open(f"{ROOT}/schemas/examples/beam-on-cylinder.json"))
    scene["body"]["mesh"]["elements"] = 10
    for load in scene["body"]["loads"]:
        load["node"] = 10
    scene["steps"] = 2
    return scene


def attack_slow_and_idle():
    head = b"GET /v1/health HTTP/1.1\r\nHost: grip\r\nX-Padding: "
    slow = [None] * 500
    sent = [0] * 500
    idle = [None] * 500
    # The attackers run in a process of their own: in this one, their loop over 1,000 sockets
    # held the interpreter's lock while the measuring client waited for it (a /v1/health of
    # 61 ms measured from another process read 250-1,500 ms here).
    stop = multiprocessing.Event()
    opened = {"n": 0}
    opened_total = multiprocessing.Value("i", 0)

    def open_slow(i):
        slow[i] = connect(f"127.0.1.{1 + i % 200}")
        sent[i] = 0
        opened["n"] += 1

    def open_idle(i):
        idle[i] = connect(f"127.0.1.{1 + (500 + i) % 200}")
        if idle[i]:
            try:
                idle[i].send(b"GET /v1/health HTTP/1.1\r\nHost: grip\r\n\r\n")
            except OSError:
                pass
        opened["n"] += 1

    def run():
        while not stop.is_set():
            for i in range(500):
                if slow[i] is None or gone(slow[i]):
                    if slow[i]:
                        slow[i].close()
                    open_slow(i)
                    continue
                byte = head[sent[i]:sent[i] + 1] or b"a"
                sent[i] += 1
                try:
                    slow[i].send(byte)
                except OSError:
                    pass
            for i in range(500):
                if idle[i] is None or gone(idle[i]):
                    if idle[i]:
                        idle[i].close()
                    open_idle(i)
            opened_total.value = opened["n"]
            time.sleep(0.4)

    t0 = time.time()
    for i in range(500):
        open_slow(i)
        open_idle(i)
    print(f"1000 attacking connections opened in {time.time() - t0:.2f} s")
    attacker = multiprocessing.Process(target=run)
    attacker.start()
    latencies, failed = [], 0
    worst = (0.0, 0.0, 0.0)  # the slowest: total, connect, answer (ms)
    job = None
    start = time.time()
    submitted = 0.0
    done_at, doc = None, {}
    while time.time() - start < DURATION:
        t = time.time()
        status, connect_ms, answer_ms = timed_health()
        latencies.append(connect_ms + answer_ms)
        worst = max(worst, (connect_ms + answer_ms, connect_ms, answer_ms))
        failed += status != 200
        if job is None and time.time() - start > 1:
            submitted = time.time()
            status, body = http("POST", "/v1/jobs", json.dumps(small_scene()).encode(), timeout=120)
            job = json.loads(body)["jobID"] if status == 201 else ""
        elif job and done_at is None:  # the job polled every 10 ms until it ends
            while time.time() - t < 0.1 and done_at is None:
                status, body = http("GET", f"/v1/jobs/{job}", timeout=120)
                doc = json.loads(body) if status == 200 else {}
                if doc.get("status") in ("successful", "failed"):
                    done_at = time.time()
                time.sleep(0.01)
        time.sleep(0.1)
    while job and done_at is None:
        status, body = http("GET", f"/v1/jobs/{job}", timeout=120)
        doc = json.loads(body) if status == 200 else {}
        if doc.get("status") in ("successful", "failed"):
            done_at = time.time()
            break
        time.sleep(0.05)
    stop.set()
    attacker.join()
    for s in slow + idle:
        if s:
            s.close()
    opened["n"] = opened_total.value
    latencies.sort()
    print(f"/v1/health under attack: {len(latencies)} requests, {failed} failed, median "
          f"{statistics.median(latencies):.1f} ms, p90 {latencies[int(0.9 * len(latencies))]:.1f} ms, "
          f"max {latencies[-1]:.1f} ms (connect {worst[1]:.1f} ms, answer {worst[2]:.1f} ms); "
          f"{opened['n']} attacking connections opened in all")
    if done_at:
        print(f"small job: {doc['status']}, solve {doc.get('solve_seconds', 0):.3f} s, submission to "
              f"seen finished {done_at - submitted:.3f} s (beyond its solve: "
              f"{done_at - submitted - doc.get('solve_seconds', 0):.3f} s)")
    else:
        print("small job: not submitted or not finished")


def post_without_length():
    s = socket.create_connection(("127.0.0.1", PORT))
    t = time.time()
    s.sendall(b"POST /v1/jobs HTTP/1.1\r\nHost: grip\r\nContent-Type: application/json\r\n\r\n")
    s.settimeout(30)
    try:
        answer = s.recv(200)
    except OSError:
        answer = b""
    print(f"POST without a length: answered {answer[:12].decode(errors='replace')!r} after {time.time() - t:.3f} s")
    s.close()


def dropped_streams():
    scene = small_scene()
    busy = json.load(open(f"{ROOT}/tests/load/small-job.json"))
    busy["stages"][-1]["steps"] = 9990  # some 50 s: the worker stays busy, the job queued
    _, b = http("POST", "/v1/jobs", json.dumps(busy).encode())
    busy_id = json.loads(b)["jobID"]
    _, b = http("POST", "/v1/jobs", json.dumps(scene).encode())
    queued = json.loads(b)["jobID"]
    request = f"GET /v1/jobs/{queued}/events HTTP/1.1\r\nHost: grip\r\n\r\n".encode()
    streams = []
    for _ in range(32):
        s = socket.create_connection(("127.0.0.1", PORT))
        s.sendall(request)
        s.settimeout(2)
        s.recv(100)
        streams.append(s)
    t = time.time()
    for s in streams:
        s.close()
    first = None
    again = []
    while len(again) < 32 and time.time() - t < 30:
        s = socket.create_connection(("127.0.0.1", PORT))
        s.sendall(request)
        s.settimeout(2)
        try:
            head = s.recv(100)
        except OSError:
            head = b""
        if head.startswith(b"HTTP/1.1 200"):
            again.append(s)
            first = first or time.time() - t
        else:
            s.close()
            time.sleep(0.02)
    print(f"32 streams dropped on a queued job: a new stream accepted after {first * 1000:.0f} ms, "
          f"{len(again)} of 32 new ones after {(time.time() - t) * 1000:.0f} ms")
    for s in again:
        s.close()
    http("DELETE", f"/v1/jobs/{busy_id}")
    http("DELETE", f"/v1/jobs/{queued}")


which = sys.argv[3] if len(sys.argv) > 3 else "all"
if which in ("all", "attack"):
    attack_slow_and_idle()
    time.sleep(3)
if which in ("all", "post"):
    post_without_length()
if which in ("all", "streams"):
    dropped_streams()
