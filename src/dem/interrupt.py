"""Ctrl-C that ends a run cleanly: the command line's SIGINT handler (``catching_interrupts``).

Python runs a signal handler between two bytecodes, wherever the main thread is. Raised inside
Numba's compiler (the first run compiles its kernels, later runs load them from Numba's cache),
KeyboardInterrupt can break a kernel half made: llvmlite's ctypes hook that hands Numba a
kernel's object code discards it (Python prints "Exception ignored" and goes on), and the
half-made kernel then fails to be cached ("no compiled object yet", a traceback) or crashes the
process as it exits (segmentation fault). So while this thread holds Numba's compiler lock the
handler only leaves the interrupt pending, and it is raised as the lock is released, the kernel
whole. An interrupt that Python discards elsewhere (any other callback from C) also stays
pending, silently, and ``Simulation.run`` raises it between its chunks of steps
(``raise_pending``).
"""

import signal
import sys
import threading

from numba.core import event
from numba.core.compiler_lock import global_compiler_lock

_pending = False


def _on_interrupt(signum, frame):
    """SIGINT handler: leave the interrupt pending and, unless Numba compiles, raise it as
    Python's own handler does."""
    global _pending
    _pending = True
    if not global_compiler_lock.is_locked():
        raise KeyboardInterrupt


def raise_pending():
    """Raise KeyboardInterrupt if a SIGINT came (under catching_interrupts) since the last call;
    the interrupt is then no longer pending."""
    global _pending
    if _pending:
        _pending = False
        raise KeyboardInterrupt


class _AfterCompiling(event.Listener):
    """Numba's compiler-lock events: raises a pending interrupt once the outermost compile
    (or cache load) has released the lock."""

    def on_start(self, event):
        pass

    def on_end(self, event):
        if not global_compiler_lock.is_locked():
            raise_pending()


class catching_interrupts:
    """Context: SIGINT handled by this module's handler inside it (deferred while Numba
    compiles), and a KeyboardInterrupt that Python discards while one is pending kept silent
    (``sys.unraisablehook``; any other discarded exception goes to the previous hook); both
    restored after, nothing pending on entry or exit. A process that ignores SIGINT (a command
    started in the background by a shell) keeps ignoring it, and outside the main thread (where
    Python takes no signal handler) nothing changes."""

    def __enter__(self):
        global _pending
        _pending = False
        self._previous = None
        if threading.current_thread() is threading.main_thread():
            previous = signal.getsignal(signal.SIGINT)
            if previous is not signal.SIG_IGN:
                self._previous = signal.signal(signal.SIGINT, _on_interrupt)
                self._previous_hook = sys.unraisablehook
                sys.unraisablehook = self._discarded
                self._after_compiling = _AfterCompiling()
                event.register("numba:compiler_lock", self._after_compiling)
        return self

    def _discarded(self, unraisable):
        if not (_pending and issubclass(unraisable.exc_type, KeyboardInterrupt)):
            self._previous_hook(unraisable)

    def __exit__(self, *exc):
        global _pending
        if self._previous is not None:
            event.unregister("numba:compiler_lock", self._after_compiling)
            signal.signal(signal.SIGINT, self._previous)
            sys.unraisablehook = self._previous_hook
        _pending = False
        return False
