"""Pure computation beside an event loop: ``run(fn)`` runs ``fn()`` in a worker thread while
the installed waiter (the GUI's, gui.progress) keeps its event loop turning and its Cancel
answering, or simply calls ``fn()`` when no waiter is installed (the command line, tests).
Work that must stay in the calling thread (it reaches OpenCASCADE) calls ``tick()`` in its
long loops instead: the installed pump turns the event loop there when it is due.

Only work that touches no FreeCAD document, Coin node nor OpenCASCADE shape may be given to
``run``: numpy, scipy, matplotlib on its Agg backend and plain files. Such work calls
``check()`` between its steps, so a job the user cancelled stops at the next step instead of
running on unseen (its result would be dropped anyway).
"""

import threading
from concurrent.futures import ThreadPoolExecutor, wait

from .errors import Cancelled

_WAITER = [None]
_PUMP = [None]
_LOCAL = threading.local()
# The worker of the last run, joined before the next starts: two reports drawing with
# matplotlib's pyplot at once would share its state.
_LAST = [None]
# How often a thread waiting for pool_map's threads lets its event loop turn, s.
TICK_S = 0.05
# How long a new run waits for the last cancelled worker to reach its next check(), s.
JOIN_S = 60.0


def set_waiter(waiter):
    """Install ``waiter(thread, stop)`` (None: none) and return the one it replaces. The waiter
    runs its event loop until ``thread`` ends, or sets the threading.Event ``stop`` and raises
    errors.Cancelled when the user cancels."""
    previous = _WAITER[0]
    _WAITER[0] = waiter
    return previous


def set_pump(pump):
    """Install ``pump()`` (None: none) and return the one it replaces: called by tick() in the
    thread that installed it, it turns the event loop when due and raises errors.Cancelled
    once the user cancelled."""
    previous = _PUMP[0]
    _PUMP[0] = pump
    return previous


def tick():
    """In a long loop: in a worker, check(); in the thread of the event loop, its pump."""
    if getattr(_LOCAL, "stop", None) is not None:
        check()
    elif _PUMP[0] is not None:
        _PUMP[0]()


def check():
    """In work given to run(): raise Cancelled once the user cancelled it."""
    stop = getattr(_LOCAL, "stop", None)
    if stop is not None and stop.is_set():
        raise Cancelled("cancelled")


def run(fn):
    """fn()'s value (or its exception), computed in a worker thread while the waiter turns its
    event loop; without a waiter, in this thread."""
    waiter = _WAITER[0]
    if waiter is None or getattr(_LOCAL, "stop", None) is not None:
        return fn()    # no event loop to keep turning, or already in a worker
    if _LAST[0] is not None:
        _LAST[0].join(JOIN_S)
    outcome = {}
    stop = threading.Event()

    def work():
        _LOCAL.stop = stop
        try:
            outcome["value"] = fn()
        except BaseException as exc:   # handed to the waiting thread, which raises it
            outcome["error"] = exc

    thread = threading.Thread(target=work, name="BladeInspect background", daemon=True)
    _LAST[0] = thread
    thread.start()
    waiter(thread, stop)
    thread.join()
    if "error" in outcome:
        raise outcome["error"]
    return outcome["value"]


def pool_map(work, items, threads):
    """[work(item) for item in items] on ``threads`` threads (numpy releases the GIL in its
    array loops), this thread ticking while it waits for them."""
    with ThreadPoolExecutor(max_workers=threads) as pool:
        futures = [pool.submit(work, item) for item in items]
        try:
            while wait(futures, timeout=TICK_S).not_done:
                tick()
        except BaseException:
            for future in futures:
                future.cancel()
            raise
        return [f.result() for f in futures]
