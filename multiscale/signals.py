"""Python's signal handlers kept where libraries take them.

Python ignores SIGPIPE (a write into a closed pipe raises ``BrokenPipeError``) and the command line
turns SIGTERM and SIGHUP into Ctrl-Cs (``io.CtrlCWatch``, ``io.StepStop``). Two libraries replace
those handlers at the C level when they start: gmsh's ``initialize`` sets SIGPIPE, SIGTERM and
SIGHUP to the default (a run piped into ``head`` ended with status 141, its files half written; a
run sent SIGTERM ended without a word), PETSc's initialisation installs its own for SIGTERM and
SIGHUP (and SIGPIPE: "Caught signal number 15", then ``MPI_Abort``; measured by ``sigaction``
2026-12-05). ``keep_python_handlers`` is called right after each.
"""
from __future__ import annotations

import signal
import threading

TERMINATING = (signal.SIGTERM, signal.SIGHUP)     # signals that end a run as Ctrl-C does
KEPT = ("SIGPIPE", "SIGTERM", "SIGHUP")


def keep_python_handlers() -> None:
    """Put Python's own handlers of ``KEPT`` back at the C level (main thread only; elsewhere
    Python cannot set handlers)."""
    if threading.current_thread() is not threading.main_thread():
        return
    for name in KEPT:
        if hasattr(signal, name):
            kind = getattr(signal, name)
            signal.signal(kind, signal.getsignal(kind))
