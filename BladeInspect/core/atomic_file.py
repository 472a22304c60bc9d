"""Replacing a file all at once: a reader, or a run resumed after a crash or a kill, finds the
old file or the new one, complete, never a mix, and an error leaves nothing half-written.

    with atomic_write(path, "w", newline="") as fh:
        fh.write(...)

writes a temporary file in the target's folder (so that the rename stays on one file system),
and only when the with-block ends without an exception: flushes it, fsyncs it, closes it,
``os.replace``s it over ``path`` and fsyncs the folder (where the platform allows: the rename
itself is then on disk too). On any exception (KeyboardInterrupt included) the temporary file
is closed and removed and the target is left untouched; the exception goes on unchanged.
``atomic_copy(source, target)`` is the same for a copy of a file.

Permissions are those a plain ``open(path, "w")`` gives: an existing target's mode is kept, a
new file gets 0o666 less the umask (tempfile.mkstemp would give 0o600).

A symbolic link at ``path`` is written through (the file it points to is replaced), as
``open`` would.

Temporary files are named ``.<name>.<pid>.<random>.tmp`` beside the target ``<name>``. After a
SIGKILL or a power cut in the middle of a write one may be left behind (nothing can remove it
then); the target itself is intact. ``stray_temps(path)`` lists those of a target, by default
only those whose writing process is no longer alive on this host (on Windows, where that
cannot be asked safely, none), so that a caller that knows no other writer is at work (e.g.
under its own lock) can delete them. Nothing removes them
automatically: a folder shared between hosts may hold the temporary file of a live writer
elsewhere, with a process id that means nothing here.

Standard library only (no FreeCAD, numpy not needed)."""
import contextlib
import errno
import os
import re
import secrets
import shutil
import stat

TEMP_SUFFIX = ".tmp"
_MAX_STEM = 180     # room for ".<pid>.<random>.tmp" within the usual 255-byte name limit
_TEXT_OR_BINARY = re.compile(r"^w[bt]?\+?$|^w\+[bt]$")


def _target(path):
    """The file actually replaced: a symbolic link is followed, as open() would."""
    path = os.fspath(path)
    return os.path.realpath(path) if os.path.islink(path) else os.path.abspath(path)


def _temp_prefix(target):
    return "." + os.path.basename(target)[:_MAX_STEM] + "."


def _open_temp(target):
    """A new temporary file beside ``target`` (O_EXCL: never someone else's): (fd, path)."""
    folder = os.path.dirname(target)
    prefix = _temp_prefix(target)
    try:
        mode = stat.S_IMODE(os.stat(target).st_mode)
    except FileNotFoundError:
        mode = None
    for _ in range(100):
        tmp = os.path.join(folder, "%s%d.%s%s" % (prefix, os.getpid(), secrets.token_hex(4),
                                                  TEMP_SUFFIX))
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0),
                         0o666)
        except FileExistsError:
            continue
        except OSError as exc:
            # Named as open(target) would name it: the user knows the target, not the temp.
            raise type(exc)(exc.errno, exc.strerror, target) from None
        if mode is not None:
            try:
                os.chmod(tmp, mode)
            except BaseException:
                os.close(fd)
                _remove(tmp)
                raise
        return fd, tmp
    raise FileExistsError(errno.EEXIST, "no free temporary file name beside it", target)


def _remove(path):
    try:
        os.unlink(path)
    except FileNotFoundError:
        pass


def fsync_folder(folder):
    """The folder's entries (a rename just made) on disk, where the platform allows it
    (not on Windows, nor on file systems that refuse to fsync a directory)."""
    try:
        fd = os.open(folder, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))
    except OSError:
        return
    try:
        os.fsync(fd)
    except OSError:
        pass
    finally:
        os.close(fd)


def _fsync_path(path):
    fd = os.open(path, os.O_RDONLY | getattr(os, "O_BINARY", 0))
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def atomic_write(path, mode="w", encoding=None, errors=None, newline=None):
    """A file object to write ``path`` anew, replacing it only when the with-block completes
    (see the module's text). ``mode``: "w" (text, the default) or "wb" (also "wt", "w+"...);
    ``encoding``, ``errors``, ``newline`` as for open()."""
    if not _TEXT_OR_BINARY.match(mode):
        raise ValueError("atomic_write: mode must be a write mode ('w', 'wb'...), got %r"
                         % (mode,))
    target = _target(path)
    fd, tmp = _open_temp(target)
    try:
        if "b" in mode:
            fh = os.fdopen(fd, mode)
        else:
            fh = os.fdopen(fd, mode, encoding=encoding, errors=errors, newline=newline)
    except BaseException:
        os.close(fd)
        _remove(tmp)
        raise
    try:
        with fh:
            yield fh
            closed_early = fh.closed
            if not closed_early:
                fh.flush()
                os.fsync(fh.fileno())
        if closed_early:    # closed inside the block: still to be made durable
            _fsync_path(tmp)
        os.replace(tmp, target)
    except BaseException:
        _remove(tmp)
        raise
    fsync_folder(os.path.dirname(target))


def atomic_copy(source, target):
    """Copy the file ``source`` to ``target`` all at once and on disk (as atomic_write).
    A missing or unreadable ``source`` raises before anything is created."""
    with open(source, "rb") as src:
        with atomic_write(target, "wb") as dst:
            shutil.copyfileobj(src, dst, 1 << 20)
    return target


def _alive(pid):
    if pid == os.getpid() or os.name == "nt":   # on Windows os.kill(pid, 0) would kill it
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except (PermissionError, OSError):
        return True         # someone else's process, or a platform that cannot tell: alive
    return True


def stray_temps(path, dead_only=True):
    """The temporary files atomic_write left beside ``path`` (a kill in mid-write), sorted;
    ``dead_only``: only those whose process id is no longer alive on this host. The caller
    decides whether to remove them (see the module's text)."""
    target = _target(path)
    folder = os.path.dirname(target)
    pattern = re.compile(re.escape(_temp_prefix(target)) + r"(\d+)\.[0-9a-f]{8}"
                         + re.escape(TEMP_SUFFIX) + "$")
    found = []
    try:
        names = os.listdir(folder)
    except FileNotFoundError:
        return []
    for name in names:
        m = pattern.match(name)
        if m and not (dead_only and _alive(int(m.group(1)))):
            found.append(os.path.join(folder, name))
    return sorted(found)
