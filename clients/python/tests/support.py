"""Shared test support: one `grip serve` on a free loopback port for the whole test run, the
package on sys.path, small scenes, and a TCP proxy that cuts a connection mid-stream.

The grip binary comes from $GRIP_BINARY (ctest sets it), else the usual build folders."""

from __future__ import annotations

import atexit
import copy
import json
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import tempfile
import threading
import time

HERE = os.path.dirname(os.path.abspath(__file__))
PACKAGE_DIR = os.path.dirname(HERE)  # clients/python
REPO = os.path.dirname(os.path.dirname(PACKAGE_DIR))
EXAMPLES = os.path.join(REPO, "schemas", "examples")
# GRIP_CLIENT_INSTALLED=1 (tests/installed.sh): the package as pip installed it into a venv,
# and the command line as its `grip-client` script; otherwise this source tree.
INSTALLED = os.environ.get("GRIP_CLIENT_INSTALLED") == "1"
if not INSTALLED and PACKAGE_DIR not in sys.path:
    sys.path.insert(0, PACKAGE_DIR)

import grip_client  # noqa: E402
from grip_client import Client  # noqa: E402

if INSTALLED and os.path.abspath(grip_client.__file__).startswith(PACKAGE_DIR + os.sep):
    raise RuntimeError(f"GRIP_CLIENT_INSTALLED=1 but grip_client comes from the source tree: "
                       f"{grip_client.__file__}")


def grip_binary() -> str:
    env = os.environ.get("GRIP_BINARY")
    if env:
        return env
    for d in ("build", "build-py", "build-srv"):
        p = os.path.join(REPO, d, "apps", "grip")
        if os.access(p, os.X_OK):
            return p
    raise RuntimeError("no grip binary: set GRIP_BINARY or build the `grip` target")


class Server:
    """`grip serve --port 0` in a temporary folder; the port is read from its log."""

    def __init__(self, extra_args=()):
        self.dir = tempfile.mkdtemp(prefix="grip-pytest-")
        self.log_path = os.path.join(self.dir, "server.log")
        self.log = open(self.log_path, "wb")
        args = [grip_binary(), "serve", "--host", "127.0.0.1", "--port", "0",
                "--db", os.path.join(self.dir, "jobs.sqlite"), "--workers", "2",
                "--schemas", os.path.join(REPO, "schemas"), "--grace", "0", *extra_args]
        self.proc = subprocess.Popen(args, stdout=self.log, stderr=subprocess.STDOUT,
                                     cwd=self.dir)
        self.port = self._wait_for_port()
        self.url = f"http://127.0.0.1:{self.port}"

    def _wait_for_port(self) -> int:
        deadline = time.monotonic() + 30
        pattern = re.compile(rb"listening on http://[0-9.]+:(\d+)")
        while time.monotonic() < deadline:
            if self.proc.poll() is not None:
                raise RuntimeError("grip serve exited:\n" + self.read_log())
            with open(self.log_path, "rb") as f:
                m = pattern.search(f.read())
            if m:
                return int(m.group(1))
            time.sleep(0.05)
        raise RuntimeError("grip serve did not start:\n" + self.read_log())

    def read_log(self) -> str:
        with open(self.log_path, "rb") as f:
            return f.read().decode("utf-8", "replace")

    def stop(self):
        if self.proc.poll() is None:
            self.proc.send_signal(signal.SIGTERM)
            try:
                self.proc.wait(timeout=20)
            except subprocess.TimeoutExpired:
                self.proc.kill()
                self.proc.wait()
        self.log.close()
        shutil.rmtree(self.dir, ignore_errors=True)


_server = None
_lock = threading.Lock()


def server() -> Server:
    """The run's server, started on first use and stopped at exit."""
    global _server
    with _lock:
        if _server is None:
            _server = Server()
            atexit.register(_server.stop)
        return _server


def client() -> Client:
    return Client(server().url)


def example(name: str) -> dict:
    with open(os.path.join(EXAMPLES, name + ".json"), encoding="utf-8") as f:
        return json.load(f)


def small_beam(elements: int = 10, steps: int = 4, friction: float = 0.2) -> dict:
    """The paper's beam, coarse: a job of a fraction of a second."""
    s = copy.deepcopy(example("beam-on-cylinder"))
    s["body"]["mesh"]["elements"] = elements
    s["body"]["loads"][0]["node"] = elements
    s["steps"] = steps
    s["obstacles"][0]["friction"] = friction
    return s


def failing_beam() -> dict:
    """A scene whose first step fails: one Newton iteration allowed."""
    s = small_beam()
    s["solver"]["newton"] = {"max_iterations": 1}
    return s


def long_sheet(steps: int = 600) -> dict:
    """The paper's sheet in tiny increments: runs for a long while (it gets dismissed)."""
    s = copy.deepcopy(example("sheet-stretching"))
    s["steps"] = steps
    return s


def cli(*args, env_extra=None, timeout=120):
    """Runs `python3 -m grip_client ARGS` (this interpreter; installed: the venv's `grip-client`
    command) against the run's server."""
    env = dict(os.environ)
    env["GRIP_URL"] = server().url
    env.pop("GRIP_TOKEN", None)
    if INSTALLED:
        command = [os.path.join(os.path.dirname(sys.executable), "grip-client")]
    else:
        env["PYTHONPATH"] = PACKAGE_DIR + os.pathsep + env.get("PYTHONPATH", "")
        command = [sys.executable, "-m", "grip_client"]
    if env_extra:
        env.update(env_extra)
    return subprocess.run([*command, *args], capture_output=True, text=True, env=env,
                          timeout=timeout, cwd=REPO)


class CuttingProxy:
    """A loopback TCP proxy to the server that closes the first event stream after `cut_after`
    bytes of its response, and records each request's head."""

    def __init__(self, target_port: int, cut_after: int):
        self.target = ("127.0.0.1", target_port)
        self.cut_after = cut_after
        self.requests = []  # request heads (bytes), in order
        self.sock = socket.socket()
        self.sock.bind(("127.0.0.1", 0))
        self.sock.listen(8)
        self.port = self.sock.getsockname()[1]
        self.url = f"http://127.0.0.1:{self.port}"
        self.connections = 0
        self.closed = False
        self.cut_done = False
        self.lock = threading.Lock()
        self.thread = threading.Thread(target=self._accept, daemon=True)
        self.thread.start()

    def _accept(self):
        while not self.closed:
            try:
                conn, _ = self.sock.accept()
            except OSError:
                return
            self.connections += 1
            threading.Thread(target=self._serve, args=(conn,), daemon=True).start()

    def _serve(self, conn):
        upstream = socket.create_connection(self.target)
        head = b""
        conn.settimeout(10)
        while b"\r\n\r\n" not in head:
            chunk = conn.recv(65536)
            if not chunk:
                break
            head += chunk
        with self.lock:
            self.requests.append(head)
            # Only the first event stream is cut.
            limit = None
            if b"/events" in head.split(b"\r\n")[0] and not self.cut_done:
                self.cut_done = True
                limit = self.cut_after
        upstream.sendall(head)
        sent = 0
        try:
            while True:
                data = upstream.recv(65536)
                if not data:
                    break
                if limit is not None and sent + len(data) >= limit:
                    conn.sendall(data[: limit - sent])
                    break  # cut: close both sides mid-stream
                conn.sendall(data)
                sent += len(data)
        except OSError:
            pass
        finally:
            for s in (conn, upstream):
                try:
                    s.shutdown(socket.SHUT_RDWR)
                except OSError:
                    pass
                s.close()

    def close(self):
        self.closed = True
        self.sock.close()
