"""Shared test helpers: paths to the shared real-blade data, the demo blade, the GUI runner, a
pose's bound computed from the truth, CPU timing, reading result files."""
import json
import os
import resource

import numpy as np

from BladeInspect.core import transforms as tf

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.normpath(os.path.join(REPO, "..", "shared"))
ROTOR67_DIR = os.path.join(SHARED, "data", "blades", "nasa_rotor67")
ROTOR67_SECTIONS = os.path.join(ROTOR67_DIR, "rotor67geometry.dat")
ROTOR67_CLOUD = os.path.join(ROTOR67_DIR, "MoveSurface_NASA_R67_parablade.txt")


_DEMO_NOMINAL = []


def demo_nominal():
    """The built-in demo blade's Nominal, built once per test run (about a second) and shared
    by the modules that only read it."""
    if not _DEMO_NOMINAL:
        from BladeInspect.inspection.pipeline import load_nominal
        _DEMO_NOMINAL.append(load_nominal(None))
    return _DEMO_NOMINAL[0]


def have_rotor67():
    return os.path.exists(ROTOR67_SECTIONS)


def run_freecad_gui(macro, out_dir, timeout_s):
    """Run a macro in the real FreeCAD GUI under Xvfb with a private HOME, the workbench
    installed there the way users install it (a link in the user Mod folder), so FreeCAD's own
    settings stay untouched. The macro finds BI_GUI_OUT (= out_dir) and BI_REPO in its
    environment; FreeCAD's output goes to out_dir/freecad.log."""
    import subprocess
    home = os.path.join(out_dir, "home")
    env = dict(os.environ, HOME=home, QTWEBENGINE_DISABLE_SANDBOX="1", BI_GUI_OUT=out_dir,
               BI_REPO=REPO, FREECAD_USER_MOD=os.path.join(home, ".local", "share", "FreeCAD",
                                                           "Mod"))
    for key in ("XDG_DATA_HOME", "XDG_CONFIG_HOME"):
        env.pop(key, None)
    subprocess.run([os.path.join(REPO, "scripts", "install-workbench.sh")], env=env,
                   check=True, capture_output=True)
    # Each test worker (scripts/run_tests.py) looks for a free display from its own number up:
    # two xvfb-run -a starting together from the same number can both take it.
    first_display = 99 + 50 * int(os.environ.get("BLADEINSPECT_TEST_WORKER", "0"))
    cmd = ["xvfb-run", "-a", "-n", str(first_display), "-s", "-screen 0 1280x1024x24",
           "freecad", macro]
    with open(os.path.join(out_dir, "freecad.log"), "w") as log:
        subprocess.run(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, timeout=timeout_s,
                       cwd=out_dir)


SCREENS = "/tmp/bladeinspect-screens"


class GuiMacroChecks:
    """Mixed into a unittest.TestCase: runs MACRO in the real GUI once for the class, copies its
    log, checks and screenshots to SCREENS for people to look at (log and checks under
    LOG_NAME/CHECKS_NAME), and asserts the macro finished with every check (at least MIN_CHECKS)
    passed. The macro writes BI_GUI_OUT/checks.json."""
    MACRO = None
    TIMEOUT_S = 900   # a bound for a hung GUI on a loaded machine, not a speed requirement
    MIN_CHECKS = 1
    LOG_NAME = "freecad.log"
    CHECKS_NAME = None

    @classmethod
    def setUpClass(cls):
        import json
        import shutil
        import tempfile
        cls.tmp = tempfile.mkdtemp(prefix="bi-gui-")
        run_freecad_gui(os.path.join(REPO, "tests", cls.MACRO), cls.tmp, cls.TIMEOUT_S)
        path = os.path.join(cls.tmp, "checks.json")
        cls.report = None
        if os.path.exists(path):
            with open(path) as fh:
                cls.report = json.load(fh)
        os.makedirs(SCREENS, exist_ok=True)
        shutil.copy(os.path.join(cls.tmp, "freecad.log"), os.path.join(SCREENS, cls.LOG_NAME))
        if cls.report is not None and cls.CHECKS_NAME:
            shutil.copy(path, os.path.join(SCREENS, cls.CHECKS_NAME))
        for name in os.listdir(cls.tmp):
            if name.endswith(".png"):
                shutil.copy(os.path.join(cls.tmp, name), SCREENS)

    @classmethod
    def tearDownClass(cls):
        import shutil
        shutil.rmtree(cls.tmp, ignore_errors=True)

    def test_macro_ran_to_the_end(self):
        with open(os.path.join(self.tmp, "freecad.log")) as fh:
            log = fh.read()[-3000:]
        self.assertIsNotNone(self.report, "the GUI macro wrote no checks; log tail:\n" + log)

    def test_every_check_passed(self):
        import json
        self.assertIsNotNone(self.report)
        failed = [c for c in self.report["checks"] if not c["ok"]]
        self.assertEqual(failed, [], json.dumps(failed, indent=1))
        self.assertGreater(len(self.report["checks"]), self.MIN_CHECKS)


def least_squares_pose_bound(points_cad, normals, sigma, corners):
    """1 sigma worst-corner displacement of the efficient (least-squares) pose estimate from
    readings with independent errors of standard deviation `sigma` along the surface normals at
    the true points, computed here from first principles (information sum J^T J / sigma^2 with
    J = [n, p x n] for a small motion (t, w) about the points' centroid), never from the code
    under test. For normal errors it is the Cramér–Rao bound; for any errors of that variance
    (the simulations' are uniform) it is the least a linear unbiased fit can reach
    (Gauss–Markov). Returns (bound mm, 6x6 covariance about the centroid, the centroid)."""
    p = np.asarray(points_cad, dtype=float)
    n = np.asarray(normals, dtype=float)
    c = p.mean(axis=0)
    J = np.hstack([n, np.cross(p - c, n)])
    weights = np.broadcast_to(1.0 / np.asarray(sigma, dtype=float) ** 2, (len(p),))
    cov = np.linalg.inv((J * weights[:, None]).T @ J)
    worst = 0.0
    for x in np.asarray(corners, dtype=float) - c:
        # The corner moves by t + w x (corner - c) = [I, -[x]_x] [t, w].
        A = np.hstack([np.eye(3), -np.array([[0.0, -x[2], x[1]], [x[2], 0.0, -x[0]],
                                             [-x[1], x[0], 0.0]])])
        worst = max(worst, float(np.sqrt(np.trace(A @ cov @ A.T))))
    return worst, cov, c


def sensor_pose_bound(nominal, truth, xyz, snr, sensor, error_field=None):
    """least_squares_pose_bound for readings of the simulated rig's sensor (uniform noise of
    half-width accuracy * sqrt(SNR_ref / SNR) along the beam, rounded to its resolution), at
    the true points the simulator's pose `truth` maps them to. The beam's error is taken whole
    along the normal, which it meets at an angle: the bound returned is an upper limit of the
    true one. Gross errors (beyond the noise's half-width) and points on a known error field
    are left out, as an efficient estimator would leave them. Returns (bound mm, n points)."""
    if sensor.noise != "uniform":
        raise ValueError("sensor_pose_bound: uniform sensor noise only")
    snr = np.asarray(snr, dtype=float)
    true = nominal.signed_distance(tf.apply_transform(truth, xyz))
    half_width = sensor.accuracy * np.sqrt(sensor.snr_ref / snr)
    field = np.zeros(len(snr)) if error_field is None else error_field(true.closest)
    keep = (np.abs(true.distance) <= half_width + sensor.resolution) & (field == 0)
    sigma = np.sqrt(half_width[keep] ** 2 / 3.0 + sensor.resolution ** 2 / 12.0)
    bound = least_squares_pose_bound(true.closest[keep], true.normal[keep], sigma,
                                     nominal.bbox_corners)[0]
    return bound, int(np.count_nonzero(keep))


def best_cpu_seconds(run, tries=3, enough=None):
    """The least CPU time this thread spent in run() over up to `tries` calls (stopping at the
    first under `enough` seconds), and the last call's value. CPU time, not wall time: other
    jobs share the machine's cores; the thread's own, so that another thread of the test
    process does not count; the best of several, so that a first call's page faults do not."""
    def spent():
        usage = resource.getrusage(resource.RUSAGE_THREAD)
        return usage.ru_utime + usage.ru_stime
    best, value = float("inf"), None
    for _ in range(tries):
        start = spent()
        value = run()
        best = min(best, spent() - start)
        if enough is not None and best < enough:
            break
    return best, value


def read_json(path):
    with open(path) as fh:
        return json.load(fh)


def read_lines(path):
    with open(path) as fh:
        return fh.read().splitlines()


def first_difference(mine, theirs):
    """None when the two lists of lines are equal, else a short note of the first difference
    (assertEqual's diff of thousands of lines takes minutes)."""
    for i, (a, b) in enumerate(zip(mine, theirs)):
        if a != b:
            return "line %d: %r != %r" % (i + 1, a, b)
    if len(mine) != len(theirs):
        return "%d lines, not %d" % (len(mine), len(theirs))
    return None


def rodrigues(points, angle_deg, direction, point=(0.0, 0.0, 0.0)):
    """Points turned by angle_deg about the line through ``point`` along ``direction``:
    Rodrigues' vector form, independent of the project's rotation matrices."""
    k = np.asarray(direction, float) / np.linalg.norm(direction)
    v = np.atleast_2d(points) - np.asarray(point, float)
    a = np.radians(angle_deg)
    return (np.asarray(point, float) + v * np.cos(a) + np.cross(k, v) * np.sin(a)
            + np.outer(v @ k, k) * (1 - np.cos(a)))


def face_points(face, n, rng, margin=0.05):
    """(points (n, 3), OCC's unit normals there (n, 3), parameters (n, 2)) at random parameters
    of a Part face, ``margin`` of its parameter range clear of the range's ends."""
    u0, u1, v0, v1 = face.ParameterRange
    uv = rng.uniform([u0 + margin * (u1 - u0), v0 + margin * (v1 - v0)],
                     [u1 - margin * (u1 - u0), v1 - margin * (v1 - v0)], size=(n, 2))
    p = np.array([tuple(face.valueAt(a, b)) for a, b in uv])
    nrm = np.array([tuple(face.normalAt(a, b)) for a, b in uv])
    return p, nrm / np.linalg.norm(nrm, axis=1)[:, None], uv


def _read_plan(rig, plan):
    """Each path of the plan read on a simulated rig: (path, which spots gave a reading, their
    table points, their SNR)."""
    k = rig.kinematics
    for path in plan.paths:
        r = rig.scan_path(plan.path_stage_xyz(path), path.angle_deg)
        d = np.asarray(r.reading_mm, dtype=float)
        ok = np.isfinite(d)
        table = k.table_point(k.machine_point(np.asarray(r.stage_xyz)[ok], d[ok]),
                              path.angle_deg)
        yield path, ok, table, np.asarray(r.snr)[ok]


def planned_pointset(rig, plan):
    """The plan's paths read on a simulated rig, as the rig reports them: a PointSet of table
    points with their SNR and an ``angle_deg`` column (what a planned scan writes)."""
    from BladeInspect.core.pointio import PointSet
    xyz, snr, angle = [], [], []
    for path, ok, table, s in _read_plan(rig, plan):
        xyz.append(table)
        snr.append(s)
        angle.append(np.full(int(ok.sum()), path.angle_deg))
    return PointSet(xyz=np.vstack(xyz), snr=np.concatenate(snr),
                    columns={"angle_deg": np.concatenate(angle)}, source="planned")


def planned_readings_result(nominal, rig, plan):
    """The plan's paths read on a simulated rig and mapped into the CAD by the rig's true pose:
    (a RegistrationResult with no registration error, (n, 2) planned [section, point] of each
    reading)."""
    from BladeInspect.core import stats
    from BladeInspect.inspection.result import RegistrationResult
    xyz, snr, planned = [], [], []
    for path, ok, table, s in _read_plan(rig, plan):
        xyz.append(tf.apply_transform(rig.table_to_cad, table))
        snr.append(s)
        planned.append(np.column_stack([np.full(ok.sum(), path.section), path.points[ok]]))
    xyz, snr = np.vstack(xyz), np.concatenate(snr)
    dist = nominal.signed_distance(xyz)
    result = RegistrationResult(
        measured_to_cad=np.eye(4), points_cad=xyz, deviation=dist.distance,
        inlier=np.ones(len(xyz), bool), closest=dist.closest, normal=dist.normal,
        face=dist.face, snr=snr, columns={}, n_rows_skipped=0, rms_mm=0.0,
        pose_covariance=np.zeros((6, 6)), center=xyz.mean(axis=0), pose_uncertainty_mm=0.0,
        deviation_stats=stats.deviation_statistics(dist.distance), coarse={})
    return result, np.vstack(planned)


def suction_bump_at(nominal, height_pct, radius_mm, height_mm):
    """(span axis, a rig.simulated bump) centred on the suction side where the plane at
    ``height_pct`` of the span crosses it, halfway along the chord."""
    from BladeInspect.inspection.sections import span_axis_of
    from BladeInspect.rig.simulated import make_bump
    axis, (lo, hi) = span_axis_of(nominal)
    s = nominal.samples
    level = lo + (hi - lo) * height_pct / 100.0
    near = np.isin(s.face, nominal.roles["suction"]) & (np.abs(s.xyz @ axis - level) < 0.5)
    pts = s.xyz[near]
    centre = pts[np.argmin(np.linalg.norm(pts - pts.mean(axis=0), axis=1))]
    return axis, make_bump(centre, radius_mm, height_mm)


def cli_process(wrapper_pid):
    """The pid of the CLI's Python process that the ``./bladeinspect`` wrapper ``wrapper_pid``
    runs as its child (None while it has not started)."""
    try:
        with open("/proc/%d/task/%d/children" % (wrapper_pid, wrapper_pid)) as fh:
            children = [int(pid) for pid in fh.read().split()]
    except OSError:
        return None
    for pid in children:
        try:
            with open("/proc/%d/cmdline" % pid, "rb") as fh:
                if b"BladeInspect.cli" in fh.read():
                    return pid
        except OSError:
            continue
    return None


def process_state(pid):
    """The kernel's one-letter state of ``pid`` ('T' stopped, 'Z' dead but not reaped), or
    None once it is gone."""
    try:
        with open("/proc/%d/stat" % pid) as fh:
            return fh.read().rsplit(")", 1)[1].split()[0]
    except (OSError, IndexError):
        return None
