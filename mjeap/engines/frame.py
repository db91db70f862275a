"""The stepping frame every engine shares (:mod:`mjeap.engines`): the run's work and
sampling checked before it starts, the voltage history, the sample store of one actuator
(its SI result a :class:`mjeap.engines.result.RolloutResult`, re-exported here) and
:func:`lockstep`, the loop that steps a model from Python.

A sample copies MuJoCo's raw world positions and the drive's signals; the SI read-outs
(clamp frame, tip angle, arc curvature) are computed for all samples at once at the end.
"""
from __future__ import annotations

import math
from typing import Callable, Dict, Optional

import mujoco
import numpy as np

from ..model.analytical import arc_curvature
from ..errors import ParameterError, check_range
from ..drives.waveforms import Waveform, parse_waveform
from .result import RolloutResult

__all__ = ["RolloutResult", "Decided", "Samples", "MAX_STEPS", "DEFAULT_SAMPLES", "check_work", "check_sampling",
           "voltage_steps", "to_waveform", "one_voltage", "check_initial_curvature", "sample_steps", "lockstep",
           "CONTROLLER_CONTRACT", "check_controller", "controller_every", "reset_controller"]

#: at most this many samples are kept per rollout unless sample_interval is given
DEFAULT_SAMPLES = 5000


class Decided(Exception):
    """A run's outcome is decided at a sample: ``reason`` (words), ``time`` (s); the
    engines add ``step`` and ``state`` (their full physics state there, when they roll out
    ahead)."""

    def __init__(self, reason: str, time: float):
        super().__init__(reason)
        self.reason, self.time = reason, time
        self.step, self.state = None, None


class Samples:
    """Preallocated sample arrays of one rollout of one actuator (an
    :class:`~mjeap.simulation.part.ActuatorPart`). A sample copies MuJoCo's raw world positions
    (clamp, links, payload, tip site), the tip's orientation (and the clamp's, where the
    clamp can move) and the drive's signals; the clamp-frame SI read-outs (the part's
    clamp_frame and in_plane_angle, as its own read-outs use) are computed for all samples
    at once at the end, so a sample costs a few copies."""

    def __init__(self, part, ns: int):
        self.part, self.ns = part, ns
        N = part.layout.segments
        # raw world points per sample: clamp, the N link origins, the tip site, the payload
        self._bodies = np.r_[part.clamp_id, part.link_ids].astype(np.intp)
        self._raw = np.empty((ns, N + 2 + (part.payload_id >= 0), 3))
        self._xmat = np.empty((ns, 9))
        self._moving = part.clamp_moves
        self._clamp_xmat = np.empty((ns, 9)) if self._moving else None
        self.t, self.v = np.empty(ns), np.empty(ns)
        self.sig: Dict[str, np.ndarray] = {}
        self.n = 0                                  # samples taken
        #: called with this store after every sample; may raise a decision to stop the run
        #: (:class:`mjeap.simulation.periodic.PeriodicStop`)
        self.stop = None

    def planned_arrays(self) -> dict:
        """What a run fills, by name: (array, the shape planned for it): times, voltages,
        raw positions (clamp, links, tip[, payload]), tip orientations and, where the clamp
        moves, the clamp's."""
        points = self._bodies.size + 1 + (self.part.payload_id >= 0)       # clamp, links, tip[, payload]
        out = {"times": (self.t, (self.ns,)), "voltages": (self.v, (self.ns,)),
               "positions": (self._raw, (self.ns, points, 3)), "orientations": (self._xmat, (self.ns, 9))}
        if self._clamp_xmat is not None:
            out["clamp orientations"] = (self._clamp_xmat, (self.ns, 9))
        return out

    def _put(self, key, i, value):
        if key not in self.sig:
            self.sig[key] = np.full(self.ns, np.nan)
        self.sig[key][i] = value

    def take(self, t: float, v: float, signals: Dict[str, float], controller=None) -> None:
        """Sample the state after the step that ended at ``t`` s (kinematics up to date),
        ``v`` the voltage held over that step (the first sample: the first step's), the
        instant the drive's ``signals`` describe."""
        p, i = self.part, self.n
        d = p.data
        self.t[i], self.v[i] = t, v
        raw, N = self._raw[i], p.layout.segments
        np.take(d.xpos, self._bodies, axis=0, out=raw[:N + 1], mode="clip")
        raw[N + 1] = d.site_xpos[p.tip_site_id]
        if p.payload_id >= 0:
            raw[N + 2] = d.xpos[p.payload_id]
        self._xmat[i] = d.xmat[p.tip_body_id]
        if self._moving:
            self._clamp_xmat[i] = d.xmat[p.clamp_id]
        for k, x in signals.items():
            self._put(k, i, x)
        if controller is not None and hasattr(controller, "signals"):
            for k, x in controller.signals().items():
                self._put(f"controller_{k}", i, x)
        self.n += 1
        if self.stop is not None:
            self.stop(self)

    def take_all(self, t: np.ndarray, v: np.ndarray, raw: np.ndarray, xmat: np.ndarray,
                 signals: Dict[str, np.ndarray]) -> None:
        """All samples at once, as :meth:`take` would have taken them one by one: times (s),
        voltages, MuJoCo's raw world points (n, clamp + links + tip site [+ payload], 3),
        the tip body's flattened orientations (n, 9) and the drive's signals (a fixed clamp
        only)."""
        if self._moving:
            raise ValueError("take_all needs a fixed clamp")
        n = len(t)
        self.t[:n], self.v[:n], self._raw[:n], self._xmat[:n] = t, v, raw, xmat
        self.sig = {k: np.asarray(x, float)[:n] for k, x in signals.items()}
        self.n = n

    def clamp_frame(self, idx: np.ndarray):
        """Clamp-frame points (m; clamp, hinges, tip[, payload]) and tip angles (rad) of the
        samples ``idx`` taken so far (copies; the store is left as it is)."""
        raw = self._raw[idx] - self._raw[idx, :1]
        return self._to_clamp(raw, self._xmat[idx], None if self._clamp_xmat is None else self._clamp_xmat[idx])

    def _to_clamp(self, raw: np.ndarray, xmat: np.ndarray, clamp_xmat=None):
        """Clamp-frame points (m) and tip angles (rad) of raw samples (the first ones, or
        those whose clamp orientations are ``clamp_xmat``)."""
        p = self.part
        if not self._moving:
            return p.clamp_frame(raw), p.in_plane_angle(xmat)
        R = (self._clamp_xmat[:len(raw)] if clamp_xmat is None else clamp_xmat).reshape(-1, 3, 3)
        pts = np.einsum("n...j,njk->n...k", raw, R) * p.units.length
        rel = np.einsum("nji,njk->nik", R, xmat.reshape(-1, 3, 3))
        return pts, np.arctan2(rel[:, 1, 0], rel[:, 0, 0])

    def result(self, drive, initial_curvature: float, meta: dict) -> RolloutResult:
        """The SI result; called once, at the end (it works on the raw arrays in place)."""
        n, p = self.n, self.part
        N = p.layout.segments
        raw = self._raw[:n]
        raw -= raw[:, :1].copy()                    # relative to the clamp (in place)
        pts, ang = self._to_clamp(raw, self._xmat[:n])
        cl = pts[:, :N + 2]                         # clamp, hinges, tip
        tip = cl[:, -1].copy()                      # the centreline ends at the tip point
        kap = arc_curvature(tip[:, 0], tip[:, 1])
        pay = pts[:, N + 2] if p.payload_id >= 0 else None
        ref = drive.reference_curvature(self.t[:n], self.v[:n], initial_curvature) \
            if (n > 1 and drive is not None) else None
        return RolloutResult(self.t[:n], self.v[:n], tip, ang, kap, cl, pay,
                             {k: x[:n] for k, x in self.sig.items()}, ref, meta)


#: runs of more steps are refused unless ``max_steps`` is raised (the voltage history alone
#: takes 8 bytes a step; at ~10-30 us a step this is minutes of work)
MAX_STEPS = 20_000_000
#: a waveform whose energy above the step's Nyquist frequency exceeds this fraction is refused
ALIASED_ENERGY = 1e-3


def check_work(duration: float, dt: float, max_steps: Optional[int] = None) -> int:
    """The number of steps of a run, refused before any work where the duration is shorter
    than one timestep or the steps exceed ``max_steps`` (default MAX_STEPS)."""
    limit = MAX_STEPS if max_steps is None else int(max_steps)
    if duration < dt:
        raise ParameterError("duration", f"{duration:g} s", f"at least one timestep ({dt:.4g} s)")
    n = int(round(duration / dt))
    if n > limit:
        raise ParameterError("duration", f"{duration:g} s", f"at most {limit:,} steps of {dt:.4g} s "
                             f"({limit * dt:.4g} s); this run needs {n:,} steps and {8 * n / 2**20:.0f} MiB for its "
                             "voltage history alone. Raise max_steps (--max-steps) to run it")
    return n


#: what to change when a waveform is above the step's Nyquist frequency, by who owns the step
SCENE_TIMESTEP = "pass a smaller timestep to the Scene (Scene(..., timestep=...), --timestep)"


def check_sampling(wave, dt: float, remedy: str = SCENE_TIMESTEP) -> None:
    """Refuse a waveform whose content the step cannot represent: a frequency at or above
    the Nyquist frequency 1/(2 dt) (a sine of 13 kHz at dt = 77 us runs as an aliased
    38 Hz one), or csv samples with more than ALIASED_ENERGY of their energy above it.
    ``remedy``: what to change, in words (the Scene's timestep, or a System's)."""
    if not isinstance(wave, Waveform):
        return
    f_n = 0.5 / dt
    above = wave.content_above(f_n)
    if above > (ALIASED_ENERGY if wave.kind == "csv" else 0.0):
        what = (f"{above:.1%} of the csv signal's energy lies above" if wave.kind == "csv"
                else f"frequency {wave.max_frequency:g} Hz is at or above")
        raise ParameterError("voltage", getattr(wave, "text", str(wave)),
                             f"content below the Nyquist frequency {f_n:.4g} Hz of the timestep {dt:.4g} s "
                             f"({what} it and would alias)", remedy)


def voltage_steps(wave, duration: float, dt: float, drive, max_steps: Optional[int] = None,
                  remedy: str = SCENE_TIMESTEP) -> np.ndarray:
    n_steps = check_work(duration, dt, max_steps)
    check_sampling(wave, dt, remedy)
    t_steps = np.arange(n_steps) * dt
    v = np.zeros(n_steps) if wave is None else np.asarray(wave(t_steps), dtype=float) * np.ones(n_steps)
    drive.check_voltage(v)
    return v


def to_waveform(voltage, duration: float):
    """A waveform from text, a :class:`Waveform`, a number (a constant voltage, V) or a
    callable v(t); anything else is refused naming what is accepted."""
    if isinstance(voltage, bool) or voltage is None:
        raise ParameterError("voltage", voltage, "a waveform ('step:1V', 'sine:1V@2Hz', ...), a number of volts "
                             "or a callable v(t); None only with a controller")
    if isinstance(voltage, (int, float, np.number)):
        v = float(voltage)
        if not math.isfinite(v):
            raise ParameterError("voltage", voltage, "a finite number of volts")
        voltage = Waveform("step", amplitude=v, text=f"constant {v:g} V")
    if not isinstance(voltage, (str, Waveform)) and not callable(voltage):
        raise ParameterError("voltage", voltage, "a waveform text, a Waveform, a number of volts or a callable v(t)")
    if not isinstance(voltage, (str, Waveform)):
        why = arity_problem(voltage, 1)
        if why is not None:
            raise ParameterError("voltage", getattr(voltage, "__qualname__", type(voltage).__name__),
                                 "a callable v(t) of one argument, t in s", why)
    wave = parse_waveform(voltage) if isinstance(voltage, str) else voltage
    return wave.with_duration(duration) if isinstance(wave, Waveform) else wave


def one_voltage(value, name: str, where: str = "") -> float:
    """A policy's or controller's command for one actuator as a voltage (V): a finite real
    number or a one-element array (shape (1,), a dm_env action). Text, None, a bool, more
    values (two for one actuator, never cut to the first), none or NaN/inf are refused
    naming ``name``, the shape expected and ``where`` (the controller and time). The one
    check of every command path (:func:`rollout`'s loop, :class:`mjeap.simulation.system.System`,
    the dm_env environment)."""
    try:
        a = None if isinstance(value, (str, bytes, bool, type(None))) else np.asarray(value)
    except (TypeError, ValueError):          # ragged nesting
        a = None
    ok = a is not None and a.size == 1 and a.dtype.kind in "iuf"
    v = float(a.reshape(-1)[0]) if ok else math.nan
    if not math.isfinite(v):
        if not ok and a is not None and a.size == 1:      # the shape is right, the type is not (a bool, text)
            shown = value if a.ndim == 0 else f"{type(value).__name__} of shape {a.shape} and dtype {a.dtype}"
            raise ParameterError(name, shown, "one number, a finite voltage in V for one actuator: an int or float "
                                 f"(a number or an array of shape (1,) of dtype float), not {a.dtype}", where)
        shown = value if ok or a is None or a.ndim == 0 else f"{type(value).__name__} of shape {a.shape}"
        raise ParameterError(name, shown, "one number, a finite voltage in V for one actuator (a number or an "
                             "array of shape (1,))", where)
    return v


# ---------------------------------------------------------------- the controller contract
#: one contract for :func:`mjeap.rollout` (a Scene) and :meth:`mjeap.System.rollout` (a System)
CONTROLLER_CONTRACT = ("a callable controller(t, scene_or_system) -> voltage(s) in V: a function or an object with "
                       "__call__; used when present: reset(scene_or_system, drive), interval (s), name, signals()")


def arity_problem(fn, n: int) -> Optional[str]:
    """Why ``fn`` cannot be called with ``n`` positional arguments (its signature), or None
    (it can, or its signature cannot be read: a builtin)."""
    import inspect
    try:
        sig = inspect.signature(fn)
    except (TypeError, ValueError):
        return None
    try:
        sig.bind(*range(n))
    except TypeError as e:
        return f"its signature is {sig}: {e}"
    return None


def check_controller(controller, voltage=None, voltage_name: str = "voltage") -> str:
    """The controller contract, one for :func:`mjeap.rollout` and :meth:`mjeap.System.rollout`,
    checked before any work; returns the controller's name.

    A controller is any callable ``controller(t, target)`` (a plain function or an object with
    ``__call__``), ``t`` in s and ``target`` the Scene or the System being run, that returns
    the voltage to hold until its next call: one number (V) for a scene; for a system one per
    actuator, one for all or a dict by prefix (None: unchanged). Used when present:
    ``reset(target, drive)`` once before the first step (``drive``: the scene's drive; None for
    a system, whose drives are ``system.actuators[i].drive``), ``interval`` (s, read after
    ``reset``) the control period, rounded to whole steps (default: every step), ``name``
    (default: the function's or class's name) in the result's meta and in errors, and
    ``signals()`` (a dict of numbers) recorded at every sample as ``controller_<key>`` (a
    scene's result). Its commands are checked and clipped to the drive's safe range
    (:func:`one_voltage`). ``voltage`` (what the caller also gave) must be None with one."""
    if not callable(controller):
        raise ParameterError("controller", controller, CONTROLLER_CONTRACT, "it is not callable")
    for attr in ("reset", "signals"):
        if getattr(controller, attr, None) is not None and not callable(getattr(controller, attr)):
            raise ParameterError(f"controller.{attr}", getattr(controller, attr), f"a method, or none: {CONTROLLER_CONTRACT}")
    # the arguments each is called with, checked before any work (not a TypeError mid-run)
    for label, fn, args in (("controller", controller, ("t", "target")),
                            ("controller.reset", getattr(controller, "reset", None), ("target", "drive")),
                            ("controller.signals", getattr(controller, "signals", None), ())):
        why = None if fn is None else arity_problem(fn, len(args))
        if why is not None:
            raise ParameterError(label, getattr(fn, "__qualname__", type(fn).__name__),
                                 f"a callable taking {len(args)} positional argument{'s' * (len(args) != 1)}"
                                 + (f" ({', '.join(args)})" if args else "") + f": {CONTROLLER_CONTRACT}", why)
    if voltage is not None:
        raise ParameterError(voltage_name, getattr(voltage, "text", voltage), "None when a controller sets the voltage")
    name = getattr(controller, "name", None)
    return str(name) if name else getattr(controller, "__name__", None) or type(controller).__name__


def reset_controller(controller, target, drive) -> None:
    """``controller.reset(target, drive)`` where the controller has one (:func:`check_controller`)."""
    reset = getattr(controller, "reset", None)
    if reset is not None:
        reset(target, drive)


def controller_every(controller, dt: float) -> int:
    """The controller's period in whole steps of ``dt`` s: its ``interval`` (s, checked: finite
    and > 0) rounded, at least one step; every step without one."""
    interval = getattr(controller, "interval", None)
    if interval is None:
        return 1
    try:
        h = float(interval)
    except (TypeError, ValueError):
        h = math.nan
    if isinstance(interval, bool) or not (0 < h < math.inf):
        raise ParameterError("controller.interval", interval, "a finite number > 0 s (the control period), or none "
                             "for every step")
    return max(1, int(round(h / dt)))


#: the largest initial bend accepted: a uniform arc closing into a full circle
MAX_INITIAL_BEND = 2 * np.pi


def check_initial_curvature(kappa, length: float, name: str = "initial_curvature") -> float:
    """A finite initial curvature (1/m) whose arc bends at most MAX_INITIAL_BEND over the
    beam (|kappa| L <= 2 pi: a full circle; more wraps the beam around itself)."""
    return check_range(name, kappa, -MAX_INITIAL_BEND / length, MAX_INITIAL_BEND / length, "1/m")


def sample_steps(n_steps: int, dt: float, sample_interval: Optional[float]) -> np.ndarray:
    """The steps after which a sample is taken: every ``sample_interval`` (rounded to whole
    steps) or, by default, every ceil(n / DEFAULT_SAMPLES) steps: at most DEFAULT_SAMPLES + 1
    samples with the initial state, evenly spaced (the analytical references integrate on
    them), the last within one interval of the end (the scene holds the final state)."""
    every = max(1, int(round(sample_interval / dt))) if sample_interval else max(1, -(-n_steps // DEFAULT_SAMPLES))
    return np.arange(0, n_steps + 1, every)


def lockstep(model, data, n_steps: int, steps: np.ndarray, before: Callable[[int], None],
             sample: Callable[[int, int], None], check: Callable[[int, int], None], *, check_every: int = 100,
             progress: Optional[Callable[[int], None]] = None) -> None:
    """Step ``model`` ``n_steps`` times from Python, the frame of the loop engine and of
    :meth:`mjeap.System.rollout`: ``before(k)`` sets what acts over step k (a drive's
    moments, the actuators' ctrl), then ``mj_step``; ``check(k + 1, k)`` after every
    ``check_every``-th step and at each sample step raises on a diverged state;
    ``sample(i, k)`` samples the state after step k = ``steps[i]`` (``steps[0]`` = 0 first);
    ``progress(n)`` is told of n more steps at each sample."""
    step_fn = mujoco.mj_step
    ns = len(steps)
    sample(0, 0)
    i, nxt = 1, (int(steps[1]) if ns > 1 else n_steps + 1)
    last = 0
    for k in range(n_steps):
        before(k)
        step_fn(model, data)
        if (k + 1) % check_every == 0 or k + 1 == nxt:
            check(k + 1, k)
        if k + 1 == nxt:
            sample(i, k + 1)
            i += 1
            nxt = int(steps[i]) if i < ns else n_steps + 1
            if progress is not None:
                progress(k + 1 - last)
                last = k + 1
