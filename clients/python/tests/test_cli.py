"""`python3 -m grip_client` against a live server: output, files and exit codes
(0 success, 1 job failed, 2 usage or HTTP error with the problem's pointers)."""

import hashlib
import json
import os
import re
import tempfile
import unittest

import support
from grip_client import Client


def write_json(folder, name, doc):
    path = os.path.join(folder, name)
    with open(path, "w", encoding="utf-8") as f:
        json.dump(doc, f)
    return path


class Cli(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.client = support.client()
        cls.small = write_json(cls.tmp.name, "small.json", support.small_beam())
        cls.failing = write_json(cls.tmp.name, "failing.json", support.failing_beam())

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_submit_watch_prints_a_line_per_iteration_and_a_bar_per_step(self):
        p = support.cli("submit", self.small, "--watch")
        self.assertEqual(p.returncode, 0, p.stderr)
        lines = p.stdout.splitlines()
        job_id = lines[0].strip()
        events = list(self.client.job(job_id).events())
        iterations = [e for e in events if e.type == "iteration"]
        it_lines = [l for l in lines if "||v||" in l]
        self.assertEqual(len(it_lines), len(iterations))
        for line, ev in zip(it_lines, iterations):
            self.assertIn(f"step {ev['step']}", line)
            self.assertIn(f"m {ev['m']:>3}", line)
            self.assertIn(f"||v|| {ev['v2']:.3e}", line)
            self.assertIn(f"stick {ev['stick']}  slip {ev['slip']}", line)
        done = [l for l in lines if "converged:" in l]
        self.assertEqual(len(done), 4)
        for k, line in enumerate(done, start=1):
            self.assertIn(f"] {k}/4", line)
            self.assertIn("#" * (5 * k) + "." * (20 - 5 * k) + "]", line)
        self.assertEqual(lines[-1], "job finished: 4 of 4 steps")

    def test_failed_job_exits_1(self):
        p = support.cli("submit", self.failing, "--watch")
        self.assertEqual(p.returncode, 1, p.stdout + p.stderr)
        self.assertIn("job failed", p.stdout)
        # The reason with its kind and what to do about it (cli.FAILURE_ADVICE, by kind).
        self.assertRegex(p.stdout, r"job failed: step \d+ failed: .* \[[a-z_]+: [^\]]+\]")
        job_id = p.stdout.splitlines()[0].strip()
        self.assertEqual(support.cli("watch", job_id).returncode, 1)
        status = support.cli("status", job_id)
        self.assertEqual(status.returncode, 1)
        self.assertRegex(status.stdout, r"(?m)^failure +.* \[[a-z_]+: ")
        self.assertRegex(status.stdout, r"(?m)^steps_completed +\d+$")

    def test_invalid_scene_exits_2_with_pointers(self):
        scene = support.small_beam()
        scene["body"]["mesh"]["elements"] = 0
        scene["obstacles"][0]["friction"] = "high"
        path = write_json(self.tmp.name, "invalid.json", scene)
        p = support.cli("submit", path)
        self.assertEqual(p.returncode, 2)
        self.assertIn("422 Invalid scene", p.stderr)
        self.assertRegex(p.stderr, r"(?m)^  /body/mesh/elements: ")
        self.assertRegex(p.stderr, r"(?m)^  /obstacles/0/friction: ")

    def test_usage_and_http_errors_exit_2(self):
        self.assertEqual(support.cli().returncode, 2)
        self.assertEqual(support.cli("submit").returncode, 2)
        self.assertEqual(support.cli("submit", os.path.join(self.tmp.name, "none.json")).returncode, 2)
        p = support.cli("status", "no-such-job")
        self.assertEqual(p.returncode, 2)
        self.assertIn("404 Job not found", p.stderr)
        p = support.cli("sweep", self.small, "--set", "steps")
        self.assertEqual(p.returncode, 2)
        p = support.cli("list", env_extra={"GRIP_URL": "http://127.0.0.1:1"})
        self.assertEqual(p.returncode, 2)
        self.assertIn("cannot reach", p.stderr)

    def test_plot_without_matplotlib_says_how_to_get_it(self):
        # A matplotlib that cannot be imported, first on the path: as on a python without it.
        hidden = os.path.join(self.tmp.name, "no-matplotlib", "matplotlib")
        os.makedirs(hidden, exist_ok=True)
        with open(os.path.join(hidden, "__init__.py"), "w", encoding="utf-8") as f:
            f.write("raise ImportError('No module named matplotlib')\n")
        path = os.path.dirname(hidden) + os.pathsep + os.environ.get("PYTHONPATH", "")
        if not support.INSTALLED:
            path = os.path.dirname(hidden) + os.pathsep + support.PACKAGE_DIR
        p = support.cli("plot", "any-job", "-o", self.tmp.name, env_extra={"PYTHONPATH": path})
        self.assertEqual(p.returncode, 2, p.stderr)
        self.assertIn("plot needs matplotlib", p.stderr)
        self.assertIn("python3-matplotlib", p.stderr)
        self.assertIn("grip-client[plot]", p.stderr)
        self.assertNotIn("Traceback", p.stderr)
        # Everything else works without it.
        p = support.cli("list", "--limit", "1", env_extra={"PYTHONPATH": path})
        self.assertEqual(p.returncode, 0, p.stderr)

    def test_status_list_result_dismiss(self):
        job = self.client.submit(support.small_beam(steps=2))
        job.wait()
        p = support.cli("status", job.id)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertRegex(p.stdout, r"(?m)^status +successful$")
        self.assertRegex(p.stdout, r"(?m)^steps +2$")
        p = support.cli("status", job.id, "--json")
        self.assertEqual(json.loads(p.stdout)["jobID"], job.id)

        p = support.cli("list", "--status", "successful", "--limit", "500")
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn(job.id, p.stdout)

        out = os.path.join(self.tmp.name, "result")
        p = support.cli("result", job.id, "-o", out, "--format", "all")
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(out, "result.json"), encoding="utf-8") as f:
            self.assertEqual(json.load(f), job.result())
        for t in ("steps", "nodes", "contact_points", "history"):
            with open(os.path.join(out, t + ".csv"), encoding="utf-8") as f:
                self.assertEqual(f.read(), job.result("csv", table=t))
        pvd = [n for n in os.listdir(os.path.join(out, "vtk", "grip-" + job.id[:8]))
               if n.endswith(".pvd")]
        self.assertEqual(len(pvd), 1)

        p = support.cli("dismiss", job.id)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertEqual(support.cli("status", job.id).returncode, 2)

    def test_sweep_tabulates_outputs_of_each_variant(self):
        p = support.cli("sweep", self.small, "--set", "obstacles.0.friction=0,0.3",
                        "--set", "/steps=2,4", "--output", "steps.-1.nodes.-1.w",
                        "--output", "summary.contact_iterations", "--json")
        self.assertEqual(p.returncode, 0, p.stderr)
        rows = json.loads(p.stdout)
        self.assertEqual([(r["obstacles.0.friction"], r["/steps"]) for r in rows],
                         [(0, 2), (0, 4), (0.3, 2), (0.3, 4)])
        client = Client(support.server().url)
        for r in rows:
            self.assertEqual(r["status"], "successful")
            result = client.job(r["jobID"]).result()
            self.assertEqual(result["scene"]["obstacles"][0]["friction"], r["obstacles.0.friction"])
            self.assertEqual(len(result["steps"]), r["/steps"])
            self.assertEqual(r["steps.-1.nodes.-1.w"], result["steps"][-1]["nodes"][-1]["w"])
            self.assertEqual(r["summary.contact_iterations"],
                             result["summary"]["contact_iterations"])
        # The text table has a header, a rule and one row per variant; CSV too.
        csv_path = os.path.join(self.tmp.name, "sweep.csv")
        p = support.cli("sweep", self.small, "--set", "obstacles.0.friction=0.1,0.2",
                        "--output", "summary.steps", "--csv", csv_path)
        self.assertEqual(p.returncode, 0, p.stderr)
        lines = p.stdout.splitlines()
        self.assertEqual(len(lines), 4)
        self.assertTrue(re.match(r"obstacles\.0\.friction +status +summary\.steps +jobID", lines[0]))
        self.assertRegex(lines[2], r"^0\.1 +successful +4 ")
        with open(csv_path, encoding="utf-8") as f:
            self.assertEqual(f.readline().strip(), "obstacles.0.friction,status,summary.steps,jobID")

    def test_sweep_with_a_failing_variant_exits_1(self):
        p = support.cli("sweep", self.small, "--set", "solver.newton.max_iterations=40,1",
                        "--output", "summary.steps", "--json")
        self.assertEqual(p.returncode, 1, p.stderr)
        rows = json.loads(p.stdout)
        self.assertEqual([r["status"] for r in rows], ["successful", "failed"])
        self.assertEqual(rows[0]["summary.steps"], 4)
        self.assertIsNone(rows[1]["summary.steps"])


class Meshes(unittest.TestCase):
    """submit --mesh: the scene's gmsh files uploaded (POST /v1/meshes), named by their ids."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        cls.client = support.client()
        cls.msh = os.path.join(support.EXAMPLES, "hertz-t6.msh")
        with open(cls.msh, "rb") as f:
            cls.sha = hashlib.sha256(f.read()).hexdigest()
        # The example alone in a folder of its own: its .msh is not beside it.
        cls.alone = write_json(cls.tmp.name, "hertz.json", support.example("hertz-t6"))

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def solved_with_the_upload(self, p):
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        job = self.client.job(p.stdout.splitlines()[0].strip())
        self.assertEqual(job.wait()["status"], "successful")
        result = job.result()
        self.assertEqual(result["scene"]["body"]["mesh"]["gmsh"], {"id": self.sha, "surfaces": []})
        self.assertTrue(result["summary"]["completed"])
        return result

    def test_submit_with_mesh_uploads_it_and_the_job_solves(self):
        self.solved_with_the_upload(support.cli("submit", self.alone, "--mesh", self.msh, "--watch"))
        # Without --mesh: the file beside the scene, as grip solve reads it; example:NAME: the
        # server's example file. The same bytes each time: one stored mesh.
        beside = self.solved_with_the_upload(
            support.cli("submit", os.path.join(support.EXAMPLES, "hertz-t6.json")))
        example = self.solved_with_the_upload(support.cli("submit", "example:hertz-t6"))
        self.assertEqual(beside["steps"][-1]["nodes"], example["steps"][-1]["nodes"])
        self.assertEqual(self.client.get("/v1/meshes/" + self.sha)["id"], self.sha)

    def test_a_missing_or_unused_mesh_is_a_usage_error(self):
        p = support.cli("submit", self.alone)
        self.assertEqual(p.returncode, 2)
        self.assertIn("/body/mesh/gmsh/file names 'hertz-t6.msh': give it with --mesh", p.stderr)
        other = os.path.join(support.REPO, "tests", "data", "gmsh", "block.msh")
        p = support.cli("submit", self.alone, "--mesh", self.msh, "--mesh", other)
        self.assertEqual(p.returncode, 2)
        self.assertIn("--mesh block.msh: the scene names no such file", p.stderr)
        p = support.cli("submit", self.alone, "--mesh", os.path.join(self.tmp.name, "none.msh"))
        self.assertEqual(p.returncode, 2)
        self.assertIn("none.msh: no such file", p.stderr)
        # A file the reader refuses: the server's 422 with the line.
        bad = os.path.join(self.tmp.name, "hertz-t6.msh")
        with open(bad, "w", encoding="utf-8") as f:
            f.write("$MeshFormat\n5.0 0 8\n$EndMeshFormat\n")
        p = support.cli("submit", self.alone, "--mesh", bad)
        self.assertEqual(p.returncode, 2)
        self.assertIn("422 Invalid mesh", p.stderr)
        self.assertIn("upload:2:", p.stderr)
        os.remove(bad)


class Study(unittest.TestCase):
    def test_study_tabulates_each_level_and_the_extrapolation(self):
        # Lame's thick cylinder, axisymmetric q4 at 2 x 1, 4 x 2 and 8 x 4 elements: u_r at the
        # inner radius converges at about q4's order 2 toward the closed form.
        scene = {
            "body": {"model": "continuum", "kinematics": "linear", "analysis": "axisymmetric",
                     "element": "q4",
                     "material": {"young": 1000, "poisson": 0.3, "law": "saint_venant_kirchhoff"},
                     "mesh": {"rectangle": {"origin": [1, 0], "size": [1, 0.5], "divisions": [2, 1]}},
                     "contact_set": "right",
                     "supports": [{"set": "bottom", "fix": ["y"]}, {"set": "top", "fix": ["y"]}],
                     "loads": [{"set": "left", "traction": [10, 0]}]},
            "obstacles": [{"name": "far", "shape": {"type": "segment", "from": [100, 50],
                                                    "to": [200, 50]}}],
            "solver": {"contact": {"reach": 0.01}},
            "outputs": [{"name": "u_inner", "kind": "displacement", "at": [1, 0], "component": "x"}]}
        tmp = tempfile.TemporaryDirectory()
        self.addCleanup(tmp.cleanup)
        path = write_json(tmp.name, "cylinder.json", scene)
        p = support.cli("study", path, "--levels", "3", "--json")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        doc = json.loads(p.stdout)
        self.assertEqual(doc["status"], "successful")
        q = doc["quantities"][0]
        exact = 10 * 1 / (1000 * 3) * 1.3 * (0.4 * 1 + 4 / 1)
        self.assertTrue(1.5 <= q["order"] <= 2.5, q)
        self.assertLess(abs(q["extrapolated"] - exact), abs(q["values"][2] - exact))
        p = support.cli("study", path, "--levels", "3")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        self.assertIn("u_inner error", p.stdout)
        self.assertIn("cheapest < 1 %", p.stdout)
        # Refined until u_inner's estimate is below 0.5 %: three levels give 2.9e-3.
        p = support.cli("study", path, "--accuracy", "u_inner=0.005", "--json")
        self.assertEqual(p.returncode, 0, p.stdout + p.stderr)
        doc = json.loads(p.stdout)
        self.assertTrue(doc["answer"]["reached"], doc["answer"])
        self.assertEqual(doc["answer"]["level"], 3)
        self.assertLess(doc["answer"]["estimated_error"], 0.005)


if __name__ == "__main__":
    unittest.main()
