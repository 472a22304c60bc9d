"""The rig driven over a serial line: G-code to a GRBL-style controller, the sensor's own line
protocol (docs/protocol.md), on one shared port or two (``MOTION,SENSOR``).

Motion is streamed with GRBL's character counting: lines go out as long as the bytes not yet
answered fit the controller's receive buffer (128 bytes on GRBL 1.1, as ``$I`` reports), so a
pass of K points costs one sensor round trip plus a stream, not K exchanges. Every failure ends in one DeviceError naming the
port and what went wrong; the driver never retries, since the strategy above it decides.
"""

import collections
import contextlib
import select
import time

import numpy as np

from ..core.errors import DeviceError, InputError
from . import protocol as pr
from .base import Readings, Rig
from .sensor import SensorModel

# A real GRBL homes at a few mm/s over up to the full travel: give it far longer than a reply.
HOME_TIMEOUT_S = 120.0
# While an answer is awaited the status is polled this often, as GRBL senders do.
STATUS_POLL_S = 0.5


class _Port:
    """One pyserial port with a byte buffer cut into lines; errors become DeviceError."""

    def __init__(self, url, baud, label):
        import serial
        self.url = url
        self.label = label
        self._serial_error = serial.SerialException
        try:
            self.serial = serial.serial_for_url(url, baudrate=baud, timeout=0, write_timeout=None)
        except (serial.SerialException, OSError, ValueError) as exc:
            # pyserial wraps the OSError whose strerror is the useful part.
            cause = exc.__context__ if isinstance(exc.__context__, OSError) else exc
            reason = getattr(cause, "strerror", None) or str(exc)
            raise DeviceError("serial:%s: cannot open the %s port (%s)"
                              % (url, label, reason)) from None
        try:
            self._fileno = self.serial.fileno()
        except Exception:
            self._fileno = None
        self._buffer = b""
        try:
            self.serial.reset_input_buffer()
        except Exception:
            pass    # not every URL handler has an input buffer to flush

    def lost(self, exc):
        return DeviceError("serial:%s: %s port lost (%s)" % (self.url, self.label, exc))

    def write(self, data):
        try:
            self.serial.write(data)
        except (self._serial_error, OSError) as exc:
            raise self.lost(exc)

    def read_lines(self):
        """Complete lines already received, decoded; [] when none is waiting."""
        try:
            # With timeout 0 this returns at once; on a vanished port it raises instead.
            data = self.serial.read(max(1, self.serial.in_waiting))
        except (self._serial_error, OSError) as exc:
            raise self.lost(exc)
        if not data:
            return []
        self._buffer += data
        *lines, self._buffer = self._buffer.split(b"\n")
        out = []
        for raw in lines:
            try:
                text = raw.decode("ascii").strip()
            except UnicodeDecodeError:
                raise DeviceError("serial:%s: garbage from the %s port: %r"
                                  % (self.url, self.label, raw[:60]))
            if text:
                out.append(text)
        return out

    def close(self):
        try:
            self.serial.close()
        except Exception:
            pass    # the port may be gone already; closing must not mask the original error


def _wait_readable(ports, timeout):
    """Block until one of the ports may have data or the timeout passes."""
    fds = [p._fileno for p in ports]
    if all(fd is not None for fd in fds):
        try:
            select.select(fds, [], [], timeout)
        except (OSError, ValueError) as exc:
            raise ports[0].lost(exc)
    else:
        # Ports without a file descriptor (loop://, sockets): poll briefly.
        time.sleep(min(timeout, 0.002))


class SerialRig(Rig):
    """A four-axis rig with its conoscopic sensor over pyserial. ``port_url`` is one port
    (pty path, /dev/ttyUSB0, loop://, ...) carrying both protocols, or ``MOTION,SENSOR``.
    ``timeout_s``: longest silence while an answer is awaited (homing gets HOME_TIMEOUT_S).
    ``feed_mm_min``: feed along a scan path (the simulated rig's 20 mm/s by default).
    ``rx_buffer``: the controller's receive buffer, when ``$I`` does not tell it.
    ``limits``/``sensor``: the travel checked before sending and the sensor model the
    strategy plans with (default: the sensor's own ID fields on SensorModel defaults)."""

    def __init__(self, port_url, timeout_s=5, baud=115200, feed_mm_min=1200.0,
                 rx_buffer=None, limits=None, sensor=None):
        if timeout_s is None or not timeout_s > 0:
            raise InputError("timeout_s: must be a positive number of seconds, got %r" % timeout_s)
        urls = [u.strip() for u in str(port_url).split(",")]
        if len(urls) not in (1, 2) or not all(urls):
            raise InputError("serial:%s: expected PORT or MOTION_PORT,SENSOR_PORT" % port_url)
        self.port_url = port_url
        self.timeout_s = float(timeout_s)
        self.feed_mm_min = float(feed_mm_min)
        # Until $I reports the controller's receive buffer, assume GRBL 1.1's.
        self.rx_buffer = pr.GRBL_RX_BUFFER
        self._rx_buffer_forced = rx_buffer is not None
        if rx_buffer is not None:
            self.rx_buffer = int(rx_buffer)
        if limits is not None:
            self.limits = limits
        if sensor is not None:
            self.sensor = sensor
        self._elapsed = 0.0
        self._timing_depth = 0
        self._failure = None
        self._homed = False
        self._homing_disabled = False
        self._target = None
        self._status = None
        self._banner = None
        self._connecting = True
        self._polls = 0         # status queries sent while waiting, not yet answered
        self._sensor_flushing = False
        self._inflight = collections.deque()     # (line, bytes) sent to the controller, unanswered
        self._inflight_bytes = 0
        self._sensor_answers = collections.deque()
        self._pass = None
        self.pass_index = 0
        self.sensor_identity = None
        self._motion = _Port(urls[0], baud, "motion")
        try:
            self._sensor = _Port(urls[1], baud, "sensor") if len(urls) == 2 else self._motion
            self._shared = self._sensor is self._motion
            self._ports = [self._motion] if self._shared else [self._motion, self._sensor]
            with self._timed():
                self._connect()
        except BaseException:
            self.close()
            raise

    # -- Rig interface --------------------------------------------------------------------

    def home(self):
        """Homes the machine ($H); a controller without homing switches (error:5) is only
        unlocked ($X), its position taken as it stands."""
        with self._timed():
            self._stream(["$H"], timeout_s=max(self.timeout_s, HOME_TIMEOUT_S))
            if self._homing_disabled:
                self._stream(["$X"])
            self._stream(["G90G21"])
            self._homed = True
            self._target = self._query_status().position

    def position(self):
        with self._timed():
            return self._query_status().position

    def move_to(self, x=None, y=None, z=None, a=None):
        with self._timed():
            self._ensure_homed()
        target = tuple(c if v is None else float(v) for v, c in zip((x, y, z, a), self._target))
        self.limits.check(*target)
        with self._timed():
            self._stream([pr.gcode_move("G0", x, y, z, a), pr.SYNC])
            self._target = target

    def scan_path(self, path_xyz, angle_deg):
        path = np.asarray(path_xyz, dtype=float)
        if path.ndim != 2 or path.shape[1] != 3 or len(path) == 0:
            raise InputError("scan_path: path must be (K, 3) stage positions, got shape %s"
                             % (path.shape,))
        if not np.all(np.isfinite(path)) or not np.isfinite(angle_deg):
            raise InputError("scan_path: path and angle must be finite numbers")
        angle = float(angle_deg)
        self.limits.check(path[:, 0], path[:, 1], path[:, 2], angle)
        with self._timed():
            self._ensure_homed()
            return self._run_pass(path, angle)

    @property
    def elapsed_s(self):
        """Wall-clock seconds spent talking to the rig: on a real rig that is its own time."""
        return self._elapsed

    def close(self):
        for port in getattr(self, "_ports", [getattr(self, "_motion", None)]):
            if port is not None:
                port.close()

    def set_pass_index(self, index):
        """Numbers the next pass; a simulated sensor also takes it as its noise stream
        (docs/protocol.md, PASS) so that a resumed scan measures as the uninterrupted one
        would. A real sensor has no such thing and answers BAD_COMMAND, which is ignored."""
        with self._timed():
            self._sensor_command("PASS %d" % int(index), allow_errors=("BAD_COMMAND",))
        self.pass_index = int(index)

    @contextlib.contextmanager
    def _timed(self):
        """Adds the wall time of the outermost rig operation to elapsed_s (home inside a
        move counts once). A device failure inside leaves the exchange in an unknown state
        (blocks unanswered, readings in flight): the rig refuses further work after it."""
        if self._failure is not None:
            raise DeviceError("serial:%s: rig unusable after an earlier failure (%s); open it "
                              "again" % (self.port_url, self._failure))
        self._timing_depth += 1
        start = time.monotonic()
        try:
            yield
        except DeviceError as exc:
            self._failure = str(exc).split(": ", 1)[-1]
            raise
        finally:
            self._timing_depth -= 1
            if self._timing_depth == 0:
                self._elapsed += time.monotonic() - start

    # -- one pass -------------------------------------------------------------------------

    def _run_pass(self, path, angle):
        k = len(path)
        self._pass = {"k": k, "reading": np.full(k, np.nan), "snr": np.zeros(k),
                      "seen": np.zeros(k, bool), "count": 0, "end": None}
        self._sensor_command("START %d" % k)
        lines = [pr.gcode_move("G0", a=angle),
                 pr.gcode_move("G0", *path[0]),
                 "F" + pr.format_number(self.feed_mm_min),
                 pr.TRIGGER_ON]
        previous = (None, None, None)
        for i, point in enumerate(path):
            # Unchanged axes are left out (G-code is modal): shorter lines stream faster.
            words = [None if v == p else v for v, p in zip(point, previous)]
            if i == 0:
                words = list(point)
            lines.append(pr.gcode_move("G1", *words) if any(w is not None for w in words)
                         else "G1")
            previous = point
        lines += [pr.TRIGGER_OFF, pr.SYNC]
        self._stream(lines)
        state = self._pass
        self._wait_for(lambda: state["end"] is not None, "the end of the sensor's readings")
        if state["end"] != k or state["count"] != k:
            raise DeviceError("serial:%s: sensor ended the pass with %d of %d readings"
                              % (self.port_url, state["count"], k))
        self._pass = None
        self._target = tuple(path[-1]) + (angle,)
        index = self.pass_index
        self.pass_index += 1
        return Readings(stage_xyz=path.copy(), angle_deg=angle, reading_mm=state["reading"],
                        snr=state["snr"], meta={"pass_index": index, "port": self.port_url})

    # -- transport ------------------------------------------------------------------------

    def _connect(self):
        self._motion.write(pr.SOFT_RESET)
        self._wait_for(lambda: self._banner is not None, "the controller's greeting after a reset")
        self._connecting = False
        # A reset by the port opening (DTR) may greet a second time: a status answer comes after.
        self._query_status()
        self._stream(["$I"])
        if not self._shared:
            self._sensor_flushing = True
            self._sensor_command("STOP")
            self._sensor_flushing = False
        self._sensor_command("ID")
        if self.sensor is None:
            self.sensor = _sensor_model(self.sensor_identity)

    def _ensure_homed(self):
        if not self._homed:
            self.home()

    def _query_status(self):
        self._status = None
        self._motion.write(pr.STATUS_QUERY)
        self._wait_for(lambda: self._status is not None, "a status report")
        return self._status

    def _sensor_command(self, command, allow_errors=()):
        prefix = pr.SENSOR_PREFIX if self._shared else ""
        data = (prefix + command + "\n").encode("ascii")
        if self._shared:
            # On the shared port the sensor's line occupies the controller's receive buffer too.
            self._wait_for(lambda: self._inflight_bytes + len(data) <= self.rx_buffer,
                           "room in the controller's buffer")
            self._inflight.append((command, len(data), "sensor"))
            self._inflight_bytes += len(data)
        self._sensor_answers.append([command, None, allow_errors])
        self._sensor.write(data)
        entry = self._sensor_answers[-1]
        self._wait_for(lambda: entry[1] is not None, "the sensor's answer to %s" % command)
        return entry[1]

    def _stream(self, lines, timeout_s=None):
        """Send G-code lines with character counting, then wait until every one is answered."""
        pending = [(line, (line + "\n").encode("ascii")) for line in lines]
        i = 0
        while i < len(pending):
            chunk = []
            room = self.rx_buffer - self._inflight_bytes
            while i < len(pending) and len(pending[i][1]) <= room:
                line, data = pending[i]
                self._inflight.append((line, len(data), "motion"))
                self._inflight_bytes += len(data)
                room -= len(data)
                chunk.append(data)
                i += 1
            if chunk:
                self._motion.write(b"".join(chunk))
            else:
                size = len(pending[i][1])
                self._wait_for(lambda: self._inflight_bytes + size <= self.rx_buffer,
                               "an ok for %s" % self._inflight[0][0], timeout_s)
        self._wait_for(lambda: not self._inflight, "an ok for the last block", timeout_s)

    def _wait_for(self, done, what, timeout_s=None):
        """Handle incoming lines until done(). Times out after timeout_s without progress;
        while waiting it polls the status, so a long move (the controller reporting Run)
        is progress, and an idle or silent controller is not."""
        timeout = self.timeout_s if timeout_s is None else timeout_s
        poll = min(STATUS_POLL_S, timeout / 4.0)
        now = time.monotonic()
        deadline, next_poll = now + timeout, now + poll
        while not done():
            progressed = None
            for port in self._ports:
                for line in port.read_lines():
                    progressed = self._handle(port, line) or bool(progressed)
            now = time.monotonic()
            if progressed:
                deadline = now + timeout
            if progressed is not None:
                continue
            if now >= deadline:
                raise DeviceError("serial:%s: timeout, no answer within %g s while waiting for %s"
                                  % (self.port_url, timeout, what))
            if now >= next_poll and not self._connecting:
                self._motion.write(pr.STATUS_QUERY)
                self._polls += 1
                next_poll = now + poll
            wake = deadline if self._connecting else min(deadline, next_poll)
            _wait_readable(self._ports, max(0.0, wake - now))

    def _handle(self, port, line):
        """Act on one line; False only for a poll's answer that shows no motion."""
        if self._connecting:
            # Until the reset's greeting, lines are leftovers of an earlier session.
            if line.startswith(pr.BANNER_PREFIXES):
                self._banner = line
            return True
        if port is self._sensor and (not self._shared or line.startswith(pr.SENSOR_PREFIX)):
            self._handle_sensor(line[1:] if self._shared else line)
            return True
        try:
            kind, payload = pr.parse_motion_line(line)
        except pr.ProtocolError:
            raise DeviceError("serial:%s: garbage from the controller: %r" % (self.port_url, line[:60]))
        if kind == pr.OK:
            self._answered("motion", line)
        elif kind == pr.ERROR:
            sent = self._answered("motion", line)
            if sent == "$H" and payload == 5:
                self._homing_disabled = True
                return True
            what = "soft limit: " if payload == 15 else ""
            raise DeviceError("serial:%s: %scontroller answered %s to %s"
                              % (self.port_url, what, pr.describe_error(payload), sent))
        elif kind == pr.ALARM:
            what = {1: "hard limit: ", 2: "soft limit: "}.get(payload, "")
            raise DeviceError("serial:%s: %scontroller raised %s"
                              % (self.port_url, what, pr.describe_alarm(payload)))
        elif kind == pr.STATUS:
            self._status = payload
            if self._polls:
                self._polls -= 1
                if payload.state == "Alarm":
                    raise DeviceError("serial:%s: controller is in alarm state while waiting"
                                      % self.port_url)
                return payload.state not in ("Idle", "Sleep")
        elif kind == pr.BANNER:
            if self._banner is not None and self._status is not None:
                raise DeviceError("serial:%s: controller reset itself (%s)" % (self.port_url, line))
            self._banner = payload
        elif kind == pr.INFO:
            size = pr.parse_build_options(payload)
            if size is not None and not self._rx_buffer_forced:
                self.rx_buffer = size
        # Other INFO lines ([MSG:...], [VER:...]) carry nothing the driver acts on.
        return True

    def _answered(self, channel, line):
        """Retire the oldest unanswered line of the channel; an answer nobody asked for is
        the sign of a confused or foreign device."""
        for j, (sent, nbytes, kind) in enumerate(self._inflight):
            if kind == channel:
                del self._inflight[j]
                self._inflight_bytes -= nbytes
                return sent
        if channel == "sensor" and not self._shared:
            return None
        raise DeviceError("serial:%s: unexpected %r from the %s side" % (self.port_url, line, channel))

    def _handle_sensor(self, line):
        if self._sensor_flushing and line != "OK STOP":
            return      # readings of a pass an earlier session left behind
        try:
            kind, payload = pr.parse_sensor_line(line)
        except pr.ProtocolError:
            raise DeviceError("serial:%s: garbage from the sensor: %r" % (self.port_url, line[:60]))
        if kind == pr.READING:
            self._store_reading(*payload)
        elif kind == pr.SENSOR_END:
            if self._pass is None:
                raise DeviceError("serial:%s: sensor ended a pass that was not started"
                                  % self.port_url)
            self._pass["end"] = payload
        elif kind == pr.SENSOR_ERROR:
            code, text = payload
            entry = self._sensor_answers[0] if self._sensor_answers else None
            if entry is not None and code in entry[2]:
                self._answered("sensor", line)
                self._sensor_answers.popleft()
                entry[1] = line
                return
            raise DeviceError("serial:%s: %s" % (self.port_url, pr.describe_sensor_error(code, text)))
        else:   # OK or ID: the answer to the oldest sensor command
            if not self._sensor_answers:
                raise DeviceError("serial:%s: unexpected sensor answer %r" % (self.port_url, line))
            self._answered("sensor", line)
            entry = self._sensor_answers.popleft()
            if kind == pr.SENSOR_ID:
                self.sensor_identity = payload
            entry[1] = line

    def _store_reading(self, index, distance, snr):
        state = self._pass
        if state is None:
            raise DeviceError("serial:%s: sensor sent a reading outside a pass" % self.port_url)
        if not 0 <= index < state["k"] or state["seen"][index]:
            raise DeviceError("serial:%s: sensor sent reading %d %s" % (
                self.port_url, index, "twice" if 0 <= index < state["k"] else
                "beyond the %d requested" % state["k"]))
        state["seen"][index] = True
        state["count"] += 1
        state["reading"][index] = distance
        state["snr"][index] = snr if np.isfinite(distance) else 0.0


def _sensor_model(identity):
    """The planning model of the sensor, with what it says of itself in place of the defaults."""
    known = {}
    for key, field in (("standoff_mm", "standoff"), ("range_mm", "half_range"),
                       ("rate_hz", "rate_hz")):
        try:
            known[field] = float(identity[key])
        except (KeyError, ValueError):
            pass    # an unknown or unreadable field keeps the model's default
    return SensorModel(**known)
