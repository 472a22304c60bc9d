"""BladeInspect's headless command line (docs/contracts.md "Command line").

Run as ``./bladeinspect <command> ...`` from the repository, or inside FreeCADCmd::

    freecadcmd -c "import sys; sys.path.insert(0, '/path/to/BladeInspect');
                   from BladeInspect import cli; sys.exit(cli.main(['demo']))"

Bad input ends with one line ``bladeinspect: error: <file>: <problem>`` and exit status 2.
"""

import argparse
import faulthandler
import json
import os
import signal
import sys
import time

import numpy as np

from .core import contracts
from .core.blas_threads import limit_blas_threads
from .core.errors import Cancelled, DeviceError, InputError

EXIT_BAD_INPUT = 2
# Each command imports its pipeline where it runs: FreeCAD, scipy and matplotlib load only for
# a command that uses them, so --help and a bad argument answer at once.


class Progress:
    """Prints a stage's progress to stderr, at most a few lines a second."""

    def __init__(self, stream=None):
        self.stream = stream or sys.stderr
        self.last = 0.0
        self.last_message = None

    def __call__(self, fraction, message):
        now = time.monotonic()
        if message == self.last_message and now - self.last < 0.5:
            return
        self.last, self.last_message = now, message
        self.stream.write("[%3d%%] %s\n" % (round(100 * max(0.0, min(1.0, fraction))), message))
        self.stream.flush()


def _document_writer():
    """The writer of inspection.FCStd that the pipeline functions take (app/ sits above
    them), by name: it loads FreeCAD, which --help and a bad argument do not need, and a batch
    hands it to worker processes (Dask's among them) that start FreeCAD only when it runs."""
    from .freecad_library import FreeCADFunction
    return FreeCADFunction("BladeInspect.app.document", "write_inspection_document")


def _seed(value):
    return int(value)


def _heights(text):
    try:
        return contracts.parse_section_heights(text, "section heights", allow_empty=True)
    except InputError as exc:
        raise argparse.ArgumentTypeError(str(exc))


def _face_indices(text):
    try:
        values = [int(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError("expected comma-separated face indices, got %r" % text)
    if not values or min(values) < 0:
        raise argparse.ArgumentTypeError("expected face indices 0, 1, ..., got %r" % text)
    return values


FLIP_FACE_HELP = ("CAD faces (indices, as result.json's cad_faces lists them) whose outward "
                  "side is reversed: for open faces whose side the tool could not decide")


class Parser(argparse.ArgumentParser):
    """argparse that ends with exit status 2 and one line, as every other bad input does."""

    def error(self, message):
        raise InputError(message)


ALLOW_MISMATCH_HELP = ("write the result even when the scan does not fit the CAD (fewer than "
                       "half of its points within the tolerance plus the sensor's accuracy of "
                       "the surface), with the warning in result.json")


def fitting_args(parser):
    from .inspection.fitting import add_arguments
    add_arguments(parser)


def _fit_choice(args):
    from .inspection.fitting import from_args
    return from_args(args)


def build_parser():
    p = Parser(prog="bladeinspect", description="Register turbine blade scans to their CAD "
               "and report the deviations.")
    sub = p.add_subparsers(dest="command", metavar="COMMAND", parser_class=Parser)
    sub.required = True

    d = sub.add_parser("demo", help="built-in blade, simulated measurement, full pipeline")
    d.add_argument("--out", default="demo-out", help="output folder (default: demo-out)")
    d.add_argument("--seed", type=_seed, default=0)

    r = sub.add_parser("register", help="register a point file to a CAD")
    r.add_argument("--cad", required=True)
    r.add_argument("--points", required=True)
    r.add_argument("--out", required=True)
    r.add_argument("--seed", type=_seed, default=0)
    r.add_argument("--flip-face", type=_face_indices, default=[], help=FLIP_FACE_HELP)
    r.add_argument("--allow-mismatch", action="store_true", help=ALLOW_MISMATCH_HELP)
    r.add_argument("--tolerance", type=float, default=0.04,
                   help="profile tolerance +-T mm (the fit check and --fit tolerance)")
    fitting_args(r)

    s = sub.add_parser("simulate", help="the paper's simulation test bed (4.1)")
    s.add_argument("--cad", default=None, help="CAD file (default: the built-in demo blade)")
    s.add_argument("--out", required=True)
    s.add_argument("--seed", type=_seed, default=0)
    s.add_argument("--points", type=int, default=20000, help="surface points (default 20000)")
    s.add_argument("--sides", default="both", choices=("both", "suction", "pressure"))
    s.add_argument("--noise", default="uniform", choices=("uniform", "normal"))
    s.add_argument("--amplitude", type=float, default=0.006,
                   help="uniform error half-width in mm (default 0.006)")
    s.add_argument("--sigma", type=float, default=0.002,
                   help="normal error sigma in mm, clipped at 3 sigma (default 0.002)")
    s.add_argument("--outliers", type=float, default=0.0,
                   help="fraction of gross outliers, 0.1-0.5 mm at low SNR (default 0)")
    sc = sub.add_parser("scan", help="scan a blade with the simulated or a serial rig")
    sc.add_argument("--cad", default=None, help="part on the simulated rig (default: demo blade)")
    sc.add_argument("--out", required=True)
    sc.add_argument("--rig", default="sim", help="sim or serial:PORT (default sim)")
    sc.add_argument("--sections", type=int, default=5)
    sc.add_argument("--seed", type=_seed, default=0)
    sc.add_argument("--rig-file", default=None, help="RIG.json from calibrate")
    sc.add_argument("--resume", action="store_true",
                    help="continue an interrupted scan in DIR from its last complete section")

    sr = sub.add_parser("simrig", help="serve the simulated rig on a pseudo-terminal")
    sr.add_argument("--cad", default=None)
    sr.add_argument("--seed", type=_seed, default=0)

    rp = sub.add_parser("report", help="register and write the inspection report")
    rp.add_argument("--cad", required=True)
    rp.add_argument("--points", required=True)
    rp.add_argument("--out", required=True)
    rp.add_argument("--cmm", default=None, help="CMM points x,y,z[,section] in the CAD frame")
    rp.add_argument("--tolerance", type=float, default=contracts.PROFILE_TOLERANCE_MM,
                    help="profile tolerance +-T mm")
    rp.add_argument("--section-heights", type=_heights, default=None,
                    help="section planes in %% of span (default 10,30,50,70,90)")
    rp.add_argument("--seed", type=_seed, default=0)
    rp.add_argument("--flip-face", type=_face_indices, default=[], help=FLIP_FACE_HELP)
    rp.add_argument("--allow-mismatch", action="store_true", help=ALLOW_MISMATCH_HELP)
    rp.add_argument("--rig-file", default=None,
                    help="RIG.json whose calibration uncertainty enters U")
    fitting_args(rp)

    b = sub.add_parser("batch", help="inspect every point file of a production lot")
    b.add_argument("--cad", required=True)
    b.add_argument("--scans", required=True)
    b.add_argument("--out", required=True)
    b.add_argument("--tolerance", type=float, default=contracts.PROFILE_TOLERANCE_MM)
    b.add_argument("--workers", type=int, default=None, help="processes (default: all cores)")
    b.add_argument("--scheduler", default=None, help="Dask scheduler tcp://HOST:PORT")
    b.add_argument("--allow-mismatch", action="store_true", help=ALLOW_MISMATCH_HELP)
    b.add_argument("--rig-file", default=None,
                   help="RIG.json whose calibration uncertainty enters every blade's U")
    fitting_args(b)

    i = sub.add_parser("inspect", help="blind scan, register, CAD-planned scan, report")
    i.add_argument("--cad", default=None)
    i.add_argument("--out", required=True)
    i.add_argument("--rig", default="sim")
    i.add_argument("--rig-file", default=None)
    i.add_argument("--section-heights", type=_heights,
                   default=list(contracts.SECTION_HEIGHTS_PCT))
    i.add_argument("--complete", action="store_true")
    i.add_argument("--pitch", type=float, default=0.1)
    i.add_argument("--cmm", default=None)
    i.add_argument("--tolerance", type=float, default=contracts.PROFILE_TOLERANCE_MM)
    i.add_argument("--seed", type=_seed, default=0)
    i.add_argument("--resume", action="store_true",
                   help="continue an inspection in DIR interrupted by a rig failure, from its "
                        "last complete section (same CAD, seed and options)")
    i.add_argument("--flip-face", type=_face_indices, default=[], help=FLIP_FACE_HELP)
    i.add_argument("--allow-mismatch", action="store_true", help=ALLOW_MISMATCH_HELP)
    i.add_argument("--edge-radius-sigma", default=None, metavar="MM",
                   help="plan points round each section's LE and TE so closely that the fitted "
                        "edge radius's 1-sigma at the sensor's noise is at most MM (default "
                        "0.002; 0 or off: the rule off, points every 0.1 mm; "
                        "docs/user-guide.md)")
    fitting_args(i)

    a = sub.add_parser("airfoil", help="airfoil characteristics per section (nominal, or "
                       "measured against nominal with --points)")
    a.add_argument("--cad", default=None, help="CAD file (default: the built-in demo blade)")
    a.add_argument("--points", default=None,
                   help="measured points in any frame (registered first, as `register`)")
    a.add_argument("--out", required=True)
    a.add_argument("--section-heights", type=_heights, default=None,
                   help="section planes in %% of span (default 10,30,50,70,90)")
    a.add_argument("--seed", type=_seed, default=0)
    _airfoil_arguments(a, always=True)
    fitting_args(a)
    for parser in (rp, i, b):
        _airfoil_arguments(parser, always=False)

    c = sub.add_parser("calibrate", help="find the rotary axis from a reference sphere")
    c.add_argument("--out", required=True, help="RIG.json to write")
    c.add_argument("--rig", default="sim")
    c.add_argument("--rig-file", default=None, help="kinematics believed so far")
    c.add_argument("--sphere-diameter", type=float, default=25.0)
    c.add_argument("--seed", type=_seed, default=0)
    c.add_argument("--sim-axis-offset", type=float, default=0.2,
                   help="simulated rig only: injected axis offset in mm (default 0.2)")
    c.add_argument("--sim-axis-tilt", type=float, default=0.1,
                   help="simulated rig only: injected axis tilt in degrees (default 0.1)")
    return p


def _print_result(result, out_dir, stream=None):
    stream = stream or sys.stdout   # looked up at the call, so a redirected stdout gets it
    from .inspection.result import rival_lines
    stats = result.deviation_stats
    stream.write("registered %d points (%d inliers, %d rows skipped)\n"
                 % (result.n_points, result.n_inliers, result.n_rows_skipped))
    stream.write("  residual RMS %.4f mm, deviations %.4f .. %.4f mm\n"
                 % (result.rms_mm, stats["min"], stats["max"]))
    unmeasured = getattr(result, "pose_unmeasured", None) or []
    stream.write("  pose uncertainty (1 sigma, worst bounding-box corner) %.2f um%s%s\n"
                 % (result.pose_uncertainty_mm * 1000.0,
                    " in the measured directions" if unmeasured else "",
                    " - raised to cover the rival pose (statistical bound %.2f um)"
                    % (result.pose_uncertainty_statistical_mm * 1000.0)
                    if result.pose_uncertainty_includes_rival else ""))
    for direction in unmeasured:
        stream.write("  %s\n" % direction["motion"])
    for warning in result.warnings:
        stream.write("  warning: %s\n" % warning)
    if result.coarse.get("warning") and result.coarse["warning"] not in result.warnings:
        stream.write("  warning: %s\n" % result.coarse["warning"])
    for line in rival_lines(result.coarse):
        stream.write("  %s\n" % line)
    stream.write("  timing: %s\n" % ", ".join("%s %.2f s" % kv for kv in result.timing_s.items()))
    stream.write("results in %s\n" % os.path.abspath(out_dir))


def cmd_register(args):
    from .inspection.pipeline import run_register
    result = run_register(args.cad, args.points, args.out, _run_options(args),
                          progress=Progress())
    _print_result(result, args.out)


def cmd_simulate(args, cad=None):
    from .inspection.pipeline import load_nominal
    from .inspection.simulate import run_simulation, write_simulation
    nominal = load_nominal(args.cad if cad is None else cad)
    result, report, pointset = run_simulation(
        nominal, seed=args.seed, progress=Progress(), n_points=args.points, sides=args.sides,
        noise=args.noise, amplitude=args.amplitude, sigma=args.sigma,
        outlier_fraction=args.outliers)
    result.cad_source = args.cad or "built-in demo blade"
    write_simulation(args.out, result, report, pointset)
    _print_result(result, args.out)
    sys.stdout.write(
        "simulation: pose error %.3f um = %.2f x its bound; residual RMS %.4f mm "
        "(injected %.4f), min %.4f, max %.4f mm (paper: RMS 0.0019, min -0.0053, max 0.006)\n"
        % (report["pose_error_mm"] * 1000, report["pose_error_over_bound"],
           report["residual_rms_mm"], report["noise_rms_injected_mm"],
           report["residual_min_mm"], report["residual_max_mm"]))
    return result, report


def cmd_demo(args):
    """The paper's whole workflow on the built-in blade and the simulated rig: blind section
    scan, reconstruction, PCA, SNR-weighted ICP, CAD-planned scan of the nominal sections,
    report with the airfoil characteristics (as `inspect` makes by default); then the pose
    judged against the simulator's truth."""
    from .inspection.airfoil_stage import options_from_args
    from .inspection.closed_loop import run_inspect
    from .inspection.run_options import RunOptions
    summary = run_inspect(None, args.out, RunOptions(seed=args.seed, airfoil=options_from_args()),
                          progress=Progress(), document=_document_writer())
    result = summary["result"]
    _print_result(result, args.out)
    sys.stdout.write("verdict: %s\n" % summary["verdict"]["summary"])
    with open(os.path.join(args.out, "scan.json")) as fh:
        truth = json.load(fh).get("table_to_cad")
    if truth is not None:
        from .core import transforms as tf
        from .cad.load import load_nominal
        corners = load_nominal(None).bbox_corners
        delta = np.asarray(result.measured_to_cad) @ tf.invert_transform(np.asarray(truth))
        err = tf.corner_displacement(delta, np.eye(4), corners)
        sys.stdout.write("pose against the simulator's truth: %.2f um = %.2f x its 1-sigma "
                         "bound\n" % (1e3 * err, err / result.pose_uncertainty_mm))


def cmd_scan(args):
    from .inspection.pipeline import load_nominal
    from .rig.kinematics import RigKinematics
    from .measurement.scan import open_rig, scan_to_dir
    kinematics = RigKinematics.from_json(args.rig_file) if args.rig_file else None
    nominal = load_nominal(args.cad) if args.rig == "sim" else None
    rig = open_rig(args.rig, nominal=nominal, seed=args.seed, kinematics=kinematics)
    try:
        summary = scan_to_dir(args.out, rig, n_sections=args.sections, seed=args.seed,
                              resume=args.resume, progress=Progress(), kinematics=kinematics)
    finally:
        rig.close()
    sys.stdout.write("scanned %d sections, %d points; simulated %.1f s, real rig about %.1f s\n"
                     "results in %s\n" % (len(summary["sections"]), summary["points"],
                                           summary["simulated_s"], summary["real_time_s"],
                                           os.path.abspath(args.out)))


def cmd_simrig(args):
    from .rig.simrig_device import run_simrig
    from .inspection.pipeline import load_nominal
    run_simrig(load_nominal(args.cad), seed=args.seed)


def _airfoil_arguments(parser, always):
    # report, inspect and batch add the airfoil characteristics unless --no-airfoil
    # (result.json always gains `airfoil`); --airfoil, the former switch, is kept and a no-op.
    if not always:
        parser.add_argument("--airfoil", action="store_true",
                            help="add the airfoil characteristics per section (the default)")
        parser.add_argument("--no-airfoil", action="store_true",
                            help="leave out the airfoil characteristics")
    parser.add_argument("--engine-axis", default=None,
                        help="engine axis: x, y, z, -x, ... or \"1,0,0\" (default the CAD's +X)")
    parser.add_argument("--characteristics", default=None, metavar="FILE",
                        help="tolerances: CSV characteristic,section,lower,upper[,nominal]")
    parser.add_argument("--chord-method", default=None,
                        choices=("nose-tail", "caliper", "tangent"),
                        help="chord definition (default nose-tail)")
    parser.add_argument("--edge-offsets", default=None, metavar="MM,MM,...",
                        help="edge thickness offsets from the LE/TE points (default 0.5,1,2)")
    parser.add_argument("--le-rule", default=None, choices=("engine-axis", "larger-radius"),
                        help="which end is the LE when the CAD does not name it: the upstream "
                             "end along the engine axis (default; the flow runs along +axis) "
                             "or the larger edge radius")
    parser.add_argument("--uncertainty-task", default=None, metavar="FILE",
                        help="task-specific uncertainty: reuse the re-fit draws stored in FILE "
                             "for the sections whose measurement matches the task's "
                             "conditions; FILE absent: make it from this blade (48 draws a "
                             "section; docs/user-guide.md)")


def _airfoil_options(args):
    """inspection.airfoil_stage.Options from the command's arguments; None with --no-airfoil."""
    given = [args.engine_axis, args.characteristics, args.chord_method, args.edge_offsets,
             args.le_rule, args.uncertainty_task]
    if getattr(args, "no_airfoil", False):
        if any(v is not None for v in given) or args.airfoil:
            raise InputError("--no-airfoil: cannot be given with --airfoil or the airfoil "
                             "options (--engine-axis, --characteristics, --chord-method, "
                             "--edge-offsets, --le-rule, --uncertainty-task)")
        return None
    from .inspection.airfoil_stage import options_from_args
    return options_from_args(*given)


def cmd_airfoil(args):
    import dataclasses
    from .inspection.airfoil_stage import run_airfoil
    opts = _airfoil_options(args)
    choice = _fit_choice(args)
    if args.points is None and not (choice.is_icp and choice.weights is None):
        raise InputError("--fit, --free, --weights-by-zone and --weights: for the measured "
                         "points (--points) only")
    # the fit's named directions (t_engine, r_engine) and the verdicts follow the airfoil's
    choice = dataclasses.replace(choice, engine_axis=tuple(opts.engine_axis))
    opts = dataclasses.replace(opts, decision_rule=choice.decision_rule, fit_choice=choice)
    summary = run_airfoil(args.cad, args.out, points_path=args.points,
                          heights_pct=args.section_heights, opts=opts,
                          seed=args.seed, progress=Progress())
    sys.stdout.write("airfoil: %d sections -> %s\n%s\n"
                     % (len(summary["stage"].blocks), args.out,
                        summary["stage"].verdict["summary"]))
    size = (summary["doc"].get("fit") or {}).get("size_deviation")
    if size:
        sys.stdout.write("size deviation %+.4f mm, U (k=%g) %s\n" % (
            size["value_mm"], size["k"],
            "not determined" if size["U_mm"] is None else "%.4f mm" % size["U_mm"]))


def cmd_report(args, cad=None, points=None):
    from .inspection.report import run_report
    summary = run_report(args.cad, args.points, args.out, _run_options(args),
                         progress=Progress(), document=_document_writer())
    _print_result(summary["result"], args.out)
    sys.stdout.write("verdict: %s\n" % summary["verdict"]["summary"])


def _model(args):
    from .inspection.uncertainty import model_from_rig_file
    return model_from_rig_file(args.rig_file)


def cmd_batch(args):
    from .inspection.batch import run_batch
    summary = run_batch(args.cad, args.scans, args.out, _run_options(args),
                        workers=args.workers, scheduler=args.scheduler, progress=Progress(),
                        document=_document_writer())
    sys.stdout.write("%s\n" % summary["message"])


def cmd_inspect(args):
    from .inspection.closed_loop import run_inspect
    summary = run_inspect(args.cad, args.out, _run_options(args, loop=_loop_options(args)),
                          progress=Progress(), document=_document_writer())
    _print_result(summary["result"], args.out)
    sys.stdout.write("verdict: %s\n" % summary["verdict"]["summary"])


def _run_options(args, loop=None):
    """inspection.run_options.RunOptions from a command's parsed arguments: the options the
    command has, the others at their defaults. ``loop``: the `inspect` loop's (LoopOptions).
    The airfoil options, the fit and the measurement model are made in that order, so that a
    bad one is reported as before."""
    from .inspection.run_options import LoopOptions, RunOptions
    given = {"loop": loop or LoopOptions()}
    for name, flag in (("seed", "seed"), ("tolerance", "tolerance"), ("cmm", "cmm"),
                       ("flip_faces", "flip_face"), ("allow_mismatch", "allow_mismatch"),
                       ("rig_file", "rig_file")):
        if hasattr(args, flag):
            given[name] = getattr(args, flag)
    # `report` with no (or empty) --section-heights takes the default heights; `inspect`'s
    # are checked as given.
    if loop is not None or getattr(args, "section_heights", None):
        given["section_heights"] = args.section_heights
    if hasattr(args, "no_airfoil"):
        given["airfoil"] = _airfoil_options(args)
    if hasattr(args, "fit"):
        given["fit_choice"] = _fit_choice(args)
    if hasattr(args, "rig_file"):
        given["measurement_model"] = _model(args)
    return RunOptions(**given)


def _loop_options(args):
    """The `inspect` loop's options (inspection.run_options.LoopOptions) from its arguments;
    --edge-radius-sigma absent: the default target."""
    from .inspection.run_options import LoopOptions
    edge_rule = {}
    if args.edge_radius_sigma is not None:
        edge_rule["edge_radius_sigma_mm"] = args.edge_radius_sigma
    return LoopOptions(rig_spec=args.rig, complete=args.complete, pitch=args.pitch,
                       resume=args.resume, **edge_rule)


def cmd_calibrate(args):
    from .measurement.calibration import run_calibration
    errors = {}
    if args.rig == "sim":
        errors = {"axis_offset_mm": args.sim_axis_offset, "axis_tilt_deg": args.sim_axis_tilt}
    result = run_calibration(args.out, rig_spec=args.rig, sphere_diameter=args.sphere_diameter,
                             seed=args.seed, rig_file=args.rig_file, progress=Progress(),
                             **errors)
    out = sys.stdout
    out.write("rotary axis through (%.4f, %.4f, %.4f) mm, direction (%.7f, %.7f, %.7f)\n"
              % (tuple(result["axis_point"]) + tuple(result["axis_direction"])))
    out.write("  tilt from +Y: %.4f deg about Z, %.4f deg about X; sphere measured %.4f mm "
              "(nominal %.4f); circle residual RMS %.4f mm\n"
              % (result["axis_tilt_about_z_deg"], result["axis_tilt_about_x_deg"],
                 result["measured_diameter_mm"], result["sphere_diameter_mm"],
                 result["circle_residual_rms_mm"]))
    out.write("  calibration uncertainty (1 sigma at the part, written to RIG.json): %.2f um\n"
              % (1e3 * result["calibration_uncertainty_mm"]))
    error = result.get("truth_error")
    if error:
        out.write("  against the simulator's truth: position %.2f um, direction %.5f deg\n"
                  % (1e3 * error["position_mm"], error["direction_deg"]))
    out.write("rig calibration written to %s\n" % os.path.abspath(args.out))


COMMANDS = {"demo": cmd_demo, "register": cmd_register, "simulate": cmd_simulate,
            "scan": cmd_scan, "simrig": cmd_simrig, "report": cmd_report, "batch": cmd_batch,
            "inspect": cmd_inspect, "calibrate": cmd_calibrate, "airfoil": cmd_airfoil}


# Commands whose --out is a folder (calibrate's is the RIG.json file itself).
OUT_FOLDER_COMMANDS = ("demo", "register", "simulate", "scan", "report", "batch", "inspect",
                       "airfoil")


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    limit_blas_threads()
    try:
        args = build_parser().parse_args(argv)
        if args.command in OUT_FOLDER_COMMANDS:
            from .inspection.checks import check_out_dir
            check_out_dir(args.out)
        COMMANDS[args.command](args)
    except (InputError, DeviceError) as exc:
        sys.stderr.write("bladeinspect: error: %s\n" % exc)
        return EXIT_BAD_INPUT
    except Cancelled:
        sys.stderr.write("bladeinspect: cancelled\n")
        return 130
    except KeyboardInterrupt:
        sys.stderr.write("bladeinspect: interrupted\n")
        return 130
    return 0


def run_program():
    """The entry of ``./bladeinspect``: FreeCAD started as a library (freecad_library), then
    main(). The wrapper passes BLADEINSPECT_STATUS_FILE, where this records the command and
    the versions when it starts and its exit status when main() returns: a process that dies
    without the second line crashed, and the wrapper says so instead of ending silently."""
    status_file = os.environ.get("BLADEINSPECT_STATUS_FILE")
    _die_with_wrapper(os.environ.get("BLADEINSPECT_WRAPPER_PID"))
    _record_status(status_file, "pid %d" % os.getpid())
    try:
        from . import freecad_library
        versions = freecad_library.versions()
    except ImportError as exc:
        sys.stderr.write("bladeinspect: error: %s\n" % exc)
        _record_status(status_file, "finished 1")
        return 1
    # Enabled after FreeCAD installed its own signal handlers, so a fatal signal writes the
    # Python stack before FreeCAD's handler ends the process: into the wrapper's log, where the
    # one line the wrapper prints points, rather than a screenful on the terminal.
    crash_log = os.environ.get("BLADEINSPECT_CRASH_LOG")
    faulthandler.enable(file=open(crash_log, "a") if crash_log else sys.stderr)
    command = next((a for a in sys.argv[1:] if not a.startswith("-")), "")
    _record_status(status_file, "started %s\tFreeCAD %s, Python %s"
                   % (command, versions["freecad"], versions["python"]))
    try:
        code = main()
    except SystemExit as stop:   # argparse's --help (0) and usage errors (2) end here
        code = stop.code if isinstance(stop.code, int) else (0 if stop.code is None else 1)
        if not isinstance(stop.code, (int, type(None))):
            sys.stderr.write("%s\n" % stop.code)
    _record_status(status_file, "finished %d" % code)
    return code


def _die_with_wrapper(wrapper_pid):
    """The wrapper runs this process as its child (to report a crash), so a kill of the
    wrapper, even SIGKILL, must end this process too, as it would if the wrapper had exec'd
    it: the kernel sends SIGKILL here when the parent dies (Linux prctl PR_SET_PDEATHSIG). And
    a child started in the background by a shell begins with SIGINT ignored: Ctrl-C must
    still raise KeyboardInterrupt, which keeps a checkpoint."""
    signal.signal(signal.SIGINT, signal.default_int_handler)
    if not wrapper_pid:
        return
    try:
        import ctypes
        PR_SET_PDEATHSIG = 1
        ctypes.CDLL(None, use_errno=True).prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL))
    except (OSError, AttributeError):   # not Linux: the wrapper's traps still forward signals
        return
    if os.getppid() != int(wrapper_pid):   # the wrapper died before the request was made
        os._exit(128 + int(signal.SIGKILL))


def _record_status(path, line):
    if path:
        with open(path, "a") as fh:
            fh.write(line + "\n")


if __name__ == "__main__":
    sys.exit(run_program())
