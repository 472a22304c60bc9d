"""core.blas_threads: after the limit, every OpenBLAS this process has loaded runs one thread
(read back through the library's own getter, found independently in /proc/self/maps)."""
import ctypes
import os
import unittest

import numpy as np

from BladeInspect.core.blas_threads import limit_blas_threads


def loaded_openblas_getters():
    with open("/proc/self/maps") as maps:
        paths = sorted({line.split()[-1] for line in maps if ".so" in line})
    getters = {}
    for path in paths:
        if not path.startswith("/"):
            continue
        try:
            getters[path] = ctypes.CDLL(path).openblas_get_num_threads
        except (OSError, AttributeError):
            pass
    return getters


class TestBlasThreads(unittest.TestCase):

    def test_every_loaded_openblas_runs_one_thread(self):
        limited = limit_blas_threads()
        np.dot(np.ones((300, 300)), np.ones((300, 300)))   # BLAS is loaded and has run
        chosen = os.environ.get("OPENBLAS_NUM_THREADS")
        getters = loaded_openblas_getters()
        for path, getter in getters.items():
            getter.restype = ctypes.c_int
            self.assertEqual(getter(), int(chosen) if chosen else 1, path)
        # Some library was set exactly when an OpenBLAS is loaded (and the user chose nothing).
        self.assertEqual(bool(limited), bool(getters) and not chosen)

    def test_once_per_process(self):
        self.assertIs(limit_blas_threads(), limit_blas_threads())


if __name__ == "__main__":
    unittest.main()
