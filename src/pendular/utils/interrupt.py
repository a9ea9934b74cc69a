"""Ctrl-C that ends a run cleanly: the command line's SIGINT handler (``catching_interrupts``).

Python runs a signal handler between two bytecodes, wherever the main thread is. Raised inside
Numba's compiler (the first run compiles its kernels, later runs load them from Numba's cache),
KeyboardInterrupt can break a kernel half made: llvmlite's ctypes hook that hands Numba a
kernel's object code discards it (Python prints "Exception ignored" and goes on), and the
half-made kernel then fails to be cached ("no compiled object yet", a traceback), or the
interrupt is lost and the run goes on to its end. So while this thread holds Numba's compiler
lock the handler only leaves the interrupt pending, and it is raised as the lock is released,
the kernel whole; anywhere else it is raised at once, as by Python's own handler. An
interrupt that Numba's C dispatcher reports wrapped in a SystemError (it calls Python code
outside the lock too; seen while it loaded a cached kernel, before the deferral) leaves the
context as the KeyboardInterrupt it is.

``deferred_interrupts`` holds Ctrl-C back over a short critical section (writing a run's
results), and ``pause_point`` lets the tests send Ctrl-C at a known phase of a run instead of
racing its speed.
"""

import os
import signal
import sys
import threading
import time

from numba.core import event
from numba.core.compiler_lock import global_compiler_lock

_pending = False
#: Whether an interrupt arrived inside ``deferred_interrupts`` (raised at its end).
_deferred = False
#: Environment variable naming the phase at which a run waits for Ctrl-C (``pause_point``).
PAUSE_VARIABLE = "PENDULAR_TEST_PAUSE_AT"
#: Longest wait at a pause point [s]: a test that never sends its signal still ends.
PAUSE_LIMIT = 600.0


def _on_interrupt(signum, frame):
    """SIGINT handler: KeyboardInterrupt now, or pending while Numba compiles."""
    global _pending
    if global_compiler_lock.is_locked():
        _pending = True
    else:
        raise KeyboardInterrupt


class _AfterCompiling(event.Listener):
    """Numba's compiler-lock events: raises a pending interrupt once the outermost compile
    (or cache load) has released the lock."""

    def on_start(self, started):
        pass

    def on_end(self, ended):
        global _pending
        if _pending and not global_compiler_lock.is_locked():
            _pending = False
            raise KeyboardInterrupt


class catching_interrupts:
    """Context: SIGINT handled by this module's handler inside it (deferred while Numba
    compiles), an interrupt wrapped in a SystemError raised as a KeyboardInterrupt; the
    previous handler restored after, nothing pending on entry or exit. A process that ignores
    SIGINT (a command started in the background by a shell) keeps ignoring it, and outside the
    main thread (where Python takes no signal handler) nothing changes."""

    def __enter__(self):
        global _pending
        _pending = False
        self._previous = None
        if threading.current_thread() is threading.main_thread():
            previous = signal.getsignal(signal.SIGINT)
            if previous is not signal.SIG_IGN:
                self._previous = signal.signal(signal.SIGINT, _on_interrupt)
                self._after_compiling = _AfterCompiling()
                event.register("numba:compiler_lock", self._after_compiling)
        return self

    def __exit__(self, exc_type, error, traceback):
        global _pending
        if self._previous is not None:
            event.unregister("numba:compiler_lock", self._after_compiling)
            signal.signal(signal.SIGINT, self._previous)
        _pending = False
        if isinstance(error, SystemError) and _caused_by_interrupt(error):
            raise KeyboardInterrupt from error
        return False


def _caused_by_interrupt(error):
    """Whether a KeyboardInterrupt is among the causes (or contexts) of ``error``."""
    while error is not None:
        if isinstance(error, KeyboardInterrupt):
            return True
        error = error.__cause__ or error.__context__
    return False


def _on_deferred_interrupt(signum, frame):
    """SIGINT handler inside ``deferred_interrupts``: remembered, raised at its end."""
    global _deferred
    _deferred = True


class deferred_interrupts:
    """Context: a SIGINT that arrives inside it is raised as KeyboardInterrupt at its end, so
    the block (e.g. writing a run's history and summary) is never left half done. Nests; outside
    the main thread, or where SIGINT is ignored, it changes nothing."""

    def __enter__(self):
        global _deferred
        self._previous = None
        if threading.current_thread() is threading.main_thread():
            previous = signal.getsignal(signal.SIGINT)
            if previous is not signal.SIG_IGN and previous is not _on_deferred_interrupt:
                _deferred = False
                self._previous = signal.signal(signal.SIGINT, _on_deferred_interrupt)
        return self

    def __exit__(self, exc_type, error, traceback):
        global _deferred
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            if _deferred:
                _deferred = False
                if exc_type is None:
                    raise KeyboardInterrupt
        return False


def pause_point(phase):
    """Test hook: when the environment variable PENDULAR_TEST_PAUSE_AT names ``phase``, print
    ``paused at PHASE`` on stderr and wait there (at most PAUSE_LIMIT s) until Ctrl-C arrives,
    which is then raised as anywhere else in that phase (held back to the end of a
    ``deferred_interrupts`` block). Elsewhere it does nothing."""
    if os.environ.get(PAUSE_VARIABLE) != phase:
        return
    print(f"paused at {phase}", file=sys.stderr, flush=True)
    waited = time.monotonic()
    while not _deferred and time.monotonic() - waited < PAUSE_LIMIT:
        time.sleep(0.01)


def pausing_at(phase):
    """Whether ``pause_point(phase)`` will wait (the tests' PENDULAR_TEST_PAUSE_AT)."""
    return os.environ.get(PAUSE_VARIABLE) == phase
