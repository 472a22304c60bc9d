"""core.background: work beside an event loop, its cancel, and plain calls without one."""
import threading
import time
import unittest

from BladeInspect.core import background
from BladeInspect.core.errors import Cancelled


class Waiter:
    """A stand-in for the GUI's waiter: counts its turns; cancels after ``cancel_after`` s."""

    def __init__(self, cancel_after=None):
        self.turns = 0
        self.cancel_after = cancel_after

    def __call__(self, thread, stop):
        t0 = time.perf_counter()
        while thread.is_alive():
            self.turns += 1
            if self.cancel_after is not None and time.perf_counter() - t0 > self.cancel_after:
                stop.set()
                thread.join(0.3)
                raise Cancelled("cancelled")
            thread.join(0.01)


class TestBackground(unittest.TestCase):
    def tearDown(self):
        background.set_waiter(None)
        background.set_pump(None)

    def test_without_a_waiter_the_work_runs_here(self):
        self.assertIsNone(background.set_waiter(None))
        self.assertEqual(background.run(lambda: threading.current_thread().name),
                         threading.current_thread().name)
        background.tick()    # no pump: nothing happens
        background.check()   # not in a worker: nothing happens

    def test_with_a_waiter_the_work_runs_beside_it(self):
        waiter = Waiter()
        background.set_waiter(waiter)
        here = threading.current_thread()
        value = background.run(lambda: (time.sleep(0.2), threading.current_thread())[1])
        self.assertIsNot(value, here)
        self.assertGreater(waiter.turns, 5, "the waiter must turn while the work runs")

    def test_an_error_of_the_work_reaches_the_caller(self):
        background.set_waiter(Waiter())

        def fail():
            raise ValueError("bad")
        with self.assertRaisesRegex(ValueError, "bad"):
            background.run(fail)

    def test_cancel_stops_the_work_at_its_next_check(self):
        background.set_waiter(Waiter(cancel_after=0.1))
        steps = []

        def work():
            for i in range(200):
                background.check()
                steps.append(i)
                time.sleep(0.01)
        t0 = time.perf_counter()
        with self.assertRaises(Cancelled):
            background.run(work)
        self.assertLess(time.perf_counter() - t0, 1.0)
        time.sleep(0.1)
        n = len(steps)
        time.sleep(0.1)
        self.assertEqual(len(steps), n, "the worker must stop at its next check")
        self.assertLess(n, 200)

    def test_tick_calls_the_pump_and_a_worker_checks(self):
        calls = []
        background.set_pump(lambda: calls.append(1))
        background.tick()
        self.assertEqual(calls, [1])
        background.set_waiter(Waiter())
        background.run(background.tick)   # in a worker: check(), not the pump
        self.assertEqual(calls, [1])

    def test_pool_map_keeps_order_and_ticks(self):
        ticks = []
        background.set_pump(lambda: ticks.append(1))
        out = background.pool_map(lambda x: (time.sleep(0.05 * (x % 3)), x * x)[1],
                                  list(range(12)), 2)
        self.assertEqual(out, [x * x for x in range(12)])
        self.assertTrue(ticks, "waiting for the threads, the caller ticks")


if __name__ == "__main__":
    unittest.main()
