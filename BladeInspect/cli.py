"""BladeInspect's headless command line (DESIGN.md "Contracts").

Run as ``./bladeinspect <command> ...`` from the repository, or inside FreeCADCmd::

    freecadcmd -c "import sys; sys.path.insert(0, '/path/to/BladeInspect');
                   from BladeInspect import cli; sys.exit(cli.main(['demo']))"

Bad input ends with one line ``bladeinspect: error: <file>: <problem>`` and exit status 2.
"""

import argparse
import json
import os
import sys
import time

import numpy as np

from .core.errors import Cancelled, DeviceError, InputError

EXIT_BAD_INPUT = 2


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


def _seed(value):
    return int(value)


def _heights(text):
    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise argparse.ArgumentTypeError("expected comma-separated percentages, got %r" % text)
    for v in values:
        if not 0.0 <= v <= 100.0:
            raise argparse.ArgumentTypeError("section height %g%% is outside 0-100" % v)
    return values


class Parser(argparse.ArgumentParser):
    """argparse that ends with exit status 2 and one line, as every other bad input does."""

    def error(self, message):
        raise InputError(message)


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
    return p


def _print_result(result, out_dir, stream=sys.stdout):
    stats = result.deviation_stats
    stream.write("registered %d points (%d inliers, %d rows skipped)\n"
                 % (result.n_points, result.n_inliers, result.n_rows_skipped))
    stream.write("  residual RMS %.4f mm, deviations %.4f .. %.4f mm\n"
                 % (result.rms_mm, stats["min"], stats["max"]))
    stream.write("  pose uncertainty (1 sigma, worst bounding-box corner) %.2f um\n"
                 % (result.pose_uncertainty_mm * 1000.0))
    if result.coarse.get("warning"):
        stream.write("  warning: %s\n" % result.coarse["warning"])
    stream.write("  timing: %s\n" % ", ".join("%s %.2f s" % kv for kv in result.timing_s.items()))
    stream.write("results in %s\n" % os.path.abspath(out_dir))


def cmd_register(args):
    from .inspect.pipeline import run_register
    result = run_register(args.cad, args.points, args.out, seed=args.seed, progress=Progress())
    _print_result(result, args.out)


def cmd_simulate(args, cad=None):
    from .inspect.pipeline import load_nominal
    from .inspect.simulate import run_simulation, write_simulation
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
    ns = argparse.Namespace(cad=None, out=args.out, seed=args.seed, points=20000, sides="both",
                            noise="uniform", amplitude=0.006, sigma=0.002, outliers=0.02)
    cmd_simulate(ns)


COMMANDS = {"demo": cmd_demo, "register": cmd_register, "simulate": cmd_simulate}


def main(argv=None):
    argv = sys.argv[1:] if argv is None else list(argv)
    try:
        args = build_parser().parse_args(argv)
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


if __name__ == "__main__":
    sys.exit(main())
