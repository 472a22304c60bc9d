"""`inspect` over the serial driver, interrupted and resumed: the demo blade on the simulated rig
served on a pty (SimRigDevice), failing inside the 2nd blind section (the port vanishes), then
inside the 1st planned section (an alarm) and the 2nd (garbage), then inside the re-planned
scan (silence); each time the folder keeps a checkpoint (no result), and each resume runs on a
fresh device. The last resume must
end with exactly the files of one uninterrupted run of the same rig in process: the same
points.csv rows (nothing measured twice or lost) and the same pose.

A small epsilon (0.2 mm) puts the re-plan threshold at 0.5 um, so the loop re-plans here and
the re-planned scan can be interrupted too; the blind scan keeps the usual 2 mm criterion."""
import contextlib
import hashlib
import io
import json
import os
import shutil
import tempfile
import unittest

import numpy as np

from BladeInspect.core import transforms as tf
from BladeInspect.core.errors import DeviceError, InputError
from BladeInspect.core.pointio import read_points
from BladeInspect.inspection.run_options import RunOptions
from tests.helpers import demo_nominal, first_difference, read_json, read_lines

HEIGHTS = (30.0, 70.0)
SEED = 23
EPSILON = 0.2
SCAN_OPTIONS = {"n_sections": 3, "point_spacing": 0.5, "edges": False, "epsilon": 2.0}
RESULT_FILES = ("result.json", "deviations.csv", "report.html", "report.pdf")
# Where the chain of runs fails: the device's fault and what the driver's error says.
FAULTS = {"blind": ("close", "motion port lost"),
          "first planned": ("alarm", r"hard limit: controller raised ALARM:1"),
          "planned": ("garbage", "garbage from the controller"),
          "replanned": ("silent", r"timeout, no answer within 1 s")}


def simulated_rig(nominal):
    from BladeInspect.rig.simulated import SimulatedRig, random_fixture_pose
    return SimulatedRig(nominal, random_fixture_pose(np.random.default_rng(SEED)), seed=SEED)


class Reference:
    """One uninterrupted run in process, with the rig's pass index at each blind section and
    each planned path (per plan attempt): where to make the device fail."""

    def __init__(self, nominal, out):
        from BladeInspect.inspection.closed_loop import run_inspect
        rig = simulated_rig(nominal)
        self.blind_section_pass = []
        self.path_pass = []         # per attempt: pass index at the start of each path
        self.plans = []

        def progress(fraction, message):
            if message.startswith("section "):
                self.blind_section_pass.append(rig.pass_index)
            elif message.startswith("planned scan: path"):
                self.path_pass[-1].append(rig.pass_index)

        def on_plan(plan):
            self.plans.append(plan)
            self.path_pass.append([])
        self.summary = run_inspect(None, out,
                                   RunOptions.of(seed=SEED, section_heights=HEIGHTS,
                                                 epsilon=EPSILON, scan_options=dict(SCAN_OPTIONS)),
                                   rig=rig, nominal=nominal, document=False, progress=progress,
                                   on_plan=on_plan)
        self.points_lines = read_lines(os.path.join(out, "points.csv"))
        self.points = read_points(os.path.join(out, "points.csv"))
        self.result = read_json(os.path.join(out, "result.json"))
        self.scan = read_json(os.path.join(out, "scan.json"))
        self.plan_text = [plan.to_json() for plan in self.plans]
        self.truth = rig.table_to_cad

    def inside_section(self, attempt, section):
        """Pass index at the 2nd path of a planned section: the section has begun and is
        not finished."""
        plan = self.plans[attempt]
        paths = [i for i, p in enumerate(plan.paths) if p.section == section]
        assert len(paths) >= 2, "section %d has one path: no fault inside it" % section
        return self.path_pass[attempt][paths[1]]


class TestInspectResume(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.nominal = demo_nominal()
        cls.tmp = tempfile.mkdtemp(prefix="bi-resume-")
        cls.ref = Reference(cls.nominal, os.path.join(cls.tmp, "reference"))
        cls.out = os.path.join(cls.tmp, "serial")
        cls.snapshots = {}
        cls.errors = {}
        ref = cls.ref
        # Where each device fails (absolute pass index of the rig), and what the resumed run
        # starts from.
        faults = {"blind": ref.blind_section_pass[1] + 2,
                  "first planned": ref.inside_section(0, 0),
                  "planned": ref.inside_section(0, 1),
                  "replanned": ref.inside_section(1, 1)}
        start = 0
        for name in ("blind", "first planned", "planned", "replanned"):
            try:
                cls.run_serial(FAULTS[name][0], faults[name] - start, resume=start > 0)
            except DeviceError as exc:
                cls.errors[name] = str(exc)
            cls.snapshots[name] = cls.snapshot()
            start = cls.resume_pass_index(cls.snapshots[name]["scan.json"])
        cls.final_summary = cls.run_serial(resume=True)
        cls.final = cls.snapshot()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def run_serial(cls, kind=None, fault_at=None, resume=False):
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.rig.serial_rig import SerialRig
        from BladeInspect.rig.simrig_device import Fault, SimRigDevice
        fault = None if kind is None else Fault(kind, after_passes=fault_at)
        with SimRigDevice(simulated_rig(cls.nominal), fault=fault) as device:
            # A silent device is noticed after the timeout; ray casting a long pass is not
            # silence (the device reports Run meanwhile).
            rig = SerialRig(device.port_url, timeout_s=1.0 if kind == "silent" else 5.0)
            try:
                # The serial rig's sensor model comes from the device's ID: the defaults of
                # the simulated rig's, so both plan the same paths.
                return run_inspect(None, cls.out,
                                   RunOptions.of(seed=SEED, section_heights=HEIGHTS,
                                                 epsilon=EPSILON, scan_options=dict(SCAN_OPTIONS),
                                                 resume=resume), rig=rig, nominal=cls.nominal,
                                   document=False)
            finally:
                rig.close()

    @classmethod
    def snapshot(cls):
        files = {}
        for name in sorted(os.listdir(cls.out)):
            path = os.path.join(cls.out, name)
            files[name] = read_json(path) if name.endswith(".json") else None
        files["points_lines"] = read_lines(os.path.join(cls.out, "points.csv"))
        files["points"] = read_points(os.path.join(cls.out, "points.csv"))
        return files

    @staticmethod
    def resume_pass_index(record):
        state = record["inspection"]
        if state["phase"] == "blind":
            return record["checkpoint"]["strategy"]["pass_index"]
        return state["pass_index"]

    # -- helpers ---------------------------------------------------------------------------

    def assert_rows_match_reference(self, points, reference_rows):
        """Checkpoint rows against reference rows, to the 6 decimals the final file keeps."""
        ref = self.ref.points
        self.assertEqual(len(points.xyz), len(reference_rows))
        np.testing.assert_allclose(points.xyz, ref.xyz[reference_rows], rtol=0, atol=6e-7)
        np.testing.assert_allclose(points.snr, ref.snr[reference_rows], rtol=0, atol=6e-7)
        for name in ("section", "angle_deg"):
            np.testing.assert_allclose(points.columns[name], ref.columns[name][reference_rows],
                                       rtol=0, atol=6e-7)
        np.testing.assert_array_equal(points.columns["phase"],
                                      ref.columns["phase"][reference_rows])

    def assert_device_error(self, name):
        message = self.errors[name]
        self.assertRegex(message, r"^serial:\S+: .*" + FAULTS[name][1])
        self.assertNotIn("\n", message)

    def assert_is_checkpoint(self, snap, phase):
        for name in RESULT_FILES:
            self.assertNotIn(name, snap)
        record = snap["scan.json"]
        self.assertFalse(record["complete"])
        self.assertFalse(record["inspection"]["complete"])
        self.assertEqual(record["inspection"]["phase"], phase)
        self.assertEqual(record["inspection"]["options"]["seed"], SEED)

    def planned_rows_of(self, sections):
        """The blind rows and those of the reference's planned scan of these sections (of its
        last plan)."""
        blind = self.ref.points.columns["phase"] == "blind"
        first = int(np.max(self.ref.points.columns["section"][blind])) + 1
        keep = blind.copy()
        for k in sections:
            keep |= self.ref.points.columns["section"] == first + k
        return np.flatnonzero(keep)

    # -- the reference itself --------------------------------------------------------------

    def test_reference_replans(self):
        self.assertEqual(len(self.ref.plans), 2, self.ref.result["replans"])
        self.assertGreater(self.ref.result["replans"][0]["pose_change_mm"],
                           self.ref.result["replans"][0]["threshold_mm"])

    # -- each interruption -----------------------------------------------------------------

    def test_blind_fault_keeps_the_finished_blind_section(self):
        self.assert_device_error("blind")
        self.assertNotIn("\n", self.errors["blind"])
        snap = self.snapshots["blind"]
        self.assert_is_checkpoint(snap, "blind")
        self.assertNotIn("plan.json", snap)
        self.assertEqual([s["index"] for s in snap["scan.json"]["sections"]], [0])
        blind = self.ref.points.columns["phase"] == "blind"
        first_section = np.flatnonzero(blind & (self.ref.points.columns["section"] == 0))
        self.assert_rows_match_reference(snap["points"], first_section)
        self.assertEqual(snap["points_lines"][0], "x,y,z,snr,section,angle_deg,phase")

    def test_fault_in_the_first_planned_section(self):
        self.assert_device_error("first planned")
        snap = self.snapshots["first planned"]
        self.assert_is_checkpoint(snap, "planned")
        state = snap["scan.json"]["inspection"]
        self.assertEqual((state["attempt"], state["sections_done"]), (0, []))
        # Nothing planned kept; the next pass is the first planned one.
        self.assertEqual(state["pass_index"], self.ref.path_pass[0][0])
        self.assert_rows_match_reference(snap["points"], self.planned_rows_of([]))

    def test_planned_fault_keeps_the_finished_planned_section(self):
        self.assert_device_error("planned")
        snap = self.snapshots["planned"]
        self.assert_is_checkpoint(snap, "planned")
        state = snap["scan.json"]["inspection"]
        self.assertEqual(state["attempt"], 0)
        self.assertEqual(state["sections_done"], [0])
        plan = self.ref.plans[0]
        n_paths = sum(1 for p in plan.paths if p.section == 0)
        self.assertEqual(state["paths_done"], n_paths)
        self.assertEqual(state["pass_index"], self.ref.path_pass[0][n_paths])
        with open(os.path.join(self.tmp, "plan0.json"), "w") as fh:
            fh.write(self.ref.plan_text[0])
        self.assertEqual(snap["plan.json"], read_json(os.path.join(self.tmp, "plan0.json")))
        # The blind rows as the reference measured them; the planned rows of section 0 of
        # the first plan (the reference replaced them when it re-planned) lie on that
        # section's nominal plane by the simulator's truth, one row per reading.
        phase = snap["points"].columns["phase"]
        blind_rows = np.flatnonzero(self.ref.points.columns["phase"] == "blind")
        self.assertEqual(int(np.count_nonzero(phase == "blind")), len(blind_rows))
        planned = phase == "planned"
        self.assertEqual(int(planned.sum()), sum(r["readings"] for r in state["paths"]))
        cad = tf.apply_transform(self.ref.truth, snap["points"].xyz[planned])
        section = plan.sections[0]
        self.assertLess(np.max(np.abs((cad - section.plane_point) @ section.plane_normal)),
                        0.01)

    def test_replanned_fault_keeps_the_finished_replanned_section(self):
        self.assert_device_error("replanned")
        snap = self.snapshots["replanned"]
        self.assert_is_checkpoint(snap, "planned")
        state = snap["scan.json"]["inspection"]
        self.assertEqual(state["attempt"], 1)
        self.assertEqual(state["sections_done"], [0])
        self.assertEqual(len(state["replans"]), 1)
        # The first plan's rows are gone, the re-planned section 0 is the reference's own.
        self.assert_rows_match_reference(snap["points"], self.planned_rows_of([0]))

    # -- the finished run ------------------------------------------------------------------

    def test_resumed_run_equals_the_uninterrupted_one(self):
        self.assertIsNone(first_difference(self.final["points_lines"], self.ref.points_lines))
        T = np.asarray(self.final["result.json"]["measured_to_cad"])
        np.testing.assert_allclose(T, np.asarray(self.ref.result["measured_to_cad"]),
                                   rtol=0, atol=1e-9)
        self.assertEqual(self.final["plan.json"]["paths"],
                         json.loads(self.ref.plan_text[1])["paths"])
        for name in RESULT_FILES:
            self.assertIn(name, self.final)
        record = self.final["scan.json"]
        self.assertTrue(record["complete"])
        self.assertNotIn("inspection", record)
        # The same passes, numbered as in the uninterrupted run (the simulator's noise
        # stream per pass).
        mine = record["phases"]["planned"]["paths"]
        theirs = self.ref.scan["phases"]["planned"]["paths"]
        self.assertEqual([(p["section"], p["readings"], p["pass_index"]) for p in mine],
                         [(p["section"], p["readings"], p["pass_index"]) for p in theirs])
        self.assertEqual(record["passes"], self.ref.scan["passes"])
        self.assertEqual([r["n_measured"] for r in record["replans"]],
                         [r["n_measured"] for r in self.ref.scan["replans"]])


class TestResumeRefusals(unittest.TestCase):
    """What --resume refuses, leaving the checkpoint as it was; and the command line's
    one-line error and exit status when the rig fails."""

    @classmethod
    def setUpClass(cls):
        from BladeInspect.rig.serial_rig import SerialRig
        from BladeInspect.rig.simrig_device import Fault, SimRigDevice
        from BladeInspect.inspection.closed_loop import run_inspect
        cls.nominal = demo_nominal()
        cls.tmp = tempfile.mkdtemp(prefix="bi-refuse-")
        cls.out = os.path.join(cls.tmp, "out")
        # Two blind passes in (the span probes), the port vanishes: a blind checkpoint with
        # no finished section.
        with SimRigDevice(simulated_rig(cls.nominal), fault=Fault("close", after_passes=2)) \
                as device:
            rig = SerialRig(device.port_url, timeout_s=5)
            try:
                with contextlib.suppress(DeviceError):
                    run_inspect(None, cls.out,
                                RunOptions.of(seed=SEED, section_heights=HEIGHTS,
                                              scan_options=dict(SCAN_OPTIONS)), rig=rig,
                                nominal=cls.nominal, document=False)
            finally:
                rig.close()
        cls.files = cls.contents()

    @classmethod
    def tearDownClass(cls):
        shutil.rmtree(cls.tmp, ignore_errors=True)

    @classmethod
    def contents(cls):
        """Each file's digest: a refused resume must leave every byte as it was."""
        out = {}
        for name in sorted(os.listdir(cls.out)):
            with open(os.path.join(cls.out, name), "rb") as fh:
                out[name] = hashlib.sha256(fh.read()).hexdigest()
        return out

    def refused(self, pattern, **options):
        from BladeInspect.inspection.closed_loop import run_inspect
        nominal = options.pop("nominal", self.nominal)
        run_options = RunOptions.of(seed=SEED, section_heights=HEIGHTS, resume=True)
        with self.assertRaisesRegex(InputError, pattern) as ctx:
            run_inspect(None, self.out, run_options.replace(**options),
                        rig=simulated_rig(self.nominal), nominal=nominal, document=False)
        self.assertNotIsInstance(ctx.exception, DeviceError)
        self.assertNotIn("\n", str(ctx.exception))
        self.assertEqual(self.contents(), self.files)
        self.assertEqual([n for n in os.listdir(self.tmp) if n.startswith(".")], [])

    def test_checkpoint_without_a_finished_section(self):
        self.assertEqual(sorted(self.files), ["points.csv", "scan.json"])
        record = read_json(os.path.join(self.out, "scan.json"))
        self.assertEqual(record["sections"], [])
        self.assertEqual(record["inspection"]["phase"], "blind")

    def test_other_seed(self):
        self.refused(r"--seed \(23, not 24\)", seed=24)

    def test_other_heights(self):
        self.refused("--section-heights", section_heights=(30.0, 60.0))

    def test_other_blind_options(self):
        self.refused("blind scan's options", scan_options=dict(SCAN_OPTIONS, n_sections=4))

    def test_other_part(self):
        from BladeInspect.cad.demo_blade import BladeParams, make_demo_blade
        from BladeInspect.cad.nominal import nominal_from_shape
        model = make_demo_blade(BladeParams(span=60.0))
        self.refused("another part", nominal=nominal_from_shape(model.shape, roles=model.roles))

    def test_another_kind_of_rig(self):
        # Begun over the serial driver; the in-process simulated rig is another rig.
        self.refused("made on a SerialRig rig, not a SimulatedRig",
                     scan_options=dict(SCAN_OPTIONS))

    def test_complete_instead_of_sections(self):
        self.refused("--complete", complete=True)

    def test_fresh_run_into_a_checkpoint(self):
        self.refused("holds an interrupted inspection", resume=False)

    def test_nothing_to_resume(self):
        from BladeInspect.inspection.closed_loop import run_inspect
        empty = os.path.join(self.tmp, "empty")
        with self.assertRaisesRegex(InputError, "holds no interrupted inspection"):
            run_inspect(None, empty, RunOptions.of(seed=SEED, resume=True),
                        rig=simulated_rig(self.nominal), nominal=self.nominal, document=False)
        self.assertFalse(os.path.exists(empty))

    def test_failure_over_an_earlier_result_leaves_no_result(self):
        """A run into a folder holding a finished inspection fails on the rig: the folder is
        then a checkpoint, and none of the earlier result files stands beside it."""
        from BladeInspect.inspection.closed_loop import run_inspect
        from BladeInspect.rig.serial_rig import SerialRig
        from BladeInspect.rig.simrig_device import Fault, SimRigDevice
        out = os.path.join(self.tmp, "over-a-result")
        os.makedirs(out)
        for name in RESULT_FILES + ("plan.json", "points.csv"):
            with open(os.path.join(out, name), "w") as fh:
                fh.write("earlier\n")
        with open(os.path.join(out, "scan.json"), "w") as fh:
            json.dump({"complete": True}, fh)
        with SimRigDevice(simulated_rig(self.nominal), fault=Fault("close", after_passes=2)) \
                as device:
            rig = SerialRig(device.port_url, timeout_s=5)
            try:
                with self.assertRaises(DeviceError):
                    run_inspect(None, out,
                                RunOptions.of(seed=SEED, section_heights=HEIGHTS,
                                              scan_options=dict(SCAN_OPTIONS)), rig=rig,
                                nominal=self.nominal, document=False)
            finally:
                rig.close()
        self.assertEqual(sorted(os.listdir(out)), ["points.csv", "scan.json"])
        self.assertEqual(read_json(os.path.join(out, "scan.json"))["inspection"]["phase"],
                         "blind")
        self.assertEqual(read_lines(os.path.join(out, "points.csv")),
                         ["x,y,z,snr,section,angle_deg,phase"])

    def test_command_line_device_error(self):
        """`inspect --rig serial:PORT` on a device whose port vanishes: one line on stderr,
        the device-error exit status, a checkpoint on disk; then --resume with another seed is
        refused the same way."""
        from BladeInspect import cli
        from BladeInspect.rig.simrig_device import Fault, SimRigDevice
        out = os.path.join(self.tmp, "cli")
        with SimRigDevice(simulated_rig(self.nominal), fault=Fault("close", after_passes=1)) \
                as device:
            stderr = io.StringIO()
            with contextlib.redirect_stderr(stderr), contextlib.redirect_stdout(io.StringIO()):
                status = cli.main(["inspect", "--rig", "serial:" + device.port_url,
                                   "--out", out, "--seed", str(SEED)])
        self.assertEqual(status, cli.EXIT_BAD_INPUT)
        errors = [line for line in stderr.getvalue().splitlines() if "error" in line]
        self.assertEqual(len(errors), 1, stderr.getvalue())
        self.assertRegex(errors[0], r"^bladeinspect: error: serial:.*: motion port lost")
        self.assertEqual(sorted(os.listdir(out)), ["points.csv", "scan.json"])
        stderr = io.StringIO()
        with contextlib.redirect_stderr(stderr):
            status = cli.main(["inspect", "--rig", "sim", "--out", out, "--seed", "5",
                               "--resume"])
        self.assertEqual(status, cli.EXIT_BAD_INPUT)
        self.assertRegex(stderr.getvalue(), r"^bladeinspect: error: --resume .*--seed "
                                            r"\(23, not 5\)[^\n]*\n$")


class TestCancelledInspectionResumes(unittest.TestCase):
    """A cancel (the GUI's Cancel, raised from the progress callback) in the planned phase
    keeps what was measured as a checkpoint, as a rig failure does; --resume then ends as the
    uninterrupted run."""

    def test_cancel_in_the_planned_phase_then_resume(self):
        from BladeInspect.core.errors import Cancelled
        from BladeInspect.inspection.closed_loop import run_inspect
        nominal = demo_nominal()
        tmp = tempfile.mkdtemp(prefix="bi-cancel-")
        self.addCleanup(shutil.rmtree, tmp, True)
        ref = Reference(nominal, os.path.join(tmp, "reference"))
        out = os.path.join(tmp, "cancelled")
        rig = simulated_rig(nominal)
        inside_second_section = ref.inside_section(0, 1)

        def cancel_inside_second_section(fraction, message):
            if (message.startswith("planned scan: path")
                    and rig.pass_index >= inside_second_section):
                raise Cancelled("inspection cancelled")
        options = RunOptions.of(seed=SEED, section_heights=HEIGHTS, epsilon=EPSILON,
                                scan_options=dict(SCAN_OPTIONS))
        with self.assertRaises(Cancelled):
            run_inspect(None, out, options, rig=rig, nominal=nominal, document=False,
                        progress=cancel_inside_second_section)
        record = read_json(os.path.join(out, "scan.json"))
        self.assertFalse(record["complete"])
        self.assertEqual(record["inspection"]["phase"], "planned")
        for name in RESULT_FILES:
            self.assertFalse(os.path.exists(os.path.join(out, name)), name)
        # The blind scan and the planned section finished before the cancel are kept (the
        # reference's own planned rows are the re-plan's: the loop re-plans at this epsilon).
        kept = read_points(os.path.join(out, "points.csv"))
        self.assertGreater(np.count_nonzero(kept.columns["phase"] == "planned"), 0)
        blind, ref_blind = (p.xyz[p.columns["phase"] == "blind"] for p in (kept, ref.points))
        np.testing.assert_allclose(blind, ref_blind, atol=1e-6)

        run_inspect(None, out, options.replace(resume=True), rig=simulated_rig(nominal),
                    nominal=nominal, document=False)
        self.assertIsNone(first_difference(read_lines(os.path.join(out, "points.csv")),
                                           ref.points_lines))
        pose = np.asarray(read_json(os.path.join(out, "result.json"))["measured_to_cad"])
        np.testing.assert_allclose(pose, np.asarray(ref.result["measured_to_cad"]), atol=1e-9)


if __name__ == "__main__":
    unittest.main()
