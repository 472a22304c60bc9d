"""core.atomic_file: a file replaced all at once. The truth here is independent of the code: the
bytes the test itself chose, the old file's bytes read before the write, the folder's listing,
the permissions the umask gives, and a child process killed with SIGKILL at chosen points of a
write (after k chunks, between the write and the replace, at random moments)."""
import os
import random
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
import unittest
from unittest import mock

from BladeInspect.core import atomic_file
from BladeInspect.core.atomic_file import atomic_copy, atomic_write, stray_temps

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OLD = b"old file: line one\nline two\n" * 1000

# The child: writes CHUNKS chunks of CHUNK bytes of b"N" into argv[1] through atomic_write.
# With argv[2] == "step" it reports the temporary file open and each chunk written on stdout
# and waits for a line on stdin before going on (the parent decides exactly where it dies); with "free" it writes as fast as it can.
# Either way it then waits for a line before it exits, so that a kill never finds it gone.
CHILD = r"""
import sys
from BladeInspect.core.atomic_file import atomic_write
path, how, chunks, size = sys.argv[1], sys.argv[2], int(sys.argv[3]), int(sys.argv[4])
step = how == "step"
print("pid", flush=True)
with atomic_write(path, "wb") as fh:
    if step:
        print("open", flush=True)
        sys.stdin.readline()
    for i in range(chunks):
        fh.write(b"N" * size)
        if step:
            fh.flush()
            print("wrote", i + 1, flush=True)
            sys.stdin.readline()
print("replaced", flush=True)
sys.stdin.readline()
"""
CHUNKS, CHUNK = 16, 1 << 18          # the new file: 4 MiB of b"N"


def python():
    """A plain Python for the child (core needs no FreeCAD); FreeCAD's own if there is none."""
    return shutil.which("python3") or sys.executable


def umask():
    mask = os.umask(0)
    os.umask(mask)
    return mask


class AtomicWriteTest(unittest.TestCase):

    def setUp(self):
        self.tmp = tempfile.mkdtemp(prefix="bi-atomic-")
        self.addCleanup(shutil.rmtree, self.tmp, ignore_errors=True)
        self.path = os.path.join(self.tmp, "target.csv")

    def write_old(self):
        with open(self.path, "wb") as fh:
            fh.write(OLD)

    def read(self, path=None):
        with open(path or self.path, "rb") as fh:
            return fh.read()

    def listing(self):
        return sorted(os.listdir(self.tmp))

    # --- success: exactly the bytes, permissions as open() gives them ----------------------
    def test_success_writes_exactly_the_bytes(self):
        self.write_old()
        with atomic_write(self.path, newline="") as fh:
            fh.write("a,b\r\n1,2\n")
            fh.write("\u00e9")
        self.assertEqual(self.read(), b"a,b\r\n1,2\n" + "\u00e9".encode(fh.encoding))
        self.assertEqual(self.listing(), ["target.csv"])
        payload = bytes(range(256)) * 777
        with atomic_write(self.path, "wb") as fh:
            fh.write(payload)
        self.assertEqual(self.read(), payload)
        with atomic_write(self.path, encoding="utf-8") as fh:       # "\n" as os.linesep
            fh.write("x\ny")
        self.assertEqual(self.read(), ("x" + os.linesep + "y").encode())
        self.assertEqual(self.listing(), ["target.csv"])

    def test_permissions_as_a_plain_open(self):
        with atomic_write(self.path) as fh:
            fh.write("new")
        self.assertEqual(stat.S_IMODE(os.stat(self.path).st_mode), 0o666 & ~umask())
        os.chmod(self.path, 0o640)
        with atomic_write(self.path) as fh:
            fh.write("again")
        self.assertEqual(stat.S_IMODE(os.stat(self.path).st_mode), 0o640)
        self.assertEqual(self.read(), b"again")

    def test_symbolic_link_written_through(self):
        self.write_old()
        link = os.path.join(self.tmp, "link.csv")
        os.symlink(self.path, link)
        with atomic_write(link, "wb") as fh:
            fh.write(b"through")
        self.assertTrue(os.path.islink(link))
        self.assertEqual(self.read(), b"through")
        self.assertEqual(self.listing(), ["link.csv", "target.csv"])

    def test_file_and_folder_fsynced_before_and_after_the_replace(self):
        events = []
        real_fsync, real_replace = os.fsync, os.replace

        def fsync(fd):
            st = os.fstat(fd)
            events.append(("fsync-dir" if stat.S_ISDIR(st.st_mode) else "fsync-file",
                           st.st_ino, st.st_size))
            real_fsync(fd)

        def replace(src, dst):
            events.append(("replace", os.stat(src).st_ino, os.path.abspath(dst)))
            real_replace(src, dst)

        with mock.patch.object(os, "fsync", fsync), mock.patch.object(os, "replace", replace):
            with atomic_write(self.path, "wb") as fh:
                fh.write(b"12345")
        file_ino = os.stat(self.path).st_ino
        self.assertEqual(events, [("fsync-file", file_ino, 5),
                                  ("replace", file_ino, self.path),
                                  ("fsync-dir", os.stat(self.tmp).st_ino, mock.ANY)])

    # --- failure inside the block: the old file whole, no temporary -------------------------
    def test_exception_mid_write_keeps_the_old_file(self):
        self.write_old()
        for exc in (OSError("disk full"), ValueError("bad row"), KeyboardInterrupt()):
            with self.assertRaises(type(exc)) as caught:
                with atomic_write(self.path, "wb") as fh:
                    fh.write(b"N" * 100000)
                    fh.flush()
                    raise exc
            self.assertIs(caught.exception, exc)
            self.assertTrue(fh.closed)
            self.assertEqual(self.read(), OLD)
            self.assertEqual(self.listing(), ["target.csv"])

    def test_exception_without_an_old_file_leaves_nothing(self):
        with self.assertRaises(RuntimeError):
            with atomic_write(self.path) as fh:
                fh.write("half")
                raise RuntimeError("stop")
        self.assertEqual(self.listing(), [])

    def test_failed_replace_removes_the_temporary(self):
        self.write_old()

        def refuse(src, dst):
            raise PermissionError(13, "Permission denied", dst)

        with mock.patch.object(os, "replace", refuse):
            with self.assertRaises(PermissionError):
                with atomic_write(self.path, "wb") as fh:
                    fh.write(b"new")
        self.assertEqual(self.read(), OLD)
        self.assertEqual(self.listing(), ["target.csv"])

    def test_missing_folder_names_the_target(self):
        path = os.path.join(self.tmp, "no", "such.json")
        with self.assertRaises(FileNotFoundError) as caught:
            with atomic_write(path) as fh:
                fh.write("x")
        self.assertEqual(caught.exception.filename, path)
        self.assertIn("such.json", str(caught.exception))
        self.assertNotIn(".tmp", str(caught.exception))
        self.assertEqual(self.listing(), [])

    def test_not_a_write_mode(self):
        for mode in ("r", "a", "r+", "ab", "x"):
            with self.assertRaises(ValueError):
                with atomic_write(self.path, mode):
                    pass
        self.assertEqual(self.listing(), [])

    def test_closed_inside_the_block(self):
        with atomic_write(self.path, "wb") as fh:
            fh.write(b"closed early")
            fh.close()
        self.assertEqual(self.read(), b"closed early")
        self.assertEqual(self.listing(), ["target.csv"])

    # --- copy -------------------------------------------------------------------------------
    def test_copy(self):
        source = os.path.join(self.tmp, "source.bin")
        payload = os.urandom(3 << 20)
        with open(source, "wb") as fh:
            fh.write(payload)
        self.write_old()
        self.assertEqual(atomic_copy(source, self.path), self.path)
        self.assertEqual(self.read(), payload)
        with self.assertRaises(FileNotFoundError):
            atomic_copy(os.path.join(self.tmp, "missing"), self.path)
        self.assertEqual(self.read(), payload)
        self.assertEqual(self.listing(), ["source.bin", "target.csv"])

    # --- killed outright --------------------------------------------------------------------
    def child(self, how):
        proc = subprocess.Popen([python(), "-c", CHILD, self.path, how, str(CHUNKS), str(CHUNK)],
                                stdin=subprocess.PIPE, stdout=subprocess.PIPE, cwd=HERE,
                                env=dict(os.environ, PYTHONPATH=HERE))
        self.addCleanup(self.reap, proc)
        self.assertEqual(proc.stdout.readline(), b"pid\n")
        return proc

    @staticmethod
    def reap(proc):
        if proc.poll() is None:
            proc.kill()
        proc.wait(timeout=30)
        for f in (proc.stdin, proc.stdout):
            try:
                f.close()
            except OSError:
                pass

    def kill(self, proc):
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait(timeout=30)
        self.assertEqual(proc.returncode, -signal.SIGKILL)

    def test_killed_after_k_chunks_keeps_the_old_file(self):
        new = b"N" * (CHUNKS * CHUNK)
        for k in (0, 1, CHUNKS // 2, CHUNKS):
            self.write_old()
            for name in stray_temps(self.path, dead_only=False):
                os.remove(name)
            proc = self.child("step")
            self.assertEqual(proc.stdout.readline(), b"open\n")
            for i in range(k):
                proc.stdin.write(b"\n")
                proc.stdin.flush()
                self.assertEqual(proc.stdout.readline(), b"wrote %d\n" % (i + 1))
                self.assertEqual(self.read(), OLD)     # a reader meanwhile: the old file
            self.kill(proc)
            self.assertEqual(self.read(), OLD, "killed after %d chunks" % k)
            # The one temporary left is named after the target and the dead process.
            strays = stray_temps(self.path)
            self.assertEqual(len(strays), 1, self.listing())
            name = os.path.basename(strays[0])
            self.assertTrue(name.startswith(".target.csv.%d." % proc.pid), name)
            self.assertTrue(name.endswith(".tmp"), name)
            self.assertEqual(self.read(strays[0]), new[:k * CHUNK])
            self.assertEqual(sorted(set(self.listing()) - {name}), ["target.csv"])

    def test_killed_after_the_replace_keeps_the_new_file(self):
        self.write_old()
        proc = self.child("step")
        self.assertEqual(proc.stdout.readline(), b"open\n")
        for i in range(CHUNKS + 1):
            proc.stdin.write(b"\n")
            proc.stdin.flush()
            line = proc.stdout.readline()
        self.assertEqual(line, b"replaced\n")
        self.kill(proc)
        self.assertEqual(self.read(), b"N" * (CHUNKS * CHUNK))
        self.assertEqual(self.listing(), ["target.csv"])
        self.assertEqual(stray_temps(self.path, dead_only=False), [])

    def test_killed_at_random_moments_old_or_new_never_a_mix(self):
        new = b"N" * (CHUNKS * CHUNK)
        # how long one free write takes here, so that the kills spread over all of it
        self.write_old()
        proc = self.child("free")
        t0 = time.monotonic()
        self.assertEqual(proc.stdout.readline(), b"replaced\n")
        span = time.monotonic() - t0
        proc.stdin.write(b"\n")
        proc.stdin.flush()
        proc.wait(timeout=30)
        self.assertEqual(proc.returncode, 0)
        self.assertEqual(self.read(), new)
        rng = random.Random(5)
        outcomes = []
        for trial in range(12):
            self.write_old()
            proc = self.child("free")
            time.sleep(rng.uniform(0.0, 1.5 * span))
            self.kill(proc)     # the child waits at its end, so it is always there to kill
            got = self.read()
            self.assertIn(got, (OLD, new), "trial %d: %d bytes, a mix" % (trial, len(got)))
            outcomes.append(got == new)
            others = set(self.listing()) - {"target.csv"}
            self.assertEqual(others, {os.path.basename(p) for p in stray_temps(self.path)})
            self.assertLessEqual(len(others), 1)
            for name in others:
                os.remove(os.path.join(self.tmp, name))
        print("atomic_file: 12 kills over a %.3f s write: %d left the old file, %d the new"
              % (span, outcomes.count(False), outcomes.count(True)))

    def test_stray_temps_of_a_live_writer_are_not_listed(self):
        prefix = ".target.csv."
        mine = os.path.join(self.tmp, "%s%d.0123abcd.tmp" % (prefix, os.getpid()))
        done = subprocess.Popen([python(), "-c", "pass"])
        done.wait()
        dead = os.path.join(self.tmp, "%s%d.89abcdef.tmp" % (prefix, done.pid))
        other = os.path.join(self.tmp, ".other.csv.%d.89abcdef.tmp" % done.pid)
        for p in (mine, dead, other):
            open(p, "w").close()
        self.assertEqual(stray_temps(self.path), [dead])
        self.assertEqual(stray_temps(self.path, dead_only=False), sorted([mine, dead]))
        self.assertEqual(stray_temps(os.path.join(self.tmp, "none", "x")), [])


class ModuleRulesTest(unittest.TestCase):
    def test_standard_library_only(self):
        with open(atomic_file.__file__) as fh:
            text = fh.read()
        for name in ("FreeCAD", "Part", "numpy", "PySide"):
            self.assertNotIn("import %s" % name, text)


if __name__ == "__main__":
    unittest.main()
