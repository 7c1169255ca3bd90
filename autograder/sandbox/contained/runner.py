"""How a student's program is run, once contained: as ``python SCRIPT ARGS...`` runs it,
with two differences, both against one fault of Jazzy's ``MultiThreadedExecutor`` (rclpy
7.1.6, the PyPI wheel), which spins while a callback it handed to a worker thread has not
started (why and what was measured: docs/contributors/design.md, "How a hold looks, and
the GIL", and "A MultiThreadedExecutor that does not spin"):

* the interpreter's thread switch interval (:data:`SWITCH_INTERVAL`) is shorter, so the
  worker gets the GIL sooner; a program with one Python thread never notices;
* while a subscription's message waits for a worker, the executor does not wait on that
  subscription's QoS event handlers (:func:`calm_executors`). They share the reader's
  status condition with its data, so with them in the wait set every wait returned at once
  until a worker took the message. Every callback runs as before; a QoS event of that
  subscription (incompatible QoS, a lost message) is heard once its message is taken.

The zygote calls :func:`run_program` in its forked child; a program that is exec'd runs
this module's source through ``python -c`` (:func:`command`), since the student's user may
not be able to read this package.  So this module uses the standard library only.
"""

from __future__ import annotations

import contextlib
import functools
import importlib.abc
import importlib.machinery
import importlib.util
import os
import signal
import sys
import threading
import types
from collections.abc import Iterator, Sequence

SWITCH_INTERVAL = 0.0005
"""Seconds a thread may hold the GIL while another waits (CPython's default: 0.005)."""


def run_program(script: str, args: list[str]) -> None:
    """Run ``script`` as ``python script args...`` runs it: as ``__main__``, its folder first
    on the module path.  A KeyboardInterrupt ends it as CPython ends one (traceback, then
    death by SIGINT once threads and exit handlers are done); any other exception prints
    its traceback (the student's frames only) and exits with status 1."""
    sys.setswitchinterval(SWITCH_INTERVAL)
    calm_executors()
    fresh_signals()
    sys.argv = [script, *args]
    sys.path[0] = os.path.dirname(script)
    main = types.ModuleType("__main__")
    main.__file__ = script
    main.__builtins__ = __builtins__  # type: ignore[attr-defined]
    sys.modules["__main__"] = main
    try:
        with open(script, "rb") as source:
            code = compile(source.read(), script, "exec")
        exec(code, main.__dict__)  # running the student's program is the point
    except SystemExit:
        raise
    except BaseException as exc:  # reported as the interpreter would
        tb = exc.__traceback__.tb_next if exc.__traceback__ is not None else None
        sys.excepthook(type(exc), exc.with_traceback(tb), tb)
        if not isinstance(exc, KeyboardInterrupt):
            sys.exit(1)
        _exit_by_sigint()


def calm_executors() -> None:
    """Leave a subscription's QoS event handlers out of ``Node.waitables`` (what every rclpy
    executor waits on) while a handler of that subscription is made and not yet started:
    now if ``rclpy.node`` is imported (the zygote imported it), else when it is."""
    module = sys.modules.get("rclpy.node")
    if module is not None:
        _hold_back_pending_events(module)
    else:
        sys.meta_path.insert(0, _PatchOnImport())


def _hold_back_pending_events(module: types.ModuleType) -> None:
    node_class = getattr(module, "Node", None)
    listed = getattr(node_class, "waitables", None)
    if not isinstance(listed, property) or listed.fget is None:
        return  # not the rclpy this was written for: leave it as it is
    if getattr(listed.fget, "held_back", False):
        return
    every = listed.fget

    def waitables(node: object) -> Iterator[object]:
        pending = {id(handler)
                   for subscription in getattr(node, "subscriptions", ())
                   if getattr(subscription, "_executor_event", False)
                   for handler in getattr(subscription, "event_handlers", ())}
        for waitable in every(node):
            if id(waitable) not in pending:
                yield waitable

    waitables.held_back = True  # type: ignore[attr-defined]
    waitables.__doc__ = every.__doc__
    node_class.waitables = property(waitables)  # type: ignore[union-attr]


class _PatchOnImport(importlib.abc.MetaPathFinder):
    """Finds nothing itself: when ``rclpy.node`` is imported, has it patched once run."""

    def find_spec(self, fullname: str, path: Sequence[str] | None,
                  target: types.ModuleType | None = None) -> importlib.machinery.ModuleSpec | None:
        if fullname != "rclpy.node":
            return None
        with contextlib.suppress(ValueError):
            sys.meta_path.remove(self)
        spec = importlib.util.find_spec(fullname)
        loader = spec.loader if spec is not None else None
        if loader is None or not hasattr(loader, "exec_module"):
            return spec
        run = loader.exec_module

        def exec_module(module: types.ModuleType) -> None:
            run(module)
            _hold_back_pending_events(module)

        loader.exec_module = exec_module  # type: ignore[method-assign]
        return spec


def fresh_signals() -> None:
    """The signals as ``python script.py`` from a terminal has them, whoever started the
    grader: none blocked, SIGINT raising KeyboardInterrupt, SIGPIPE and SIGXFSZ ignored
    (CPython's own start-up), every other one at its default. A grader started in the background
    (``cmd &``, some CI runners) has SIGINT ignored, and fork and exec pass that on: the
    student's node then never saw its Ctrl-C and lost the shutdown tests."""
    signal.pthread_sigmask(signal.SIG_SETMASK, [])
    for number in signal.valid_signals():
        if number in (signal.SIGKILL, signal.SIGSTOP):
            continue
        with contextlib.suppress(OSError, ValueError):
            signal.signal(number, signal.SIG_DFL)
    signal.signal(signal.SIGINT, signal.default_int_handler)
    signal.signal(signal.SIGPIPE, signal.SIG_IGN)
    signal.signal(signal.SIGXFSZ, signal.SIG_IGN)


def _exit_by_sigint() -> None:
    threading._shutdown()  # type: ignore[attr-defined]  # what Py_Finalize does first
    import atexit

    atexit._run_exitfuncs()
    for stream in (sys.stdout, sys.stderr):
        with contextlib.suppress(Exception):
            stream.flush()
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    os.kill(os.getpid(), signal.SIGINT)
    os._exit(128 + signal.SIGINT)


@functools.cache
def _program() -> str:
    """This module's source and a call of :func:`run_program` (read once per grader)."""
    with open(__file__, encoding="utf-8") as source:
        return f"{source.read()}\nrun_program(sys.argv[1], sys.argv[2:])\n"


def command(python: str, script: str, args: list[str]) -> list[str]:
    """The command that runs ``script`` with ``args`` through :func:`run_program`."""
    return [python, "-c", _program(), script, *args]
