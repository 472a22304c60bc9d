"""Serial rig throughput: one pass of K points through SerialRig and the simulated rig on a
pseudo-terminal, checked point for point against the same rig in process.

    scripts/fcpython bench/bench_serial.py \
        [--points 100000] [--two-ports] [--process] [--rx-buffer 1024]

--process serves the device from a second process (as `./bladeinspect simrig` does) instead of
a thread sharing the interpreter lock with the driver. The rig is a stand-in whose readings
depend on every coordinate (tests/serial_support.py), so the figure is the protocol's cost,
not the ray casting's.
"""
import argparse
import os
import subprocess
import sys
import time

import numpy as np

REPO = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, REPO)

from BladeInspect.rig.serial_rig import SerialRig          # noqa: E402
from BladeInspect.rig.simrig_device import SimRigDevice    # noqa: E402
from tests.serial_support import FakeSimulatedRig, section_path   # noqa: E402

SERVE = """
import sys, time
sys.path.insert(0, %r)
from BladeInspect.rig.simrig_device import SimRigDevice
from tests.serial_support import FakeSimulatedRig
device = SimRigDevice(FakeSimulatedRig(seed=1), two_ports=%r, rx_buffer=%d).start()
print(device.port_url, flush=True)
sys.stdin.read()
device.stop()
"""


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("--points", type=int, default=100000)
    parser.add_argument("--two-ports", action="store_true")
    parser.add_argument("--process", action="store_true")
    parser.add_argument("--rx-buffer", type=int, default=1024,
                        help="controller receive buffer: 128 GRBL 1.1, 1024 grblHAL")
    args = parser.parse_args()
    if args.process:
        server = subprocess.Popen([os.path.join(REPO, "scripts", "fcpython"), "-c", SERVE % (REPO, args.two_ports, args.rx_buffer)],
                                  stdin=subprocess.PIPE, stdout=subprocess.PIPE, text=True)
        url = server.stdout.readline().strip()
    else:
        device = SimRigDevice(FakeSimulatedRig(seed=1), two_ports=args.two_ports,
                              rx_buffer=args.rx_buffer).start()
        url = device.port_url
    rig = SerialRig(url)
    rig.home()
    path = section_path(np.random.default_rng(0), args.points)
    start = time.monotonic()
    readings = rig.scan_path(path, 30.0)
    wall = time.monotonic() - start
    rig.close()
    if args.process:
        server.stdin.close()
        server.wait()
    else:
        device.stop()
    expected = FakeSimulatedRig(seed=1).scan_path(path, 30.0)
    same = (np.array_equal(readings.reading_mm, expected.reading_mm, equal_nan=True)
            and np.array_equal(readings.snr, expected.snr))
    print("%d points over %s (%s, %d-byte buffer, device in a %s): %.2f s wall, %.0f points/s, "
          "identical to in process: %s" % (args.points, url, "two ports" if args.two_ports
                                          else "one port", rig.rx_buffer, "process" if args.process
                                          else "thread", wall, args.points / wall, same))


if __name__ == "__main__":
    main()
