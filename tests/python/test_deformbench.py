"""The Python module `deformbench` (deformbench-py/) against the command line, and its errors.

Run by scripts/test after it builds the wheel into the project's venv:
    python -m unittest discover -s tests/python -v     (from the repository root)
The harness binary is target/release/harness (CARGO_TARGET_DIR honoured) or $DEFORMBENCH_HARNESS.
"""

import glob
import json
import os
import subprocess
import tempfile
import unittest

import numpy as np

import deformbench

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SHAPES = ["bar", "cactus", "cylinder", "plane"]
# Small look-alikes of the survey's four tests: every method on every one in seconds.
VERTICES = 1500
# The methods whose measures and verdicts are checked against a run of theirs beside arap.
JUDGED = ["arap", "hirm", "scale_aware"]


def harness_binary():
    if os.environ.get("DEFORMBENCH_HARNESS"):
        return os.environ["DEFORMBENCH_HARNESS"]
    target = os.environ.get("CARGO_TARGET_DIR", os.path.join(ROOT, "target"))
    return os.path.join(target, "release", "harness")


def read_off(path):
    """#V x 3 positions of an OFF file (the harness writes shortest round-trip decimals)."""
    with open(path) as f:
        lines = [l for l in f if l.strip() and not l.startswith("#")]
    n = int(lines[1].split()[0])
    return np.array([[float(x) for x in l.split()[:3]] for l in lines[2 : 2 + n]])


def metric_keys():
    """The column names of the metrics table (measures of a unit square left at rest)."""
    V, F = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]]), np.array([[0, 1, 2], [0, 2, 3]])
    return list(deformbench.measures(V, F, V, fixed=[0, 1], handles=[[2]], targets=[[[1, 1, 0]]]))


def without_survey_env():
    env = dict(os.environ)
    env.pop("DEFORM_SURVEY_DIR", None)
    return env


class AgainstTheCommandLine(unittest.TestCase):
    """Every method through `Method` gives `harness run`'s result bit for bit, and `measures` and
    `verdict` its measures and status, on small look-alikes of the four survey tests."""

    @classmethod
    def setUpClass(cls):
        os.chdir(ROOT)  # the configuration of ./configs, as `harness run --configs configs`
        os.environ.pop("DEFORM_SURVEY_DIR", None)
        cls.tmp = tempfile.TemporaryDirectory()
        cls.scenarios = os.path.join(cls.tmp.name, "scenarios")
        os.makedirs(cls.scenarios)
        for shape in SHAPES:
            with open(os.path.join(cls.scenarios, f"{shape}.toml"), "w") as f:
                f.write(f'name = "{shape}"\nprocedural = {{ shape = "{shape}", vertices = {VERTICES} }}\n')
        cls.reports = {}
        for method in deformbench.methods():
            cls.reports[method] = cls.run_harness(f"reports-{len(cls.reports)}", [method])
        # The measures of a method are taken beside arap's result of the same run.
        cls.judged = cls.run_harness("reports-judged", JUDGED)

    @classmethod
    def run_harness(cls, name, methods):
        reports = os.path.join(cls.tmp.name, name)
        args = [harness_binary(), "run", "--configs", "configs"]
        for shape in SHAPES:
            args += ["--scenario", os.path.join(cls.scenarios, f"{shape}.toml")]
        for method in methods:
            args += ["--method", method]
        args += ["--mesh-format", "off", "--every-mesh", "--quiet"]
        args += ["--threads", str(os.cpu_count()), "--reports", reports]
        done = subprocess.run(args, env=without_survey_env(), capture_output=True, text=True)
        if done.returncode != 0:  # suspect and unfinished cases are results (exit 0)
            raise AssertionError(f"{' '.join(args)}: exit {done.returncode}\n{done.stderr}")
        return reports

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def scenario(self, shape):
        return deformbench.load_scenario(os.path.join(self.scenarios, f"{shape}.toml"))

    def test_every_method_equals_harness_run_to_the_last_bit(self):
        self.assertIn("scale_aware_ora", deformbench.methods())
        for shape in SHAPES:
            s = self.scenario(shape)
            self.assertEqual(s.mesh_source, "procedural look-alike")
            for method, reports in self.reports.items():
                with self.subTest(shape=shape, method=method):
                    (path,) = glob.glob(os.path.join(reports, "meshes", f"{shape}-*.off"))
                    m = deformbench.Method(method, s.V, s.F)
                    m.bind(s.fixed(), s.handles())
                    ours = m.solve(s.targets())
                    theirs = read_off(path)
                    self.assertEqual(ours.shape, theirs.shape)
                    differ = np.flatnonzero((ours != theirs).any(axis=1))
                    self.assertEqual(len(differ), 0, f"{len(differ)} vertices differ, first {differ[:5]}")
                    self.assertGreaterEqual(m.iterations, 1)

    def test_measures_and_verdict_equal_the_reports(self):
        with open(os.path.join(self.judged, "results.json")) as f:
            cases = {(c["scenario"], c["method"]): c for c in json.load(f)["cases"]}
        mesh = lambda shape, method: read_off(os.path.join(self.judged, "meshes", f"{shape}-{method}.off"))
        for shape in SHAPES:
            s = self.scenario(shape)
            edit = dict(fixed=s.fixed(), handles=s.handles(), targets=s.targets())
            reference = mesh(shape, "arap")
            for method in JUDGED:
                with self.subTest(shape=shape, method=method):
                    result = mesh(shape, method)
                    got = deformbench.verdict(s.V, s.F, result, reference=reference, **edit)
                    case = cases[(shape, method)]
                    self.assertIn("e_iso", got["measures"])
                    for key, value in got["measures"].items():
                        if value is None or not np.isfinite(value):
                            self.assertIsNone(case[key], key)
                        else:
                            self.assertEqual(value, case[key], key)
                    self.assertTrue(case["status"].startswith(got["status"]), f"{case['status']} vs {got}")
                    measured = deformbench.measures(s.V, s.F, result, reference=reference, **edit)
                    self.assertEqual(measured.keys(), got["measures"].keys())


class Errors(unittest.TestCase):
    """Bad input raises, naming the array and the element; never a panic."""

    @classmethod
    def setUpClass(cls):
        os.chdir(ROOT)
        # A unit square of two triangles, and a tetrahedron.
        cls.V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
        cls.F = np.array([[0, 1, 2], [0, 2, 3]])

    def test_bad_arrays_name_the_array_and_the_element(self):
        cases = [
            (lambda: deformbench.Method("arap", self.V[:, :2], self.F), ValueError, "V: expected a #N x 3"),
            (lambda: deformbench.Method("arap", np.where(np.arange(12).reshape(4, 3) == 7, np.nan, self.V), self.F),
             ValueError, "V[2, 1] is NaN (not finite)"),
            (lambda: deformbench.Method("arap", self.V, [[0, 1, 9]]), ValueError, "F[0, 2] = 9 is out of range"),
            (lambda: deformbench.Method("arap", self.V, [[0, 1, -1]]), ValueError, "F[0, 2] = -1 is out of range"),
            (lambda: deformbench.Method("arap", self.V, self.F.astype(float)), ValueError, "F: expected integer"),
            (lambda: deformbench.Method("arap", self.V, self.F[:, :2]), ValueError, "F: expected a #F x 3"),
            (lambda: deformbench.Method("arapp", self.V, self.F), deformbench.DeformbenchError, "arap"),
            (lambda: deformbench.Method("arap", self.V, self.F, tolerance="small"), deformbench.DeformbenchError,
             "tolerance"),
            (lambda: deformbench.Method("arap", self.V, self.F, no_such_key=1), deformbench.DeformbenchError,
             "no_such_key"),
        ]
        for call, kind, text in cases:
            with self.subTest(text=text):
                with self.assertRaises(kind) as raised:
                    call()
                self.assertIn(text, str(raised.exception))

    def test_bad_handles_and_targets(self):
        m = deformbench.Method("laplacian", self.V, self.F)
        with self.assertRaisesRegex(deformbench.DeformbenchError, "before bind"):
            m.solve([])
        with self.assertRaisesRegex(ValueError, r"handles\[0\]\[1\] = 4 is out of range"):
            m.bind([0], [[2, 4]])
        with self.assertRaisesRegex(ValueError, "vertex 0 is in both"):
            m.bind([0], [[0, 2]])
        m.bind([0, 1], [[2]])
        with self.assertRaisesRegex(ValueError, "targets: 0 arrays for 1 handles"):
            m.solve([])
        with self.assertRaisesRegex(ValueError, r"targets\[0\]: 2 rows for the 1 vertices"):
            m.solve([[[1, 1, 0.1], [0, 0, 0]]])
        with self.assertRaisesRegex(ValueError, r"targets\[0\]\[0, 2\] is inf"):
            m.solve([[[1, 1, np.inf]]])
        V1 = m.solve([[[1, 1, 0.1]]])
        self.assertEqual(V1.shape, (4, 3))
        # laplacian's constraints are soft (least squares, weight 1e5 or so): met to 1e-8.
        np.testing.assert_allclose(V1[:2], self.V[:2], atol=1e-8)
        np.testing.assert_allclose(V1[2], [1, 1, 0.1], atol=1e-8)

    def test_a_scenario_by_name_and_a_wrong_name(self):
        self.assertEqual(deformbench.load_scenario("cylinder").name, "cylinder")
        with self.assertRaisesRegex(deformbench.DeformbenchError, "cylindre: no such file, nor a scenario of .*cylinder"):
            deformbench.load_scenario("cylindre")

    def test_measures_of_the_rest_shape(self):
        got = deformbench.verdict(self.V, self.F, self.V, fixed=[0, 1], handles=[[2]], targets=[[[1, 1, 0]]])
        self.assertEqual(got["status"], "ok", got["reasons"])
        self.assertAlmostEqual(got["measures"]["e_iso"], 0.0, places=12)
        with self.assertRaisesRegex(ValueError, "V1: 3 rows, V0 has 4"):
            deformbench.measures(self.V, self.F, self.V[:3])


class PythonMethods(unittest.TestCase):
    """`deformbench.run` with Python objects as methods: the example external method's class
    in-process gives the row its program gives through the protocol; a function and a failing
    method are reported like external ones."""

    @classmethod
    def setUpClass(cls):
        os.chdir(ROOT)
        os.environ.pop("DEFORM_SURVEY_DIR", None)
        cls.tmp = tempfile.TemporaryDirectory()
        cls.scenario = os.path.join(cls.tmp.name, "bar.toml")
        with open(cls.scenario, "w") as f:
            f.write(f'name = "bar"\nprocedural = {{ shape = "bar", vertices = {VERTICES} }}\n')

    @classmethod
    def tearDownClass(cls):
        cls.tmp.cleanup()

    def test_a_class_in_process_gives_the_row_of_its_program_through_the_protocol(self):
        import sys

        sys.path.insert(0, os.path.join(ROOT, "external", "example"))
        from harmonic_displacement import HarmonicDisplacement

        name = "harmonic_displacement"
        reports = os.path.join(self.tmp.name, "in-process")
        (ours,) = deformbench.run([self.scenario], [(name, HarmonicDisplacement)], reports=reports)
        protocol = os.path.join(self.tmp.name, "protocol")
        args = [harness_binary(), "run", "--configs", "configs", "--scenario", self.scenario, "--quiet"]
        args += ["--methods", os.path.join(ROOT, "external", "example", "harmonic_displacement.toml")]
        args += ["--method", name, "--reports", protocol, "--python", sys.executable]
        done = subprocess.run(args, env=without_survey_env(), capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        with open(os.path.join(protocol, "results.json")) as f:
            (theirs,) = json.load(f)["cases"]
        self.assertEqual(ours["origin"], "external")
        for key in ["method", "origin", "vertices", "iterations", "converged", "status"]:
            self.assertEqual(ours[key], theirs[key], key)
        for key in metric_keys():
            self.assertEqual(ours[key], theirs[key], key)
        self.assertTrue(os.path.exists(os.path.join(reports, "index.html")))

    def test_a_function_and_a_failing_method(self):
        def handles_only(V, F, constrained, targets):
            """Moves the handles, nothing else: torn at the handles' border."""
            U = V.copy()
            U[constrained] = targets
            return U

        class Broken:
            def precompute(self, V, F):
                pass

            def bind(self, regions):
                pass

            def solve(self, constrained, targets):
                raise RuntimeError("no solution here")

        reports = os.path.join(self.tmp.name, "function")
        rows = deformbench.run([self.scenario], ["laplacian", handles_only, ("broken", Broken())], reports=reports)
        by_method = {r["method"]: r for r in rows}
        self.assertEqual(set(by_method), {"laplacian", "handles_only", "broken"})
        self.assertEqual(by_method["handles_only"]["handle_residual_over_diag"], 0.0)
        self.assertTrue(by_method["handles_only"]["status"].startswith("suspect"), by_method["handles_only"]["status"])
        self.assertIn("RuntimeError: no solution here", by_method["broken"]["status"])
        self.assertTrue(by_method["broken"]["status"].startswith("failed"))
        with self.assertRaisesRegex(ValueError, "neither a method name"):
            deformbench.run([self.scenario], [42], reports=reports)
        with self.assertRaisesRegex(deformbench.DeformbenchError, "give the method another name"):
            deformbench.run([self.scenario], [("arap", handles_only)], reports=reports)


class TheReadmeExample(unittest.TestCase):
    def test_the_readme_example_runs(self):
        """README, "From Python": `python examples/python/two_methods.py` from the repository root."""
        import sys

        done = subprocess.run([sys.executable, os.path.join("examples", "python", "two_methods.py")], cwd=ROOT,
                              env=without_survey_env(), capture_output=True, text=True)
        self.assertEqual(done.returncode, 0, done.stderr)
        lines = done.stdout.splitlines()
        self.assertTrue(lines[1].startswith("arap") and lines[2].startswith("hirm"), done.stdout)
        self.assertIn("e_iso", done.stdout)


if __name__ == "__main__":
    unittest.main()
