"""The simulated rig served as a device on a pseudo-terminal: it speaks the controller's G-code
and the sensor's line protocol (docs/protocol.md), so the serial driver talks to it exactly as
to a real rig, and every reading comes from the SimulatedRig's own measure() — the same points
as in process for the same seed.

One thread runs a select loop over the pty masters; the masters never block (replies queue
until the host reads), so a host that does not read cannot stall the device. Faults are
injected on purpose for the tests: the pty vanishing, garbage, silence, an alarm, a sensor
error.
"""

import os
import select
import sys
import threading
import time
import tty
from dataclasses import dataclass

import numpy as np

from . import protocol as pr
from .simulated import simulated_rig_for

BANNER = "Grbl 1.1h ['$' for help]"
SENSOR_MODEL = "BladeInspect-SimProbe"
# The sensor buffers this many readings per acquisition; larger requests are OUT_OF_RANGE.
MAX_READINGS = 10_000_000
# grblHAL's receive buffer: eight times GRBL 1.1's, so eight times fewer waits per pass.
GRBLHAL_RX_BUFFER = 1024
FAULT_KINDS = ("close", "garbage", "silent", "alarm", "sensor_error", "busy", "lose_reading")


@dataclass
class Fault:
    """Strikes at the first command line (G-code or sensor) after ``after_lines`` lines and
    ``after_passes`` completed passes since the device started: ``close`` closes the pty, ``garbage`` answers every
    line from then on with noise, ``silent`` stops answering, ``alarm`` raises ALARM:<alarm>
    (1 hard limit), ``sensor_error`` makes the sensor report E <sensor_code>, ``busy`` holds
    that line's answers for ``busy_s`` seconds while reporting Run (a long move),
    ``lose_reading`` drops the middle reading of the next pass (a line lost on the wire)."""
    kind: str
    after_lines: int = 0
    after_passes: int = 0
    alarm: int = 1
    sensor_code: str = "LASER_FAULT"
    busy_s: float = 1.0

    def __post_init__(self):
        if self.kind not in FAULT_KINDS:
            raise ValueError("fault kind must be one of %s, got %r" % (FAULT_KINDS, self.kind))


class _Pty:
    """A pseudo-terminal whose slave a serial port opens; the device owns the master."""

    def __init__(self):
        self.master, self.slave = os.openpty()
        tty.setraw(self.slave)
        os.set_blocking(self.master, False)
        self.path = os.ttyname(self.slave)
        self.inbox = b""
        self.outbox = bytearray()

    def close(self):
        for fd in (self.master, self.slave):
            try:
                os.close(fd)
            except OSError:
                pass    # already closed by a fault


class SimRigDevice:
    """Serves ``sim_rig`` (anything with measure(stage_xyz, angle_deg, pass_index) ->
    (reading, snr); limits, home() and position() are used when present) on one pty, or on
    two (motion, sensor) with ``two_ports``. ``limits`` overrides the controller's soft limits
    (a controller set up tighter than the host believes). ``rx_buffer`` is the receive buffer
    it reports in ``$I`` and holds the host to: 128 bytes as GRBL 1.1, 1024 as grblHAL (the
    default: a rig fed at the sensor's 9000 points/s needs a controller of that class).
    ``homing=False``: a controller without homing switches ($H answers error:5)."""

    def __init__(self, sim_rig, two_ports=False, fault=None, limits=None,
                 rx_buffer=GRBLHAL_RX_BUFFER, homing=True):
        self.sim_rig = sim_rig
        self.fault = fault
        self.limits = limits if limits is not None else getattr(sim_rig, "limits", None)
        self.rx_buffer = int(rx_buffer)
        self.homing = bool(homing)
        self.lines_received = 0
        self.overflows = 0          # bytes beyond the controller's RX buffer: a host bug
        self.passes = 0
        self.pass_index = int(getattr(sim_rig, "pass_index", 0) or 0)
        self._motion = _Pty()
        self._sensor = _Pty() if two_ports else self._motion
        self._ptys = [self._motion] if self._sensor is self._motion else [self._motion, self._sensor]
        # Without homing switches GRBL starts unlocked ($22=0).
        self._homed = not self.homing
        self._alarm_latched = False
        self._position = (tuple(float(v) for v in sim_rig.position())
                          if hasattr(sim_rig, "position") else (0.0, 0.0, 0.0, 0.0))
        self._silent = False
        self._sensor_fault_sent = False
        self._busy_until = 0.0
        self._busy_done = False
        self._lose_reading = None   # True: drop a reading of the next pass; False: done
        self._held = []         # answers held while busy or measuring, sent when it is done
        self._measurement = None
        self._session = 0       # counts resets: a measurement from before one is dropped
        self._wake_read, self._wake_write = os.pipe()
        self._stop = threading.Event()
        self._thread = None
        self._closed = False
        self._reset_sensor()
        self._reset()

    @property
    def port_url(self):
        """What SerialRig (and ``--rig serial:...``) is given to reach this device."""
        return ",".join(p.path for p in self._ptys)

    def start(self):
        self._thread = threading.Thread(target=self._serve, name="simrig-device", daemon=True)
        self._thread.start()
        return self

    def stop(self):
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5)
        self._close_ptys()

    def __enter__(self):
        return self.start()

    def __exit__(self, *exc):
        self.stop()

    # -- loop ------------------------------------------------------------------------------

    def _serve(self):
        while not self._stop.is_set() and not self._closed:
            if self._measurement is not None and not self._measurement["thread"].is_alive():
                self._measured()
            if self._held and not self._holding():
                for pty, text in self._held:
                    pty.outbox += text
                self._held = []
            readers = [p.master for p in self._ptys] + [self._wake_read]
            writers = [p.master for p in self._ptys if p.outbox]
            try:
                readable, writable, _ = select.select(readers, writers, [], 0.02)
            except (OSError, ValueError):
                return
            if self._wake_read in readable:
                os.read(self._wake_read, 64)
            for pty in self._ptys:
                if self._closed:
                    return
                if pty.master in writable:
                    self._flush(pty)
                if pty.master in readable:
                    try:
                        data = os.read(pty.master, 65536)
                    except (BlockingIOError, InterruptedError):
                        continue
                    except OSError:
                        return
                    self._receive(pty, data)
                    self._flush(pty)

    def _flush(self, pty):
        try:
            written = os.write(pty.master, pty.outbox)
        except (BlockingIOError, InterruptedError):
            return
        except OSError:
            return
        del pty.outbox[:written]

    def _send(self, pty, line):
        if self._closed or self._silent:
            return
        text = (line + "\r\n").encode("ascii")
        if self._holding():
            self._held.append((pty, text))
        else:
            pty.outbox += text

    def _holding(self):
        """While a busy fault or a pass's measurement lasts, the machine counts as moving:
        answers wait and the status says Run, as a real rig is still on its path."""
        return self._measurement is not None or time.monotonic() < self._busy_until

    def _close_ptys(self):
        if self._closed:
            return      # closing a descriptor twice could close one reused meanwhile
        self._closed = True
        for pty in self._ptys:
            pty.close()
        for fd in (self._wake_read, self._wake_write):
            try:
                os.close(fd)
            except OSError:
                pass    # closed by an earlier fault

    # -- input -----------------------------------------------------------------------------

    def _receive(self, pty, data):
        if pty is self._motion:
            # GRBL picks real-time commands out of the stream wherever they fall.
            if b"\x18" in data:
                data = data[data.rindex(b"\x18") + 1:]
                self._reset()
                self._send(pty, "")
                self._send(pty, BANNER)
                if self._state == "Alarm":
                    self._send(pty, "[MSG:'$H'|'$X' to unlock]")
            if b"?" in data:
                state = "Run" if self._holding() else self._state
                if not self._silent:
                    pty.outbox += ("%s\r\n" % pr.format_status(state, self._position)
                                   ).encode("ascii") * data.count(b"?")
                data = data.replace(b"?", b"")
            self._rx_pending += len(data)
            if self._rx_pending > self.rx_buffer:
                self.overflows += 1
        pty.inbox += data
        *lines, pty.inbox = pty.inbox.split(b"\n")
        for raw in lines:
            if self._closed:
                return
            if pty is self._motion:
                self._rx_pending -= len(raw) + 1
            line = raw.decode("ascii", "replace").strip()
            if line:
                self._line(pty, line)

    def _line(self, pty, line):
        self.lines_received += 1
        fault = self.fault
        if (fault is not None and self.lines_received > fault.after_lines
                and self.passes >= fault.after_passes):
            if fault.kind == "close":
                self._close_ptys()
                return
            if fault.kind == "silent":
                self._silent = True
                return
            if fault.kind == "lose_reading" and self._lose_reading is None:
                self._lose_reading = True
            if fault.kind == "busy" and not self._busy_done:
                self._busy_done = True
                self._busy_until = time.monotonic() + fault.busy_s
            if fault.kind == "garbage":
                self._send(pty, "%%~ 0x3f garbage ~%%")
                return
            if fault.kind == "alarm" and self._state != "Alarm":
                self._state = "Alarm"
                self._alarm_latched = True
                self._send(self._motion, "ALARM:%d" % fault.alarm)
                self._send(self._motion, "[MSG:Reset to continue]")
            if fault.kind == "sensor_error" and not self._sensor_fault_sent:
                self._sensor_fault_sent = True
                self._sensor_say("E %s %s" % (fault.sensor_code,
                                              pr.SENSOR_ERRORS.get(fault.sensor_code, "")))
        if pty is self._sensor and (pty is not self._motion or line.startswith(pr.SENSOR_PREFIX)):
            self._sensor_line(line[1:] if pty is self._motion else line)
        else:
            self._motion_line(line)

    # -- controller ------------------------------------------------------------------------

    def _reset(self):
        """What a soft reset clears; homing, a latched alarm, the position and injected
        faults survive it."""
        # As in GRBL, a reset does not clear a limit alarm: only $H or $X do.
        self._state = "Idle" if self._homed and not self._alarm_latched else "Alarm"
        self._absolute = True
        self._motion_mode = 0
        self._feed = None
        self._trigger = False
        self._rx_pending = 0
        self._motion.inbox = b""
        self._motion.outbox.clear()
        self._held = [(pty, text) for pty, text in self._held if pty is not self._motion]
        if self._sensor is self._motion:
            # On the shared line the reset reaches the sensor too; a sensor on its own port
            # keeps its acquisition (the host stops it when it connects).
            self._reset_sensor()

    def _reset_sensor(self):
        self._session += 1
        self._measurement = None
        self._held = []
        self._armed = None
        self._stage = []
        self._angle = None

    def _reply(self, text):
        self._send(self._motion, text)

    def _motion_line(self, line):
        if line.startswith("$"):
            return self._system_command(line)
        if self._state == "Alarm":
            return self._reply("error:9")
        try:
            words = pr.parse_gcode(line)
        except pr.ProtocolError as exc:
            return self._reply("error:%d" % exc.args[0])
        seen = set()
        axes = {}
        motion_word = False
        g4 = False
        p_value = None
        m_code = None
        for letter, value in words:
            if letter in "XYZAFP":
                if letter in seen:
                    return self._reply("error:25")
                seen.add(letter)
            if letter == "G":
                if value in (0, 1):
                    self._motion_mode = int(value)
                    motion_word = True
                elif value == 4:
                    g4 = True
                elif value in (90, 91):
                    self._absolute = value == 90
                elif value == 21:
                    pass
                else:
                    return self._reply("error:20")
            elif letter == "M":
                if value not in (62, 63):
                    return self._reply("error:20")
                m_code = int(value)
            elif letter in "XYZA":
                axes[letter] = value
            elif letter == "F":
                if value <= 0:
                    return self._reply("error:4")
                self._feed = value
            elif letter == "P":
                p_value = value
            else:
                return self._reply("error:20")
        if m_code is not None:
            if p_value != 0:
                return self._reply("error:28")
            self._trigger = m_code == 62
            return self._reply("ok")
        if g4:
            return self._reply("ok" if p_value is not None else "error:28")
        if not axes and not motion_word:
            return self._reply("ok")
        if self._motion_mode == 1 and self._feed is None:
            return self._reply("error:22")
        target = list(self._position)
        for i, letter in enumerate("XYZA"):
            if letter in axes:
                target[i] = axes[letter] if self._absolute else target[i] + axes[letter]
        if self.limits is not None and self._outside_limits(target):
            self._state = "Alarm"
            self._alarm_latched = True
            self._reply("ALARM:2")
            return self._reply("[MSG:Reset to continue]")
        self._position = tuple(target)
        self._reply("ok")
        if self._trigger and self._motion_mode == 1:
            self._triggered()

    def _outside_limits(self, target):
        x, y, z, a = target
        for value, (lo, hi) in ((x, self.limits.x), (y, self.limits.y), (z, self.limits.z)):
            if not lo - 1e-9 <= value <= hi + 1e-9:
                return True
        return self.limits.a is not None and not self.limits.a[0] <= a <= self.limits.a[1]

    def _system_command(self, line):
        if line == "$H":
            if not self.homing:
                return self._reply("error:5")
            if hasattr(self.sim_rig, "home"):
                self.sim_rig.home()
            if hasattr(self.sim_rig, "position"):
                self._position = tuple(float(v) for v in self.sim_rig.position())
            self._homed = True
            self._alarm_latched = False
            self._state = "Idle"
            return self._reply("ok")
        if line == "$I":
            self._reply("[VER:1.1h.20190825:BladeInspect simulated rig]")
            self._reply("[OPT:V,15,%d]" % self.rx_buffer)
            return self._reply("ok")
        if line == "$X":
            self._alarm_latched = False
            self._state = "Idle"
            self._reply("[MSG:Caution: Unlocked]")
            return self._reply("ok")
        return self._reply("error:3")

    # -- sensor ----------------------------------------------------------------------------

    def _sensor_say(self, text):
        prefix = pr.SENSOR_PREFIX if self._sensor is self._motion else ""
        self._send(self._sensor, prefix + text)

    def _sensor_line(self, line):
        command, _, argument = line.partition(" ")
        if command == "ID":
            model = getattr(self.sim_rig, "sensor", None)
            fields = {"firmware": "1.0"}
            for key, attr in (("standoff_mm", "standoff"), ("range_mm", "half_range"),
                              ("rate_hz", "rate_hz")):
                if model is not None and hasattr(model, attr):
                    fields[key] = pr.format_number(getattr(model, attr))
            return self._sensor_say(pr.format_identity(SENSOR_MODEL, **fields))
        if command in ("START", "PASS"):
            try:
                value = int(argument)
            except ValueError:
                return self._sensor_say("E BAD_ARGUMENT %s needs an integer" % command)
            if command == "PASS":
                if value < 0:
                    return self._sensor_say("E OUT_OF_RANGE pass index %d" % value)
                self.pass_index = value
            else:
                if not 1 <= value <= MAX_READINGS:
                    return self._sensor_say("E OUT_OF_RANGE %d readings (1..%d)"
                                            % (value, MAX_READINGS))
                self._armed = value
                self._stage = []
                self._angle = None
            return self._sensor_say("OK %s %d" % (command, value))
        if command == "STOP":
            self._armed = None
            self._stage = []
            return self._sensor_say("OK STOP")
        return self._sensor_say("E BAD_COMMAND %s" % command[:20])

    def _triggered(self):
        if self._armed is None:
            return self._sensor_say("E NOT_ARMED")
        self._stage.append(self._position[:3])
        self._angle = self._position[3]
        if len(self._stage) < self._armed:
            return
        # The simulated reading is known only for the whole pass (its noise is drawn per
        # pass), so the readings follow the last trigger rather than each one. Ray casting a
        # CAD can take seconds: a worker does it while the loop keeps answering status.
        measurement = {"stage": np.array(self._stage, dtype=float), "angle": self._angle,
                       "pass_index": self.pass_index, "session": self._session}

        def measure():
            try:
                measurement["result"] = self.sim_rig.measure(
                    measurement["stage"], measurement["angle"], measurement["pass_index"])
            except Exception as exc:     # reported to the host as a sensor error
                measurement["error"] = "%s: %s" % (type(exc).__name__, exc)
            try:
                os.write(self._wake_write, b"!")
            except OSError:
                pass    # the device was closed meanwhile
        measurement["thread"] = threading.Thread(target=measure, daemon=True)
        self._measurement = measurement
        self._armed = None
        self._stage = []
        measurement["thread"].start()

    def _measured(self):
        measurement, self._measurement = self._measurement, None
        if measurement["session"] != self._session:
            return
        if "error" in measurement:
            return self._sensor_say("E SIMULATION_FAILED %s" % measurement["error"][:200])
        self.pass_index += 1
        self.passes += 1
        reading, snr = measurement["result"]
        prefix = pr.SENSOR_PREFIX if self._sensor is self._motion else ""
        lines = ["%s%s\r\n" % (prefix, pr.format_reading(i, d, s))
                 for i, (d, s) in enumerate(zip(np.asarray(reading, float),
                                                np.asarray(snr, float)))]
        if self._lose_reading:
            self._lose_reading = False
            del lines[len(lines) // 2]
        text = "".join(lines)
        self._sensor.outbox += text.encode("ascii")
        self._sensor_say("END %d" % len(measurement["stage"]))


def run_simrig(nominal=None, seed=0, two_ports=False, stream=None, **rig_options):
    """Serve a SimulatedRig of ``nominal`` (None: the demo blade) on a pseudo-terminal, print
    the port to give ``--rig serial:...`` and serve until interrupted (Ctrl-C, SIGTERM)."""
    import signal
    from ..cad.load import load_nominal   # cad/ needs FreeCAD; rig/ imports without it
    stream = stream or sys.stdout
    if nominal is None:
        nominal = load_nominal(None)
    device = SimRigDevice(simulated_rig_for(nominal, seed, **rig_options), two_ports=two_ports)
    device.start()
    stream.write("simulated rig (seed %d) on %s\n" % (seed, device.port_url))
    stream.write("scan with: ./bladeinspect scan --rig serial:%s --out DIR\n" % device.port_url)
    stream.flush()
    previous = signal.signal(signal.SIGTERM, signal.default_int_handler)
    try:
        while device._thread.is_alive():
            time.sleep(0.2)
    except KeyboardInterrupt:
        pass
    finally:
        signal.signal(signal.SIGTERM, previous)
        device.stop()
    return 0


def simrig_main(cad_path=None, seed=0):
    """``./bladeinspect simrig [--cad CAD] [--seed S]``: the CAD (None: the demo blade) on
    the simulated rig that ``scan --rig sim --seed S`` uses, so both scan the same points."""
    from ..cad.load import load_nominal   # cad/ needs FreeCAD; rig/ imports without it
    return run_simrig(load_nominal(cad_path), seed=seed)
