"""One thread for the BLAS library numpy uses, set at run time.

The exact distance parallelises itself (core.closest: numpy's array loops on THREADS threads).
OpenBLAS's pthread build (Debian 12's default BLAS) adds threads of its own to the many tall,
narrow products of a registration ((N, 3) @ (3, 3), least squares on (N, 6)), which gain nothing
from them, and its idle threads spin for a while after each call, taking the cores the
distance threads want. Measured on the third-party STEP blade at 269,158 points on two cores
(``scripts/fcpython bench/bench_register_stages.py --only step --repeat 2``): alone, the
register takes the same wall time either way (4.0-4.6 s) but 5.3-5.9 CPU-s instead of
6.4-7.0; two registers at once (a batch beside another job) take 5.67-5.87 s each with one BLAS
thread, 5.80-6.40 s with OpenBLAS's default of one per core.

The library is found among those this process has loaded (/proc/self/maps), as threadpoolctl
does, so that the limit holds whoever imported numpy first (FreeCAD's GUI may have); an
OPENBLAS_NUM_THREADS the user set is left alone. Other BLAS builds (the reference BLAS of
Debian 13's default, single-threaded anyway) are not touched.
"""

import ctypes
import os

_done = None


def limit_blas_threads(threads=1):
    """Set every loaded OpenBLAS to ``threads`` threads, once per process; returns the paths
    of the libraries set (empty when there is none, or the user chose through
    OPENBLAS_NUM_THREADS)."""
    global _done
    if _done is not None:
        return _done
    _done = []
    if os.environ.get("OPENBLAS_NUM_THREADS"):
        return _done
    import numpy  # noqa: F401  (loads the BLAS library this is about)
    for path in _loaded_libraries():
        if "openblas" not in path.lower():
            continue
        try:
            lib = ctypes.CDLL(path)
            setter = lib.openblas_set_num_threads
        except (OSError, AttributeError):
            continue
        setter.argtypes = [ctypes.c_int]
        setter.restype = None
        setter(int(threads))
        _done.append(path)
    return _done


def _loaded_libraries():
    try:
        with open("/proc/self/maps") as maps:
            paths = {line.split()[-1] for line in maps if ".so" in line}
    except OSError:   # no /proc: not Linux; nothing is limited
        return []
    return sorted(p for p in paths if p.startswith("/"))
