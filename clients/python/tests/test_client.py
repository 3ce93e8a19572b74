"""The library against a live `grip serve`: submit, stream, reconnect, result, dismiss,
errors with pointers, paging."""

import csv
import hashlib
import io
import json
import os
import tarfile
import unittest
import uuid

import support
from grip_client import Client, GripError


def run_small(client, **kw):
    job = client.submit(support.small_beam(**kw))
    doc = job.wait()
    return job, doc


class SubmitAndStream(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.client = support.client()
        cls.job, cls.doc = run_small(cls.client)
        cls.events = list(cls.job.events())

    def test_submit_gives_a_job_document_and_location(self):
        job = self.client.submit(support.small_beam(steps=2))
        self.assertEqual(job.location, "/v1/jobs/" + job.id)
        self.assertIn(job.doc["status"], ("accepted", "running", "successful"))
        self.assertEqual(job.doc["steps"], 2)
        self.assertEqual(job.doc["nodes"], 11)
        rels = {l["rel"] for l in job.doc["links"]}
        self.assertIn("self", rels)
        self.assertIn("monitor", rels)
        self.assertEqual(job.wait()["status"], "successful")

    def test_wait_returns_the_final_document(self):
        self.assertEqual(self.doc["status"], "successful")
        self.assertEqual(self.doc["progress"], 100)
        self.assertEqual(self.job.status()["jobID"], self.job.id)

    def test_events_are_numbered_and_complete(self):
        ids = [e.id for e in self.events]
        self.assertEqual(ids, list(range(1, len(ids) + 1)))
        types = [e.type for e in self.events]
        self.assertEqual(types[0], "step_started")
        self.assertEqual(types[-1], "job_finished")
        self.assertEqual(types.count("step_started"), 4)
        self.assertEqual(types.count("step_finished"), 4)
        for e in self.events:
            if e.type != "job_finished":
                self.assertEqual(e.data["type"], e.type)

    def test_iteration_events_equal_the_convergence_history(self):
        iters = [e.data for e in self.events if e.type == "iteration"]
        history = self.job.convergence()["iterations"]
        self.assertEqual(len(iters), len(history))
        self.assertEqual([h["v2"] for h in history], [e["v2"] for e in iters])
        self.assertEqual([h["step"] for h in history], [e["step"] for e in iters])
        # and the result's per-step history
        result = self.job.result()
        from_result = [h["v2"] for s in result["steps"] for h in s["history"]]
        self.assertEqual(from_result, [e["v2"] for e in iters])

    def test_events_after_an_id(self):
        k = 5
        tail = list(self.job.events(last_event_id=k))
        self.assertEqual([e.id for e in tail], [e.id for e in self.events[k:]])
        self.assertEqual([e.data for e in tail], [e.data for e in self.events[k:]])

    def test_reconnect_mid_stream_with_last_event_id(self):
        # The proxy cuts the first connection after 1500 bytes, in the middle of an event.
        proxy = support.CuttingProxy(support.server().port, cut_after=1500)
        try:
            via = Client(proxy.url)
            job = via.job(self.job.id)
            proxy.requests.clear()
            got = list(job.events())
        finally:
            proxy.close()
        self.assertGreaterEqual(job.reconnects, 1)
        self.assertEqual([e.id for e in got], [e.id for e in self.events])
        self.assertEqual([e.data for e in got], [e.data for e in self.events])
        streams = [r for r in proxy.requests if b"/events" in r.split(b"\r\n")[0]]
        self.assertEqual(len(streams), 2)
        self.assertNotIn(b"last-event-id", streams[0].lower())
        # The second stream resumes after the last whole event of the first.
        header = [l for l in streams[1].split(b"\r\n") if l.lower().startswith(b"last-event-id:")]
        self.assertEqual(len(header), 1)
        resumed_after = int(header[0].split(b":", 1)[1])
        self.assertGreater(resumed_after, 0)
        self.assertLess(resumed_after, len(self.events))

    def test_reconnect_mid_stream_of_a_running_job(self):
        # A long job streamed live through the cutting proxy; dismissed after 40 events.
        job = self.client.submit(support.long_sheet())
        proxy = support.CuttingProxy(support.server().port, cut_after=1500)
        got = []
        try:
            live = Client(proxy.url).job(job.id)
            for ev in live.events():
                got.append(ev)
                if len(got) == 40:
                    job.dismiss()
        finally:
            proxy.close()
            if not job.finished:
                job.status()
        self.assertGreaterEqual(live.reconnects, 1)
        self.assertEqual([e.id for e in got], list(range(1, len(got) + 1)))
        self.assertGreater(len(got), 40)
        self.assertEqual(got[-1].type, "job_failed")
        self.assertEqual([e.data for e in got], [e.data for e in job.events()])

    def test_ndjson_and_sse_carry_the_same_events(self):
        body = self.client.get(f"/v1/jobs/{self.job.id}/events?format=ndjson", raw=True)
        lines = [json.loads(l) for l in body.decode().splitlines() if l.strip()]
        self.assertEqual(lines, [e.data for e in self.events])


class Results(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.client = support.client()
        cls.job, _ = run_small(cls.client)
        cls.result = cls.job.result()

    def test_result_json(self):
        r = self.result
        self.assertTrue(r["summary"]["completed"])
        self.assertEqual(len(r["steps"]), 4)
        self.assertEqual(r["scene"]["body"]["mesh"]["elements"], 10)
        last = r["steps"][-1]
        self.assertEqual(len(last["nodes"]), 11)
        self.assertEqual(last["load_factor"], 1.0)
        self.assertTrue(any(c["state"] != "open" for c in last["contact_points"]))

    def test_result_csv_equals_json(self):
        text = self.job.result("csv", table="nodes")
        rows = list(csv.DictReader(io.StringIO(text)))
        last = [r for r in rows if int(r["step"]) == 4]
        self.assertEqual(len(last), 11)
        for row, node in zip(last, self.result["steps"][-1]["nodes"]):
            self.assertAlmostEqual(float(row["w"]), node["w"], places=12)

    def test_result_vtk_archive(self):
        data = self.job.result("vtk")
        with tarfile.open(fileobj=io.BytesIO(data)) as tar:
            names = tar.getnames()
        self.assertTrue(any(n.endswith(".pvd") for n in names))
        # one XML file per step (the .pvd's datasets)
        self.assertEqual(sum(n.endswith(".vtu") for n in names), 4)


class Dismiss(unittest.TestCase):
    def test_dismiss_a_running_job(self):
        client = support.client()
        job = client.submit(support.long_sheet())
        # The long run has not finished: no result yet.
        with self.assertRaises(GripError) as ctx:
            job.result()
        self.assertEqual(ctx.exception.status, 404)
        self.assertEqual(ctx.exception.problem["type"], "urn:grip:problem:result-not-ready")
        doc = job.dismiss()
        self.assertEqual(doc["status"], "dismissed")
        final = job.wait()
        self.assertEqual(final["status"], "dismissed")
        events = list(job.events())
        self.assertEqual(events[-1].type, "job_failed")
        self.assertIn("dismiss", json.dumps(events[-1].data))

    def test_dismiss_a_finished_job_removes_it(self):
        client = support.client()
        job, doc = run_small(client, steps=2)
        self.assertEqual(doc["status"], "successful")
        removed = job.dismiss()
        self.assertEqual(removed["jobID"], job.id)
        with self.assertRaises(GripError) as ctx:
            job.status()
        self.assertEqual(ctx.exception.status, 404)
        self.assertEqual(ctx.exception.problem["type"], "urn:grip:problem:job-not-found")


class Errors(unittest.TestCase):
    def setUp(self):
        self.client = support.client()

    def test_invalid_scene_gives_pointers(self):
        scene = support.small_beam()
        scene["body"]["mesh"]["elements"] = -1
        scene["steps"] = "x"
        del scene["obstacles"]
        with self.assertRaises(GripError) as ctx:
            self.client.submit(scene)
        e = ctx.exception
        self.assertEqual(e.status, 422)
        self.assertEqual(e.problem["type"], "urn:grip:problem:invalid-scene")
        self.assertEqual(set(e.pointers), {"/body/mesh/elements", "/steps", "/obstacles"})
        text = e.describe()
        for p in e.pointers:
            self.assertIn(p, text)

    def test_malformed_json(self):
        with self.assertRaises(GripError) as ctx:
            self.client.submit(b'{"body": ')
        self.assertEqual(ctx.exception.status, 400)
        self.assertEqual(ctx.exception.problem["type"], "urn:grip:problem:malformed-json")
        self.assertEqual(len(ctx.exception.errors), 1)

    def test_unknown_job(self):
        with self.assertRaises(GripError) as ctx:
            self.client.job("no-such-job")
        self.assertEqual(ctx.exception.status, 404)

    def test_bad_list_filter(self):
        with self.assertRaises(GripError) as ctx:
            list(self.client.jobs(status="sleeping"))
        self.assertEqual(ctx.exception.status, 400)

    def test_unreachable_server(self):
        with socket_free_port() as port:
            pass
        with self.assertRaises(GripError) as ctx:
            Client(f"http://127.0.0.1:{port}", timeout=3).health()
        self.assertEqual(ctx.exception.status, 0)


def socket_free_port():
    import contextlib
    import socket

    @contextlib.contextmanager
    def ctx():
        s = socket.socket()
        s.bind(("127.0.0.1", 0))
        try:
            yield s.getsockname()[1]
        finally:
            s.close()

    return ctx()


class Paging(unittest.TestCase):
    def test_jobs_follow_next_links(self):
        client = support.client()
        ids = []
        for k in range(3):
            ids.append(client.submit(support.small_beam(steps=1)).id)
        for i in ids:
            client.job(i).wait()
        listed = [j.id for j in client.jobs(page_size=2)]
        self.assertEqual(len(listed), len(set(listed)))
        # newest first: the three just submitted come in reverse order
        pos = [listed.index(i) for i in ids]
        self.assertEqual(pos, sorted(pos, reverse=True))
        self.assertEqual([j.id for j in client.jobs(page_size=2, limit=3)], listed[:3])
        for j in client.jobs(status="successful", page_size=2):
            self.assertEqual(j.doc["status"], "successful")

    def test_idempotency_key_replays(self):
        client = support.client()
        key = "test-" + uuid.uuid4().hex
        first = client.submit(support.small_beam(steps=1), idempotency_key=key)
        again = client.submit(support.small_beam(steps=1), idempotency_key=key)
        self.assertEqual(first.id, again.id)
        self.assertFalse(first.replayed)
        self.assertTrue(again.replayed)
        with self.assertRaises(GripError) as ctx:
            client.submit(support.small_beam(steps=2), idempotency_key=key)
        self.assertEqual(ctx.exception.status, 422)
        first.wait()


class Meshes(unittest.TestCase):
    """gmsh meshes: uploaded once (POST /v1/meshes), named in the scene by their id."""

    BLOCK = os.path.join(support.REPO, "tests", "data", "gmsh", "block.msh")

    @classmethod
    def setUpClass(cls):
        cls.client = support.client()

    def block_scene(self):
        # The sliding block on gmsh's 20 x 10 quadrilaterals of the same rectangle (block.geo).
        scene = support.example("sliding-block")
        del scene["body"]["element"]
        scene["body"]["mesh"] = {"gmsh": {"file": "block.msh"}}
        return scene

    def test_a_mesh_is_uploaded_and_the_scene_names_it_by_id(self):
        with open(self.BLOCK, "rb") as f:
            data = f.read()
        sha = hashlib.sha256(data).hexdigest()
        job = self.client.submit(self.block_scene(), meshes={"block.msh": self.BLOCK})
        self.assertEqual(job.wait()["status"], "successful")
        result = job.result()
        self.assertEqual(result["scene"]["body"]["mesh"]["gmsh"]["id"], sha)
        self.assertNotIn("file", result["scene"]["body"]["mesh"]["gmsh"])
        upload = self.client.upload_mesh(data)  # the same bytes again: the same id
        self.assertEqual(upload["id"], sha)
        self.assertEqual(upload["elements"], {"q4": 200})
        self.assertEqual(upload["nodes"], 231)

        # It solves as the generated rectangle: the same displacement at each place.
        generated = self.client.submit(support.example("sliding-block"))
        self.assertEqual(generated.wait()["status"], "successful")
        reference = generated.result()
        for mine, theirs in zip(result["steps"], reference["steps"]):
            def by_place(nodes):
                return {(round(n["x"] - n["ux"], 4), round(n["y"] - n["uy"], 4)): (n["ux"], n["uy"])
                        for n in nodes}
            a, b = by_place(mine["nodes"]), by_place(theirs["nodes"])
            self.assertEqual(a.keys(), b.keys())
            largest = max(abs(v) for uv in b.values() for v in uv)
            for place, uv in b.items():
                for u, v in zip(a[place], uv):
                    self.assertAlmostEqual(u, v, delta=1e-6 * largest, msg=f"node at {place}")

    def test_a_reference_without_a_mesh_names_its_pointer(self):
        scene = self.block_scene()
        scene["obstacles"][0]["shape"] = {"type": "gmsh_curve", "gmsh": {"file": "tools/tool.msh"},
                                          "curve": "flat"}
        with self.assertRaises(ValueError) as e:
            self.client.with_meshes(scene, {"block.msh": self.BLOCK})
        self.assertIn("/obstacles/0/shape/gmsh/file: no mesh given for 'tools/tool.msh'",
                      str(e.exception))
        self.assertNotIn("/body/mesh", str(e.exception))
        # A name with a folder takes the file of its base name; each file is uploaded once.
        tool = os.path.join(support.REPO, "tests", "data", "gmsh", "tool.msh")
        out = self.client.with_meshes(scene, {"block.msh": self.BLOCK, "tool.msh": tool})
        self.assertEqual(set(out["obstacles"][0]["shape"]["gmsh"]), {"id"})
        self.assertEqual(scene["obstacles"][0]["shape"]["gmsh"]["file"], "tools/tool.msh")  # a copy

    def test_a_file_the_reader_refuses_is_a_422_naming_its_line(self):
        with self.assertRaises(GripError) as e:
            self.client.upload_mesh(b"$MeshFormat\n5.0 0 8\n$EndMeshFormat\n")
        self.assertEqual(e.exception.status, 422)
        self.assertIn("upload:2:", e.exception.describe())


if __name__ == "__main__":
    unittest.main()
