"""`plot` and `plot --paper`: every PNG is written, and every plotted series equals the
result's numbers (read back from the matplotlib lines). Needs matplotlib: run with Debian's
/usr/bin/python3 and python3-matplotlib installed (scripts/setup.sh does)."""

import json
import os
import tempfile
import unittest

import support

try:
    import matplotlib  # noqa: F401

    HAVE_MPL = True
except ImportError:
    HAVE_MPL = False

PNG = b"\x89PNG\r\n\x1a\n"


def lines_by_gid(fig):
    out = {}
    for ax in fig.axes:
        for line in ax.get_lines():
            if line.get_gid():
                out[line.get_gid()] = line
    return out


def floats(seq):
    return [float(v) for v in seq]


@unittest.skipUnless(HAVE_MPL, "matplotlib is not importable by this python "
                               "(use /usr/bin/python3 with python3-matplotlib)")
class PlotCase(unittest.TestCase):
    """A temporary folder and the plots module for the class; `produce` makes what it plots."""

    @classmethod
    def setUpClass(cls):
        cls.tmp = tempfile.TemporaryDirectory()
        from grip_client import plots

        cls.plots = plots
        cls.produce()

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def tearDown(self):
        self.plots.pyplot().close("all")


class Plots(PlotCase):
    @classmethod
    def produce(cls):
        cls.out = os.path.join(cls.tmp.name, "paper")
        cls.proc = support.cli("plot", "--paper", "-o", cls.out, timeout=600)
        cls.client = support.client()
        with open(os.path.join(cls.out, "paper-summary.json"), encoding="utf-8") as f:
            cls.summary = json.load(f)
        cls.results = {name: cls.client.job(s["job"]).result() for name, s in cls.summary.items()}

    def assert_png(self, path):
        with open(path, "rb") as f:
            head = f.read(8)
        self.assertEqual(head, PNG, path)
        self.assertGreater(os.path.getsize(path), 10000, path)

    def test_paper_writes_every_figure(self):
        self.assertEqual(self.proc.returncode, 0, self.proc.stdout + self.proc.stderr)
        expected = ["fig4_sheet_shapes", "fig5_sheet_strain", "sheet_normal_stress",
                    "sheet_friction_stress", "sheet_convergence", "fig6_beam_shapes",
                    "fig7_beam_normal_stress", "fig8_beam_friction_stress",
                    "fig9_beam_load_deflection", "beam_convergence"]
        for stem in expected:
            self.assert_png(os.path.join(self.out, stem + ".png"))
        files = sorted(f for s in self.summary.values() for f in s["files"].values())
        self.assertEqual(files, sorted(stem + ".png" for stem in expected))

    def test_convergence_series_equal_the_history(self):
        for name, result in self.results.items():
            fig, data = self.plots.convergence(result)
            lines = lines_by_gid(fig)
            count, zero = 0, 0
            for step in result["steps"]:
                it, v2 = [], []
                for h in step["history"]:
                    count += 1
                    if h["v2"] > 0:
                        it.append(count)
                        v2.append(h["v2"])
                    else:
                        zero += 1
                if v2:
                    line = lines[f"step-{step['step']}"]
                    self.assertEqual(floats(line.get_xdata()), floats(it))
                    self.assertEqual(floats(line.get_ydata()), v2)
                else:
                    self.assertNotIn(f"step-{step['step']}", lines)
            self.assertEqual(data["zero"], zero)
            tol = result["scene"]["solver"]["contact"]["tolerance"] * \
                result["scene"]["body"]["mesh"]["length"]
            self.assertEqual(floats(lines["tolerance"].get_ydata()), [tol, tol])
            self.assertEqual(fig.axes[0].get_yscale(), "log")

    def test_shapes_are_the_deformed_nodes(self):
        for name, result in self.results.items():
            fig, data = self.plots.shapes(result)
            lines = lines_by_gid(fig)
            n = len(result["steps"])
            self.assertEqual(sorted(data["steps"]), {30: [5, 10, 15, 20, 25, 30],
                                                      20: [4, 8, 12, 16, 20]}[n])
            for k in data["steps"]:
                nodes = result["steps"][k - 1]["nodes"]
                line = lines[f"step-{k}"]
                self.assertEqual(floats(line.get_xdata()), [p["x"] for p in nodes])
                self.assertEqual(floats(line.get_ydata()), [p["y"] for p in nodes])
            ku, kv = ("u", "w") if name == "beam-on-cylinder" else ("ux", "uy")
            # Drawn from the first step shown: its positions less its displacements (both in
            # 7 digits, so each step gives the undeformed mesh to within some 1e-6 of its own).
            first = result["steps"][min(data["steps"]) - 1]["nodes"]
            self.assertEqual(floats(lines["initial"].get_xdata()), [p["x"] - p[ku] for p in first])
            zero = result["steps"][0]["nodes"]
            for drawn, p in zip(floats(lines["initial"].get_xdata()), zero):
                self.assertAlmostEqual(drawn, p["x"] - p[ku], delta=1e-6 * max(1.0, abs(p["x"])))
        sheet = self.results["sheet-stretching"]
        # The punch is drawn where the result puts it: 5 mm further down every five steps.
        _, data = self.plots.shapes(sheet)
        self.assertEqual([data["steps"][k]["offsets"]["punch"][1] for k in (5, 30)],
                         [sheet["steps"][4]["obstacles"][0]["offset"][1], -30.0])

    def test_strain_along_the_sheet(self):
        result = self.results["sheet-stretching"]
        fig, data = self.plots.strain(result)
        lines = lines_by_gid(fig)
        els = result["steps"][-1]["elements"]
        self.assertEqual(floats(lines["major_strain"].get_xdata()), [e["s0"] for e in els])
        self.assertEqual(floats(lines["major_strain"].get_ydata()), [e["major_strain"] for e in els])
        self.assertEqual(floats(lines["thickness_strain"].get_ydata()),
                         [e["thickness_strain"] for e in els])
        self.assertEqual(data["peak"]["major_strain"], max(e["major_strain"] for e in els))
        self.assertEqual(self.summary["sheet-stretching"]["highlights"]["strain_peak"]["major_strain"],
                         data["peak"]["major_strain"])

    def test_contact_stress_along_the_body(self):
        for name, result in self.results.items():
            last = result["steps"][-1]
            x0 = {n["node"]: n["x"] - n["u" if "u" in n else "ux"] for n in last["nodes"]}
            for component, key in (("normal", "sigma_n"), ("friction", "sigma_t")):
                fig, data = self.plots.contact_stress(result, component)
                lines = lines_by_gid(fig)
                for o in result["scene"]["obstacles"]:
                    pts = sorted((c for c in last["contact_points"] if c["obstacle"] == o["name"]),
                                 key=lambda c: c["node"])
                    line = lines[f"{key}-{o['name']}"]
                    self.assertEqual(floats(line.get_xdata()), [x0[c["node"]] for c in pts])
                    self.assertEqual(floats(line.get_ydata()), [c[key] for c in pts])

    def test_frictional_stress_changes_direction_on_the_beam(self):
        result = self.results["beam-on-cylinder"]
        _, data = self.plots.contact_stress(result, "friction")
        pts = sorted(result["steps"][-1]["contact_points"], key=lambda c: c["node"])
        touching = [c for c in pts if c["state"] != "open" and c["sigma_t"] != 0]
        flips = [(a, b) for a, b in zip(touching, touching[1:]) if a["sigma_t"] * b["sigma_t"] < 0]
        # One change of direction, as in the paper's Fig. 8: the old contact on the left pulls
        # left (ξ points left on top of the cylinder), the new contact on the right pulls right.
        self.assertEqual(len(flips), 1)
        self.assertEqual(len(data["obstacles"]["cylinder"]["sign_changes"]), 1)
        left = [c for c in touching if c["node"] <= flips[0][0]["node"]]
        right = [c for c in touching if c["node"] >= flips[0][1]["node"]]
        fx = dict(zip(data["obstacles"]["cylinder"]["node"], data["obstacles"]["cylinder"]["force_x"]))
        self.assertTrue(all(fx[c["node"]] < 0 for c in left))
        self.assertTrue(all(fx[c["node"]] > 0 for c in right))
        self.assertEqual(self.summary["beam-on-cylinder"]["highlights"]["friction_sign_changes"],
                         {"cylinder": data["obstacles"]["cylinder"]["sign_changes"]})

    def test_load_against_end_deflection(self):
        result = self.results["beam-on-cylinder"]
        fig, data = self.plots.load_deflection(result)
        lines = lines_by_gid(fig)
        F = 500.0
        self.assertEqual(floats(lines["deflection"].get_ydata()),
                         [0.0] + [s["load_factor"] * F for s in result["steps"]])
        self.assertEqual(floats(lines["deflection"].get_xdata()),
                         [0.0] + [-s["nodes"][40]["w"] for s in result["steps"]])
        self.assertEqual(floats(lines["horizontal"].get_xdata()),
                         [0.0] + [-s["nodes"][40]["u"] for s in result["steps"]])

    def test_plot_a_job(self):
        job = self.client.submit(support.small_beam())
        job.wait()
        out = os.path.join(self.tmp.name, "job")
        p = support.cli("plot", job.id, "-o", out)
        self.assertEqual(p.returncode, 0, p.stderr)
        names = sorted(os.listdir(out))
        self.assertEqual(names, sorted(["convergence.png", "shapes.png", "contact_normal.png",
                                        "contact_friction.png", "load_deflection.png"]))
        for n in names:
            self.assert_png(os.path.join(out, n))
        p = support.cli("plot", "-o", out)
        self.assertEqual(p.returncode, 2)


class TwoBodyPlots(PlotCase):
    """A scene of several bodies (schemas/examples/two-cylinders.json, solved by `grip solve`):
    each body is its own line, named, with exactly its rows of `nodes`, and the contact stress
    is drawn per contact pair."""

    @classmethod
    def produce(cls):
        import subprocess

        out = os.path.join(cls.tmp.name, "result.json")
        scene = os.path.join(support.EXAMPLES, "two-cylinders.json")
        subprocess.run([support.grip_binary(), "solve", scene, "--out", out], check=True,
                       capture_output=True, timeout=120)
        with open(out, encoding="utf-8") as f:
            cls.result = json.load(f)

    def test_each_body_is_its_own_line(self):
        fig, data = self.plots.shapes(self.result)
        lines = lines_by_gid(fig)
        bodies = self.result["bodies"]
        self.assertEqual([b["name"] for b in bodies], ["upper", "lower"])
        for k in data["steps"]:
            nodes = self.result["steps"][k - 1]["nodes"]
            for b in bodies:
                rows = nodes[b["first_node"]:b["first_node"] + b["nodes"]]
                line = lines[f"step-{k}-{b['name']}"]
                self.assertEqual(floats(line.get_xdata()), [p["x"] for p in rows])
                self.assertEqual(floats(line.get_ydata()), [p["y"] for p in rows])
                self.assertEqual(data["steps"][k]["bodies"][b["name"]]["x"], [p["x"] for p in rows])
        self.assertEqual(sum(b["nodes"] for b in bodies), len(self.result["steps"][-1]["nodes"]))

    def test_contact_stress_per_pair(self):
        last = self.result["steps"][-1]
        pair = self.result["scene"]["contacts"][0]["name"]
        fig, data = self.plots.contact_stress(self.result, "normal")
        line = lines_by_gid(fig)[f"sigma_n-{pair}"]
        pts = sorted((c for c in last["contact_points"] if c["obstacle"] == pair), key=lambda c: c["node"])
        self.assertTrue(any(c["sigma_n"] < 0 for c in pts))
        self.assertEqual(floats(line.get_ydata()), [c["sigma_n"] for c in pts])
        self.assertIn("contact_normal", self.plots.applicable(self.result))


class PunchStretchingPlots(PlotCase):
    """The axisymmetric punch stretching (schemas/examples/punch-stretching-axisymmetric.json,
    solved by `grip solve`): the punch force against the depth, and the strains over the radius
    at 10, 20 and 30 mm, each series the result's numbers."""

    @classmethod
    def produce(cls):
        import subprocess

        out = os.path.join(cls.tmp.name, "result.json")
        scene = os.path.join(support.EXAMPLES, "punch-stretching-axisymmetric.json")
        subprocess.run([support.grip_binary(), "solve", scene, "--out", out], check=True,
                       capture_output=True, timeout=300)
        with open(out, encoding="utf-8") as f:
            cls.result = json.load(f)

    def test_punch_force_against_depth(self):
        fig, data = self.plots.punch_force(self.result)
        line = lines_by_gid(fig)["force"]
        steps = self.result["steps"]
        self.assertEqual(floats(line.get_xdata()), [0.0] + [-s["obstacles"][0]["offset"][1] for s in steps])
        # The force on the punch: minus the contact forces on the sheet, -p_n n + p_t (-n_y, n_x).
        expected = [0.0] + [sum(c["p_n"] * c["normal"][1] - c["p_t"] * c["normal"][0]
                                for c in s["contact_points"] if c["obstacle"] == "punch") for s in steps]
        for got, want in zip(floats(line.get_ydata()), expected):
            self.assertAlmostEqual(got, want, delta=1e-9 * max(expected))
        self.assertTrue(all(b > a for a, b in zip(expected, expected[1:])))  # rises with the depth
        self.assertIn("punch_force", self.plots.applicable(self.result))

    def test_strains_over_the_radius(self):
        fig, data = self.plots.radial_strains(self.result)
        self.assertEqual(sorted(data["steps"]), [10, 20, 30])
        lines = lines_by_gid(fig)
        for k in (10, 20, 30):
            els = self.result["steps"][k - 1]["elements"]
            for key in ("meridional_strain", "hoop_strain", "thickness_strain"):
                line = lines[f"{key}-{k}"]
                self.assertEqual(floats(line.get_xdata()), [e["s0"] for e in els])
                self.assertEqual(floats(line.get_ydata()), [e[key] for e in els])
        self.assertIn("radial_strains", self.plots.applicable(self.result))
        self.assertNotIn("strain", self.plots.applicable(self.result))


if __name__ == "__main__":
    unittest.main()
