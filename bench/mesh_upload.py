#!/usr/bin/python3
"""Issue 35's upload benchmark: a gmsh mesh of 1,000,000 nodes uploaded once to the service and
used by 100 jobs, stored once.

Writes the grid of bench/gmsh_reading.py (1000 x 1000 nodes, 998,001 q4, .msh 4.1 binary, 72 MB)
into a temporary folder, starts a throwaway `grip serve` on a free loopback port with a temporary
SQLite database (one worker; --max-mesh and --max-nodes raised for the file), uploads the file
(POST /v1/meshes, timed), then submits `--jobs` jobs whose scene names the mesh by its id and
dismisses each at once (solving 100 one-million-node jobs is not the point: storage is). Prints
the upload's wall time and answer, the submissions' times, the database's size (file + WAL)
before the upload, after it and after the jobs, the rows of the meshes and job_meshes tables,
and the server's peak resident memory (VmHWM). Nothing is kept.
Usage, from the repository root:
    /usr/bin/python3 bench/mesh_upload.py [--grip build/apps/grip] [--n 1000] [--jobs 100]
Needs numpy (Debian python3-numpy)."""
import argparse
import os
import socket
import sqlite3
import statistics
import subprocess
import sys
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "clients", "python"))
from gmsh_reading import grid, write_v41  # noqa: E402
from grip_client.client import Client, GripError  # noqa: E402


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def db_bytes(path):
    return sum(os.path.getsize(path + suffix) for suffix in ("", "-wal") if os.path.exists(path + suffix))


def peak_rss_mb(pid):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmHWM:"):
                return int(line.split()[1]) / 1024
    return float("nan")


def scene(mesh_id, k):
    """A plate on the mesh pressed onto a flat (never solved: each job is dismissed at once)."""
    return {"name": f"upload-{k}",
            "body": {"model": "continuum", "kinematics": "linear", "element": "q4",
                     "material": {"young": 1000, "poisson": 0.3},
                     "mesh": {"gmsh": {"id": mesh_id}}, "contact_set": "bottom",
                     "supports": [{"set": "bottom", "fix": ["x"]}],
                     "loads": [{"set": "bottom", "force": [0, -1e-6 * (k + 1)]}]},
            "obstacles": [{"name": "flat", "shape": {"type": "segment", "from": [2, -0.01], "to": [-1, -0.01]},
                           "friction": 0.0}],
            "steps": 1}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--grip", default="build/apps/grip")
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--jobs", type=int, default=100)
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "grid.msh")
        write_v41(path, 1, *grid(args.n))
        size = os.path.getsize(path)
        db = os.path.join(tmp, "grip.sqlite")
        port = free_port()
        server = subprocess.Popen(
            [args.grip, "serve", "--host", "127.0.0.1", "--port", str(port), "--db", db, "--workers", "1",
             "--max-mesh", str(2 * size), "--max-nodes", str(2 * args.n * args.n), "--retain-jobs", "0",
             "--schemas", os.path.join(HERE, "..", "schemas")],
            stdout=subprocess.DEVNULL, stderr=open(os.path.join(tmp, "server.log"), "w"))
        try:
            client = Client(f"http://127.0.0.1:{port}", timeout=600)
            for _ in range(600):
                try:
                    client.get("/v1/health")
                    break
                except (OSError, GripError):
                    if server.poll() is not None:
                        sys.exit("grip serve stopped: " + open(os.path.join(tmp, "server.log")).read())
                    time.sleep(0.05)
            before = db_bytes(db)
            with open(path, "rb") as f:
                data = f.read()
            t0 = time.monotonic()
            answer = client.upload_mesh(data)
            upload = time.monotonic() - t0
            after_upload = db_bytes(db)
            rss_upload = peak_rss_mb(server.pid)
            t0 = time.monotonic()
            again = client.upload_mesh(data)
            upload_again = time.monotonic() - t0
            submits, statuses = [], {}
            for k in range(args.jobs):
                t0 = time.monotonic()
                try:
                    job = client.submit(scene(answer["id"], k))
                except GripError as e:
                    sys.exit(f"submission {k}: {e} {e.errors}")
                submits.append(time.monotonic() - t0)
                doc = job.dismiss()
                statuses[doc.get("status")] = statuses.get(doc.get("status"), 0) + 1
            time.sleep(1)
            after_jobs = db_bytes(db)
            rss = peak_rss_mb(server.pid)
            con = sqlite3.connect(f"file:{db}?mode=ro", uri=True)
            meshes = con.execute("SELECT COUNT(*), COALESCE(SUM(bytes), 0), COALESCE(SUM(LENGTH(data)), 0) FROM meshes").fetchone()
            links = con.execute("SELECT COUNT(*), COUNT(DISTINCT mesh_id) FROM job_meshes").fetchone()
            jobs = con.execute("SELECT COUNT(*) FROM jobs").fetchone()[0]
            con.close()
        finally:
            server.terminate()
            server.wait(timeout=60)
    mb = 1e6
    print(f"mesh file: {size / mb:.1f} MB, {args.n * args.n} nodes; answer: nodes {answer.get('nodes')}, "
          f"elements {answer.get('elements')}, id {answer['id'][:12]}..; same id again: {again['id'] == answer['id']}")
    print("| measure | value |")
    print("|---|---|")
    print(f"| upload (POST /v1/meshes, {size / mb:.0f} MB), wall s | {upload:.2f} |")
    print(f"| the same upload again, wall s | {upload_again:.2f} |")
    print(f"| server peak RSS after the upload (MB) | {rss_upload:.0f} |")
    print(f"| {args.jobs} submissions naming the mesh, wall s each: median, largest | "
          f"{statistics.median(submits):.3f}, {max(submits):.3f} |")
    print(f"| job statuses after dismissal | {statuses} |")
    print(f"| server peak RSS at the end (MB) | {rss:.0f} |")
    print(f"| database (file + WAL) before the upload (MB) | {before / mb:.2f} |")
    print(f"| database after the upload (MB) | {after_upload / mb:.2f} |")
    print(f"| database after the {args.jobs} jobs (MB) | {after_jobs / mb:.2f} |")
    print(f"| meshes rows; the file's bytes, stored bytes (MB) | {meshes[0]}; {meshes[1] / mb:.1f}, {meshes[2] / mb:.1f} |")
    print(f"| jobs rows; job_meshes links, distinct meshes | {jobs}; {links[0]}, {links[1]} |")


if __name__ == "__main__":
    main()
