"""The demo in the GUI against `./bladeinspect demo` (issue 6: no more than 20 % longer).

    scripts/fcpython bench/bench_gui_demo.py [--shots DIR]

Both run the same closed loop on the demo blade with the simulated rig, 5 nominal sections,
seed 0, report included; the GUI run is timed from a new document to the finished inspection,
the command line from its start (interpreter, imports) to its exit. --shots DIR: afterwards
the GUI also shows the Inspect panel, the inspection's tables, the registration, the deviation
map and writes the report, and the screenshots are copied into DIR (not timed)."""
import argparse
import glob
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, REPO)

from tests.helpers import run_freecad_gui  # noqa: E402


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--shots", default=None, help="folder for the GUI's screenshots")
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="bi-gui-bench-")
    try:
        t0 = time.time()
        subprocess.run([os.path.join(REPO, "bladeinspect"), "demo", "--out",
                        os.path.join(tmp, "cli")], check=True, capture_output=True)
        cli_s = time.time() - t0
        if args.shots:
            os.environ["BI_DEMO_SHOTS"] = "1"
        # The GUI as the GUI tests start it: a private HOME with the workbench installed.
        run_freecad_gui(os.path.join(REPO, "bench", "gui_demo_macro.py"), tmp, 600)
        with open(os.path.join(tmp, "gui_demo.json")) as fh:
            gui = json.load(fh)
        if "error" in gui:
            print(gui["error"])
            return 1
        print("./bladeinspect demo: %.1f s; GUI demo blade + Inspect: %.1f s; GUI/CLI = %.2f "
              "(required <= 1.20)" % (cli_s, gui["gui_demo_s"], gui["gui_demo_s"] / cli_s))
        if args.shots:
            os.makedirs(args.shots, exist_ok=True)
            for path in glob.glob(os.path.join(tmp, "*.png")):
                shutil.copy(path, args.shots)
            print("screenshots %s in %s; report files %s"
                  % (", ".join(gui.get("shots", [])), args.shots, gui.get("report_files")))
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
