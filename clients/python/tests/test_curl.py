"""The curl examples run against a live server, so they cannot rot: clients/curl/examples.sh,
and the fenced shell blocks of README.md that call curl (the service's section), with their
local URLs pointed at the test's server."""

import os
import re
import subprocess
import tempfile
import unittest

import support

URL_PATTERN = re.compile(r"https?://(?:localhost|127\.0\.0\.1|0\.0\.0\.0)(?::\d+)?")
# Lines that would start or build a server of their own: the test's server stands in.
SKIP_LINE = re.compile(r"(^|\s)(grip|\S*/grip)\s+serve\b|^\s*docker\s|^\s*(bash\s+)?scripts/")


def readme_curl_blocks(text):
    """Shell code blocks of README.md (fenced, or indented under a blank line) that call curl,
    outside the "Python client" section, in order."""
    blocks = []
    section = ""
    lines = text.splitlines()
    i = 0
    while i < len(lines):
        line = lines[i]
        heading = re.match(r"^(#{1,6})\s+(.*)", line)
        if heading:
            section = heading.group(2).strip().lower()
            i += 1
            continue
        fence = re.match(r"^(\s*)(```+|~~~+)\s*([\w+-]*)", line)
        if fence:
            lang = fence.group(3).lower()
            body = []
            i += 1
            while i < len(lines) and not lines[i].strip().startswith(fence.group(2)):
                body.append(lines[i][len(fence.group(1)):])
                i += 1
            i += 1
            if lang in ("", "sh", "bash", "shell", "console", "shell-session"):
                blocks.append((section, "\n".join(body)))
            continue
        if line.startswith("    ") and (i == 0 or not lines[i - 1].strip()):
            body = []
            while i < len(lines) and (lines[i].startswith("    ") or not lines[i].strip()):
                body.append(lines[i][4:])
                i += 1
            blocks.append((section, "\n".join(body).rstrip()))
            continue
        i += 1
    return [b for s, b in blocks
            if re.search(r"(^|[\s(|$])curl\s", b, re.M) and "python client" not in s]


def to_script(block, url):
    out = []
    for line in block.splitlines():
        line = re.sub(r"^\s*\$\s+", "", line)  # console prompts
        if SKIP_LINE.search(line):
            continue
        out.append(URL_PATTERN.sub(url, line))
    return "\n".join(out)


def run_bash(script, cwd, url, timeout=120):
    env = dict(os.environ, GRIP_URL=url)
    return subprocess.run(["bash", "-c", "set -euo pipefail\n" + script], cwd=cwd, env=env,
                          capture_output=True, text=True, timeout=timeout)


class CurlExamples(unittest.TestCase):
    def test_clients_curl_examples(self):
        url = support.server().url
        with tempfile.TemporaryDirectory() as out:
            p = subprocess.run(["bash", os.path.join(support.REPO, "clients", "curl", "examples.sh"),
                                out], env=dict(os.environ, GRIP_URL=url), capture_output=True,
                               text=True, timeout=120)
            self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
            self.assertRegex(p.stdout, r"submitted /v1/jobs/[0-9a-f-]{36}")
            self.assertRegex(p.stdout, r"(?m)^id: 11$")
            self.assertIn('"pointer":"/steps"', p.stdout)
            with open(os.path.join(out, "events.txt"), encoding="utf-8") as f:
                events = f.read()
            self.assertEqual(int(re.search(r"iterations: (\d+)", p.stdout).group(1)),
                             events.count("event: iteration"))
            self.assertTrue(events.rstrip().endswith('data: {"type":"job_finished"}'))

    def test_readme_curl_examples(self):
        with open(os.path.join(support.REPO, "README.md"), encoding="utf-8") as f:
            blocks = readme_curl_blocks(f.read())
        if not blocks:
            self.skipTest("README.md has no shell block calling curl yet (the service's section)")
        url = support.server().url
        script = "\n".join(to_script(b, url) for b in blocks)
        with tempfile.TemporaryDirectory() as work:
            # The repository's top-level entries, linked, so relative paths work and the
            # examples' output files stay out of the work tree.
            for name in os.listdir(support.REPO):
                if not name.startswith("."):
                    os.symlink(os.path.join(support.REPO, name), os.path.join(work, name))
            p = run_bash(script, work, url)
        self.assertEqual(p.returncode, 0,
                         f"README curl examples failed:\n{script}\n--- stdout\n{p.stdout}"
                         f"\n--- stderr\n{p.stderr}")


class ReadmeParsing(unittest.TestCase):
    def test_blocks_and_substitution(self):
        text = ("# x\n## Service\n```sh\n./build/apps/grip serve --port 8080 &\n"
                "$ curl -s http://localhost:8080/v1/health\n```\n\n    curl http://127.0.0.1:8080/v1/ready\n\n"
                "## Python client\n```sh\ncurl http://localhost:8080/v1/jobs\n```\n"
                "```json\n{\"curl \": 1}\n```\n")
        blocks = readme_curl_blocks(text)
        self.assertEqual(len(blocks), 2)
        script = to_script(blocks[0], "http://127.0.0.1:5")
        self.assertEqual(script, "curl -s http://127.0.0.1:5/v1/health")
        self.assertEqual(to_script(blocks[1], "http://h:1"), "curl http://h:1/v1/ready")


if __name__ == "__main__":
    unittest.main()
