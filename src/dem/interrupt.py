"""Ctrl-C that is not lost: the command line's SIGINT handler (``catching_interrupts``).

Python runs a signal handler between two bytecodes, wherever the main thread is. An exception
that the handler raises inside a callback which C code calls back into Python (ctypes:
llvmlite's hook that writes a kernel to Numba's cache while the first run compiles it) is
printed as "Exception ignored" (with a traceback) and discarded, and the run would go on to
its end. So the handler also leaves the interrupt pending, and ``Simulation.run`` checks
between its chunks of steps (``raise_pending``): an interrupt lost that way ends the run there,
a few hundred steps later, and what Python would print of it is not printed.
"""

import signal
import sys
import threading

_pending = False


def _on_interrupt(signum, frame):
    """SIGINT handler: leave the interrupt pending, then raise it as Python's own does."""
    global _pending
    _pending = True
    raise KeyboardInterrupt


def raise_pending():
    """Raise KeyboardInterrupt if a SIGINT came (under catching_interrupts) since the last call;
    the interrupt is then no longer pending."""
    global _pending
    if _pending:
        _pending = False
        raise KeyboardInterrupt


class catching_interrupts:
    """Context: SIGINT handled by this module's handler inside it, and a KeyboardInterrupt that
    Python discards while one is pending kept silent (``sys.unraisablehook``; any other
    discarded exception goes to the previous hook); both restored after, nothing pending on
    entry or exit. A process that ignores SIGINT (a command started in the background by a
    shell) keeps ignoring it, and outside the main thread (where Python takes no signal
    handler) nothing changes."""

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
        return self

    def _discarded(self, unraisable):
        if not (_pending and issubclass(unraisable.exc_type, KeyboardInterrupt)):
            self._previous_hook(unraisable)

    def __exit__(self, *exc):
        global _pending
        if self._previous is not None:
            signal.signal(signal.SIGINT, self._previous)
            sys.unraisablehook = self._previous_hook
        _pending = False
        return False
