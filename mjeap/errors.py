"""Errors raised by mjeap: each names the parameter and what would have been accepted."""
from __future__ import annotations

import difflib
import re
import sys
from typing import Iterable, Optional


def printable(text) -> str:
    """``text`` safe to print on a terminal: its control and format characters (escape
    sequences, carriage returns, bidirectional overrides; a title in a user's file can hold
    any) written as Python escapes (``\\x1b``, ``\\n``, ``\\u202e``), everything else as it is."""
    import unicodedata
    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() or c == " " else
                   (repr(c)[1:-1] if unicodedata.category(c) in ("Cc", "Cf", "Zl", "Zp", "Cs", "Co", "Cn")
                    else c) for c in text)


class MjeapError(Exception):
    """Base class of mjeap's own errors."""


class OutputError(MjeapError, OSError):
    """An output (recording, CSV) could not be written: ``cannot write PATH: reason``. The
    finished result rides along as ``result`` where there is one."""

    def __init__(self, failures, result=None):
        self.failures, self.result = list(failures), result
        super().__init__("; ".join(f"cannot write {p}: {why}" for p, why in self.failures))


class ParameterError(MjeapError, ValueError):
    """A parameter is outside its accepted range.

    The message always names the parameter, the value given and the range accepted.
    """

    def __init__(self, name: str, value, accepted: str, why: str = ""):
        self.name, self.value, self.accepted, self.why = name, value, accepted, why
        msg = f"{name}={value!r} is not accepted: expected {accepted}"
        if why:
            msg += f" ({why})"
        super().__init__(msg)


class UnknownNameError(MjeapError, KeyError):
    """A name (actuator, drive, waveform) is not registered; suggests the closest ones."""

    def __init__(self, kind: str, name: str, known: Iterable[str]):
        known = sorted(known)
        close = difflib.get_close_matches(name, known, n=3, cutoff=0.4)
        msg = f"unknown {kind} {name!r}"
        if close:
            msg += f"; did you mean {', '.join(repr(c) for c in close)}?"
        msg += f" Known: {', '.join(known)}"
        self.kind, self.name, self.known, self.suggestions = kind, name, known, close
        super().__init__(msg)

    def __str__(self) -> str:  # KeyError quotes its message otherwise
        return self.args[0]


class DivergenceError(MjeapError, RuntimeError):
    """The simulation became unstable; the message says at which step and why."""


def check_positive(name: str, value: float, unit: str = "") -> float:
    """Return ``float(value)`` if it is finite and > 0, else raise ParameterError."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, f"a positive number{(' in ' + unit) if unit else ''}") from None
    if not (v > 0 and v < float("inf")):
        raise ParameterError(name, value, f"a finite number > 0{(' ' + unit) if unit else ''}")
    return v


def check_range(name: str, value: float, lo: float, hi: float, unit: str = "",
                lo_open: bool = False, hi_open: bool = False) -> float:
    """Return ``float(value)`` if it lies in the interval, else raise ParameterError."""
    interval = f"{'(' if lo_open else '['}{lo:.6g}, {hi:.6g}{')' if hi_open else ']'}"
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ParameterError(name, value, f"a number in {interval}{(' ' + unit) if unit else ''}") from None
    ok_lo = v > lo if lo_open else v >= lo
    ok_hi = v < hi if hi_open else v <= hi
    if not (ok_lo and ok_hi) or v != v:
        raise ParameterError(name, value, f"a value in {interval}{(' ' + unit) if unit else ''}")
    return v


def check_integer(name: str, value, lo: int, hi: Optional[int] = None, why: str = "") -> int:
    """Return ``int(value)`` if it is a whole number in [lo, hi] (hi None: no upper bound),
    else raise ParameterError naming the range (a bool, 2.5 or '2.5' is refused)."""
    accepted = f"an integer in [{lo}, {hi}]" if hi is not None else f"an integer >= {lo}"
    try:
        v = value if isinstance(value, (int, float)) else float(str(value).strip())
        ok = not isinstance(value, bool) and float(v) == int(v)
    except (TypeError, ValueError, OverflowError):
        ok = False
    if not ok or int(v) < lo or (hi is not None and int(v) > hi):
        raise ParameterError(name, value, accepted, why)
    return int(v)


class Terminated(KeyboardInterrupt):
    """SIGTERM, turned into the same clean stop as Ctrl-C (what was finished is written)."""


def in_c_callback(frame) -> bool:
    """Whether ``frame`` (a signal handler's) runs within a Python callback that MuJoCo's C
    code called (:func:`_mujoco_warning`): an exception raised there cannot cross the C
    frames below it, and the C++ runtime aborts the process (SIGABRT, or a segfault)."""
    while frame is not None:
        if frame.f_code is _mujoco_warning.__code__:
            return True
        frame = frame.f_back
    return False


def _again_soon(signum: int) -> None:
    """Deliver ``signum`` to this process again in a moment, from a helper thread (by then
    MuJoCo's C code has returned)."""
    import os
    import threading
    t = threading.Timer(0.002, os.kill, (os.getpid(), signum))
    t.daemon = True
    t.start()


def interrupt_handler(exc_type):
    """A signal handler raising ``exc_type()`` (a KeyboardInterrupt) in the main thread, but
    never within a callback MuJoCo's C code runs (:func:`in_c_callback`): there the signal
    is delivered again a moment later, once the C code has returned. The one cause of the
    crashes of a stopped run (SIGTERM or Ctrl-C while MuJoCo reported a warning)."""
    def handler(signum, frame):
        if in_c_callback(frame):
            _again_soon(signum)
            return
        raise exc_type()
    handler.mjeap = True
    return handler


class sigterm_as_interrupt:
    """Context manager: within it (in the main thread) SIGTERM raises :class:`Terminated`,
    a KeyboardInterrupt, so a run or a sweep ends as after Ctrl-C; Ctrl-C (where Python's
    default handler has it) raises KeyboardInterrupt as before. Neither raises within a
    callback that MuJoCo's C code runs (:func:`interrupt_handler`). The previous handlers
    are restored on exit. Elsewhere (another thread, or a pool worker whose parent stops it:
    ``in_pool_worker``, set by :func:`mjeap.studies.sweep.worker_signals`) it does nothing: a
    worker asked to stop by its parent stops at once, it does not finish its point (nor
    hold its task queue's lock while the parent waits for it)."""

    #: True in a process-pool worker (SIGTERM keeps its default action there)
    in_pool_worker = False

    def __enter__(self):
        import signal
        import threading
        self._old = {}
        if threading.current_thread() is threading.main_thread() and not sigterm_as_interrupt.in_pool_worker:
            self._old[signal.SIGTERM] = signal.signal(signal.SIGTERM, interrupt_handler(Terminated))
            if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
                self._old[signal.SIGINT] = signal.signal(signal.SIGINT, interrupt_handler(KeyboardInterrupt))
        return self

    def __exit__(self, *exc):
        import signal
        for s, h in self._old.items():
            signal.signal(s, h)
        return False


def _mujoco_warning(message: str) -> None:
    """MuJoCo's warnings as Python warnings (not stderr and a MUJOCO_LOG.TXT in the working
    directory); its times are in the model's internal units (ms by default). MuJoCo's C
    code calls it: nothing may raise here (the process would abort), a signal's handler
    included (:func:`interrupt_handler`); a warning turned into an error is dropped."""
    import warnings
    try:
        warnings.warn(f"MuJoCo: {message.strip()} (times in the model's internal units; mjeap's default unit is "
                      "1 ms)", RuntimeWarning, stacklevel=2)
    except Exception:  # noqa: BLE001 - '-W error': an exception cannot cross MuJoCo's C frames
        pass
    except KeyboardInterrupt as e:       # a handler not mjeap's raised here: the signal again once C returned
        import signal
        _again_soon(signal.SIGTERM if isinstance(e, Terminated) else signal.SIGINT)


def install_mujoco_warnings() -> None:
    """Route MuJoCo's warnings through :func:`_mujoco_warning` (again after a library such
    as dm_control installed its own handler)."""
    import mujoco
    mujoco.set_mju_user_warning(_mujoco_warning)


# ---------------------------------------------------------------- registries (plug-ins)
#: a registered name: letters, digits, '-' and '_' (a command-line choice, a CSV column)
_PLUGIN_NAME = re.compile(r"[A-Za-z0-9_-]+")


def describe_plugin(entry) -> str:
    """``entry`` in words for a refusal: 'class X', 'function f', 'X instance'."""
    if isinstance(entry, type):
        return f"class {entry.__qualname__}"
    if hasattr(entry, "__qualname__"):
        return f"function {entry.__qualname__}"
    return f"{type(entry).__qualname__} instance"


def plugin_origin(entry) -> Optional[str]:
    """Where ``entry`` was defined: module.qualname of a class or function, or of an
    instance's class; None where that does not tell one definition from another (a lambda,
    an instance of a built-in type such as ``functools.partial``). A module run as
    ``python -m`` counts as the module it is."""
    obj = entry if hasattr(entry, "__qualname__") else type(entry)
    module = getattr(obj, "__module__", None)
    if "<lambda>" in obj.__qualname__ or (module in (None, "builtins", "functools") and obj is not entry):
        return None
    if module == "__main__":
        module = getattr(getattr(sys.modules.get("__main__"), "__spec__", None), "name", None) or module
    return f"{module}.{obj.__qualname__}"


def check_registration(kind: str, registry, name, entry, *, lacks: Optional[str] = None, expected: str = "",
                       reserved: Iterable[str] = (), replace: bool = False, how: str = "register",
                       origin=plugin_origin) -> str:
    """The one check of every registry (engines, drives, beam builders, robots, sweep
    metrics); returns ``name``. A ParameterError naming the ``kind`` and the entry where:

    * it ``lacks`` something the registry needs (the reason, in words; ``expected``: what
      it should be);
    * ``name`` is not a non-empty str of letters, digits, '-' and '_', or is ``reserved``;
    * ``name`` is taken, unless ``replace`` (``how(..., replace=True)``) or the entry there
      has the same ``origin`` (the same definition: a module re-imported or reloaded
      registers again)."""
    given = describe_plugin(entry) + (f" named {name!r}" if isinstance(name, str) and name else "")
    if lacks is not None:
        raise ParameterError(kind, given, expected, lacks)
    reserved = tuple(reserved)
    if not isinstance(name, str) or not _PLUGIN_NAME.fullmatch(name) or name in reserved:
        raise ParameterError(f"{kind} name", name, "a non-empty str of letters, digits, '-' and '_'"
                             + (f", not {', '.join(map(repr, reserved))}" if reserved else ""),
                             f"{how} given {describe_plugin(entry)}")
    old = registry.get(name)
    if old is not None and old is not entry and not replace:
        was = origin(old)
        if was is None or was != origin(entry):
            raise ParameterError(f"{kind} name", name, f"a name not registered yet (taken: {', '.join(registry)}), "
                                 f"or {how}(..., replace=True) to replace the {kind} {name!r}",
                                 f"{name!r} is already {was or describe_plugin(old)}; {how} given "
                                 f"{describe_plugin(entry)}")
    return name
