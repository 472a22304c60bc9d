"""Errors a user can act on.

An InputError carries a one-line message naming the file (or parameter) and the problem; the
command line prints it as ``bladeinspect: error: <message>`` and exits with status 2, and the
GUI shows it in a dialog. Anything else escaping the pipeline is a bug, not bad input.
"""


class InputError(Exception):
    """Bad input from the user: a file, a parameter, a device. Message is one line."""

    def __init__(self, message):
        super().__init__(" ".join(str(message).split()))


class DeviceError(InputError):
    """The rig or sensor failed (port vanished, timeout, alarm, limit, out of range)."""


class Cancelled(Exception):
    """The user cancelled a long operation; partial results stay where they were written."""
