"""The two line protocols of the rig, as pure functions both ends share (docs/protocol.md).

Motion: G-code to a GRBL 1.1 style controller with a rotary axis A. Sensor: BladeInspect's own
line protocol for the conoscopic probe. On one shared port every sensor line carries the
``@`` prefix (a character GRBL never sends or accepts at the start of a line); on a port of
its own the sensor speaks the same lines without it.

Nothing here touches a port: the serial driver, the simulated device and the tests all call
these, so host and device can only disagree about the transport, never about the text.
"""

import math
import re
from dataclasses import dataclass

import numpy as np

SENSOR_PREFIX = "@"
# GRBL's serial receive buffer; a streaming host keeps the unacknowledged bytes within it.
GRBL_RX_BUFFER = 128
# GRBL's line buffer: longer lines are rejected with error:14 (1.1) rather than executed.
GRBL_MAX_LINE = 80
STATUS_QUERY = b"?"
# GRBL greets with "Grbl 1.1h ['$' for help]", grblHAL with "GrblHAL 1.1f ['$' or '$HELP' ...]".
BANNER_PREFIXES = ("Grbl ", "GrblHAL ")
SOFT_RESET = b"\x18"

GRBL_ERRORS = {
    1: "expected command letter",
    2: "bad number format",
    3: "invalid $ statement",
    4: "negative value",
    5: "homing not enabled",
    8: "not idle",
    9: "G-code locked out during alarm",
    10: "soft limits need homing enabled",
    11: "line overflow",
    14: "line length exceeded",
    15: "travel exceeded",
    16: "invalid jog command",
    20: "unsupported command",
    21: "modal group violation",
    22: "undefined feed rate",
    23: "value not an integer",
    24: "axis command conflict",
    25: "word repeated",
    26: "no axis words",
    28: "value word missing",
    33: "invalid target",
    36: "unused words",
}

GRBL_ALARMS = {
    1: "hard limit triggered",
    2: "soft limit: target exceeds machine travel",
    3: "reset while in motion",
    4: "probe fail: not in expected initial state",
    5: "probe fail: no contact",
    6: "homing fail: reset during homing",
    7: "homing fail: safety door opened",
    8: "homing fail: pull-off did not clear the limit switch",
    9: "homing fail: limit switch not found",
    10: "emergency stop",
}

SENSOR_ERRORS = {
    "BAD_COMMAND": "unknown command",
    "BAD_ARGUMENT": "malformed argument",
    "OUT_OF_RANGE": "argument out of range",
    "NOT_ARMED": "trigger while no acquisition was started",
    "OVERRUN": "more triggers than readings requested",
    "LASER_FAULT": "laser fault",
    "SIMULATION_FAILED": "the simulated sensor's measurement raised an exception",
}

# Three coordinates of this length still fit GRBL's 80-character line. Only values within
# about 1e-5 of zero need more; they are rounded to 1e-12 mm, far below any stage's resolution.
_FALLBACK_DECIMALS = 12
_MAX_NUMBER_CHARS = 24


class ProtocolError(ValueError):
    """A line that does not parse; the driver turns it into a DeviceError naming the port."""


def format_number(value):
    """Shortest fixed-point text that reads back as exactly the same float (no exponent, which
    GRBL cannot parse), so the device moves to the very coordinates the host planned."""
    value = float(value)
    if not math.isfinite(value):
        raise ProtocolError("coordinate %r is not a finite number" % value)
    text = repr(value)      # shortest round-trip digits; fixed point unless tiny or huge
    if "e" in text:
        text = np.format_float_positional(value, unique=True, trim="-")
    elif text.endswith(".0"):
        text = text[:-2]
    if len(text) > _MAX_NUMBER_CHARS:
        text = ("%.*f" % (_FALLBACK_DECIMALS, value)).rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def gcode_move(code, x=None, y=None, z=None, a=None, feed=None):
    """One motion block, e.g. ``G1X1.5Z44F600``; axes given as None are left out (modal)."""
    words = [code]
    for letter, value in (("X", x), ("Y", y), ("Z", z), ("A", a), ("F", feed)):
        if value is not None:
            words.append(letter + format_number(value))
    line = "".join(words)
    if len(line) > GRBL_MAX_LINE:
        raise ProtocolError("G-code block longer than %d characters: %s" % (GRBL_MAX_LINE, line))
    return line


_COMMENTS = re.compile(r"\([^)]*\)|;.*")
_WORD = re.compile(r"([A-Z])([-+]?[0-9]*\.?[0-9]*)")


def parse_gcode(line):
    """A block's words as [(letter, value)], comments and spaces removed; ProtocolError carries
    the GRBL error number a controller would answer with."""
    text = "".join(_COMMENTS.sub("", line).upper().split())
    words = []
    end = 0
    for match in _WORD.finditer(text):
        if match.start() != end:
            raise ProtocolError(1)
        letter, number = match.groups()
        try:
            words.append((letter, float(number)))
        except ValueError:
            raise ProtocolError(2)
        end = match.end()
    if end != len(text):
        raise ProtocolError(1 if not text[end].isdigit() and text[end] not in ".+-" else 2)
    return words


@dataclass
class Status:
    """A real-time status report ``<State|MPos:x,y,z,a|...>``."""
    state: str
    position: tuple   # (x, y, z, a) machine position

    @property
    def idle(self):
        return self.state == "Idle"


def format_status(state, position):
    return "<%s|MPos:%s|FS:0,0>" % (state, ",".join(format_number(v) for v in position))


def parse_status(line):
    """Status from a report; takes MPos or WPos (whichever the controller is set to send)."""
    if not (line.startswith("<") and line.endswith(">")):
        raise ProtocolError("not a status report: %r" % line)
    fields = line[1:-1].split("|")
    state = fields[0].split(":")[0]
    if state not in ("Idle", "Run", "Hold", "Jog", "Alarm", "Door", "Check", "Home", "Sleep"):
        raise ProtocolError("unknown controller state in %r" % line)
    for field in fields[1:]:
        key, _, value = field.partition(":")
        if key in ("MPos", "WPos"):
            try:
                values = tuple(float(v) for v in value.split(","))
            except ValueError:
                raise ProtocolError("bad position in %r" % line)
            if len(values) != 4:
                raise ProtocolError("expected 4 axes X,Y,Z,A in %r" % line)
            return Status(state, values)
    raise ProtocolError("no MPos/WPos in %r" % line)


def parse_build_options(info):
    """The receive buffer size from ``$I``'s ``[OPT:<codes>,<blocks>,<rx bytes>,...]`` (GRBL 1.1
    and grblHAL), or None when the line is not that or carries no size."""
    if not info.startswith("OPT:"):
        return None
    fields = info[4:].split(",")
    try:
        size = int(fields[2])
    except (IndexError, ValueError):
        return None
    return size if size > 0 else None


def describe_error(code):
    return "error:%d (%s)" % (code, GRBL_ERRORS.get(code, "unknown error"))


def describe_alarm(code):
    return "ALARM:%d (%s)" % (code, GRBL_ALARMS.get(code, "unknown alarm"))


# Kinds of line a controller sends, as parse_motion_line classifies them.
OK, ERROR, ALARM, STATUS, INFO, BANNER = "ok", "error", "alarm", "status", "info", "banner"


def parse_motion_line(line):
    """(kind, payload) of one line from the controller: ok, error (code), alarm (code),
    status (Status), info (text in [..]), banner (the startup greeting after a reset)."""
    if line == "ok":
        return OK, None
    if line.startswith("error:") or line.startswith("ALARM:"):
        try:
            code = int(line.split(":", 1)[1])
        except ValueError:
            raise ProtocolError("malformed %r" % line)
        return (ERROR if line[0] == "e" else ALARM), code
    if line.startswith("<"):
        return STATUS, parse_status(line)
    if line.startswith("[") and line.endswith("]"):
        return INFO, line[1:-1]
    if line.startswith(BANNER_PREFIXES):
        return BANNER, line
    raise ProtocolError("unexpected line %r" % line)


# Sensor lines: commands host -> sensor, answers and readings sensor -> host.
READING, SENSOR_OK, SENSOR_END, SENSOR_ERROR, SENSOR_ID = "R", "OK", "END", "E", "ID"


def format_reading(index, distance_mm, snr):
    distance = "NaN" if not math.isfinite(distance_mm) else format_number(distance_mm)
    return "R %d %s %s" % (index, distance, format_number(snr))


def parse_sensor_line(line):
    """(kind, payload) of one line from the sensor (prefix already removed):
    R -> (index, distance or NaN, snr); OK -> echoed command text; END -> count;
    E -> (code, text); ID -> dict of the identity fields."""
    kind, _, rest = line.partition(" ")
    if kind == READING:
        parts = rest.split()
        if len(parts) != 3:
            raise ProtocolError("malformed reading %r" % line)
        try:
            index = int(parts[0])
            distance = float(parts[1])
            snr = float(parts[2])
        except ValueError:
            raise ProtocolError("malformed reading %r" % line)
        return READING, (index, distance, snr)
    if kind == SENSOR_OK:
        return SENSOR_OK, rest
    if kind == SENSOR_END:
        try:
            return SENSOR_END, int(rest)
        except ValueError:
            raise ProtocolError("malformed %r" % line)
    if kind == SENSOR_ERROR:
        code, _, text = rest.partition(" ")
        if not code:
            raise ProtocolError("sensor error without a code: %r" % line)
        return SENSOR_ERROR, (code, text or SENSOR_ERRORS.get(code, ""))
    if kind == SENSOR_ID:
        fields = rest.split()
        if not fields:
            raise ProtocolError("empty identity %r" % line)
        info = {"model": fields[0]}
        for field in fields[1:]:
            key, sep, value = field.partition("=")
            if sep:
                info[key] = value
        return SENSOR_ID, info
    raise ProtocolError("unexpected sensor line %r" % line)


def format_identity(model, **fields):
    return "ID %s %s" % (model, " ".join("%s=%s" % kv for kv in fields.items()))


def describe_sensor_error(code, text=""):
    return "sensor error %s (%s)" % (code, text or SENSOR_ERRORS.get(code, "unknown"))


# The controller pulses its trigger output at the end of every G1 block between these two
# (docs/protocol.md, "Triggers"); rapids (G0) never trigger.
TRIGGER_ON = "M62P0"
TRIGGER_OFF = "M63P0"
# Waits for the planner to empty: its ok means every earlier motion has finished.
SYNC = "G4P0"

