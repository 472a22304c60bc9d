"""FreeCAD as a library in a plain Python process: the one way the CLI, the benchmarks and the
tests' subprocesses import it outside FreeCADCmd.

Inside FreeCAD or FreeCADCmd, FreeCAD is imported already and nothing is done. Elsewhere:

1. the folder holding FreeCAD's Python modules (``FreeCAD.so``) is found: ``$FREECAD_LIB`` when
   set, else next to the ``freecadcmd``/``FreeCADCmd`` on PATH (``<prefix>/bin/..`` → ``lib``:
   Debian's alternatives, AppImage and conda layouts), else the distributions' known folders;
2. FreeCAD is imported, and then asked (``getHomePath()``, ``getResourceDir()``) where its
   modules' Python folders are: each ``Mod/<Module>`` and ``Ext`` is put on ``sys.path`` as
   FreeCAD's own start-up does. FreeCAD 1.0 needs this: ``Part.makeCompound`` imports
   ``PartEnums`` from ``Mod/Part`` and, when that fails, crashes the process (a null object
   dereferenced, turned into a silent exit 1 by FreeCAD's signal handler).

FreeCAD's folders go after everything already on ``sys.path``, so no call site depends on the
order of hand-set paths, and a checkout ahead on the path is never shadowed by an installed
copy. The user's own Mod folder is left out for that reason too: a workbench linked there is
this project or another one, not a module the library needs.

``scripts/fcpython [SCRIPT | -c CODE | -m MODULE] [ARGS]`` runs Python code this way (the
benchmarks, the tests' subprocesses); with no arguments it prints what was found.
"""

import glob
import os
import shutil
import sys

# Folders where distributions put FreeCAD's Python modules, tried when no freecadcmd is on PATH.
KNOWN_LIBRARY_DIRS = (
    "/usr/lib/freecad-python3/lib",   # Debian, Ubuntu
    "/usr/lib/freecad/lib",           # Debian's alternatives link, Arch
    "/usr/lib64/freecad/lib64",       # Fedora
    "/usr/lib64/freecad/lib",
    "/usr/local/lib/freecad/lib",     # built from source
    "/opt/freecad/lib",
)
COMMAND_NAMES = ("freecadcmd", "FreeCADCmd", "freecadcmd-daily")


class FreeCADNotFound(ImportError):
    pass


def _holds_freecad(folder):
    return bool(folder) and (glob.glob(os.path.join(folder, "FreeCAD.so")) or
                             glob.glob(os.path.join(folder, "FreeCAD.*.so")) or
                             glob.glob(os.path.join(folder, "FreeCAD.pyd")))


def candidate_library_dirs():
    """Where FreeCAD's Python modules may be, in the order they are tried."""
    found = []
    if os.environ.get("FREECAD_LIB"):
        found.append(os.environ["FREECAD_LIB"])
    for name in COMMAND_NAMES:
        command = shutil.which(name)
        if command:
            prefix = os.path.dirname(os.path.dirname(os.path.realpath(command)))
            found += [os.path.join(prefix, "lib"), os.path.join(prefix, "lib64")]
    found += KNOWN_LIBRARY_DIRS
    unique = []
    for folder in found:
        real = os.path.realpath(folder)
        if real not in unique:
            unique.append(real)
    return unique


def find_library_dir():
    for folder in candidate_library_dirs():
        if _holds_freecad(folder):
            return folder
    raise FreeCADNotFound(
        "FreeCAD's Python library was not found (looked in %s); install FreeCAD (Debian: "
        "apt-get install freecad) or set FREECAD_LIB to the folder holding FreeCAD.so"
        % ", ".join(candidate_library_dirs()))


def module_dirs(freecad):
    """The folders FreeCAD's start-up puts on sys.path for its own modules: every
    Mod/<Module> under its home and resource folders, and their Ext folders."""
    dirs = []
    for base in (freecad.getHomePath(), freecad.getResourceDir()):
        if not base:
            continue
        for sub in sorted(glob.glob(os.path.join(base, "Mod", "*"))) + [os.path.join(base, "Ext")]:
            real = os.path.realpath(sub)
            if os.path.isdir(real) and real not in dirs:
                dirs.append(real)
    return dirs


def _append_path(folder):
    if folder not in sys.path and os.path.realpath(folder) not in map(os.path.realpath, sys.path):
        sys.path.append(folder)


def import_freecad():
    """FreeCAD's module, importable with its Part, Points and Mesh modules fully working."""
    if "FreeCAD" in sys.modules:
        freecad = sys.modules["FreeCAD"]
    else:
        _append_path(find_library_dir())
        import FreeCAD as freecad   # noqa: E402 -- found on the path just added
    for folder in module_dirs(freecad):
        _append_path(folder)
    return freecad


def versions():
    """{'freecad': '1.0.0', 'python': '3.13.5'} of this process (FreeCAD imported here)."""
    freecad = import_freecad()
    version = freecad.Version()
    return {"freecad": ".".join(v for v in version[:3] if v),
            "python": "%d.%d.%d" % sys.version_info[:3]}


class FreeCADFunction:
    """A function of a module that needs FreeCAD, named rather than held, so that it pickles
    to a process that has not started FreeCAD yet (a Dask worker, a spawned batch worker):
    calling it there starts FreeCAD (import_freecad) first, then imports the module."""

    def __init__(self, module, name):
        self.module, self.name = module, name

    def __call__(self, *args, **kwargs):
        import importlib
        import_freecad()
        return getattr(importlib.import_module(self.module), self.name)(*args, **kwargs)

    def __repr__(self):
        return "FreeCADFunction(%r, %r)" % (self.module, self.name)


def _run(argv):
    """``scripts/fcpython``: python3 with FreeCAD imported first. ARGV is ``SCRIPT [ARGS]``,
    ``-c CODE [ARGS]`` or ``-m MODULE [ARGS]``; with none, what was found is printed."""
    import runpy
    freecad = import_freecad()
    if not argv:
        print("library: %s" % os.path.dirname(os.path.realpath(freecad.__file__)))
        print("home: %s" % freecad.getHomePath())
        print("resources: %s" % freecad.getResourceDir())
        print("user modules: %s" % os.path.join(freecad.getUserAppDataDir(), "Mod"))
        print("versions: FreeCAD %(freecad)s, Python %(python)s" % versions())
    elif argv[0] == "-c" and len(argv) > 1:
        sys.argv = ["-c"] + argv[2:]
        exec(compile(argv[1], "<string>", "exec"), {"__name__": "__main__"})
    elif argv[0] == "-m" and len(argv) > 1:
        sys.argv = [argv[1]] + argv[2:]
        runpy.run_module(argv[1], run_name="__main__", alter_sys=True)
    else:
        sys.argv = list(argv)
        sys.path.insert(0, os.path.dirname(os.path.abspath(argv[0])))
        runpy.run_path(argv[0], run_name="__main__")


if __name__ == "__main__":
    _run(sys.argv[1:])
