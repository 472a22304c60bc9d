"""Shared test helpers: paths to the shared real-blade data, temporary folders."""
import os

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.normpath(os.path.join(REPO, "..", "shared"))
ROTOR67_DIR = os.path.join(SHARED, "data", "blades", "nasa_rotor67")
ROTOR67_SECTIONS = os.path.join(ROTOR67_DIR, "rotor67geometry.dat")
ROTOR67_CLOUD = os.path.join(ROTOR67_DIR, "MoveSurface_NASA_R67_parablade.txt")


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
    cmd = ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", "freecad", macro]
    with open(os.path.join(out_dir, "freecad.log"), "w") as log:
        subprocess.run(cmd, env=env, stdout=log, stderr=subprocess.STDOUT, timeout=timeout_s,
                       cwd=out_dir)
