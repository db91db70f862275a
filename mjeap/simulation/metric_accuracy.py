"""Runs at a stated accuracy on the answer: a target on named metrics of the tip curvature
(a sweep's, a map's, an optimisation's), not on the whole trajectory
(:mod:`mjeap.simulation.accuracy`).

Each metric's error is taken relative to its own scale (:data:`METRIC_SCALES`):

* ``peak_to_peak`` (last drive period): the swing of the run (peak-to-peak tip curvature
  over the whole run), as the trajectory's target is;
* ``max_stress_proxy``, ``max_tip_deflection``: their own value;
* ``settling_time``: the drive period (the run's duration without one);
* ``returns`` (a boolean: the tip curvature changes sign in the last period): its margin,
  min(max kappa, -min kappa) over the last period relative to the swing (> 0: returns). It is
  *decided* only where |margin| exceeds the margin's estimated error; else the run is
  refined, and a point still undecided after MAX_REFINEMENTS, or whose next model would cost
  more than the scene's own (a margin of 3e-4 of the swing asked for 137 segments at 0.16 ms,
  2 minutes), is run on the scene's own (default) model, which then decides it
  (``decided_by`` says so): no point is left undecided.
  A boolean's target is its decision: the margin's estimated error is reported (the row's
  ``estimated_error.returns``) but not held to the target (a decided answer is the answer).

Time-scale separation. A question read on the last drive period (:data:`LAST_PERIOD_METRICS`)
whose drive is slow against the beam's modes (the drive's fastest time constant, 1 / its
fastest pole or zero or its ``time_constant``, at least SEPARATION / omega for each mode) is
answered with steps far beyond the modes' resolution under 'discrete': backward Euler damps
the fast modes (overdamped above f = 1 / (pi h), said in ``meta['accuracy']['damped_modes']``)
and keeps the slow path. A mode as slow as the drive (the first one near the instantaneous
column load, where it softens towards zero, or the buckled straight beam's growth) is followed
instead: the step resolves it, omega h <= RESOLVED_MODE (before, such points were not relaxed
and ran at beta / 2: 3.4 s against the default model's 1.5 s at 129 mg; now 0.1 s). The step
is chosen by the error model on the answer and bounded by the drive's fastest time constant /
STEPS_PER_TAU, the waveform's period / STEPS_PER_DRIVE_PERIOD and the sample interval, not by beta / 2 (the
refusal of such steps stays for trajectories and for user timesteps). Maxima over the whole
run (they read the release transient), drives without a time constant (the piezo bimorph,
the electrostrictive film) and electrical quantities (power, current, phase: not metrics of
this module; a sweep asking for them puts its target on the trajectory) keep the
trajectory's bound, 1/8 of the first mode's period, and beta / 2 (on pvdf-60's release
ringing a step of 1/8 period, damped by backward Euler in the run and its companions alike,
was 38 x off its estimate).

A posteriori, on the same quantities: the chosen run F = (N, h), a companion of the same N
at 2 h and one of :func:`~mjeap.simulation.accuracy.fewer_segments` at 2 h. The step's error
of each metric is |q(F) - q(F_2h)| / scale (order 1 assumed: backward Euler with the drive
held over the step; 3 x high where it is 2). With relaxed steps a third companion of the
same N at 4 h is run and the metric is extrapolated (Richardson, order 1 -> 2,
:func:`_extrapolate`): where the observed order log2((q_2h - q_4h) / (q - q_2h)) is within
EXTRAPOLATION_ORDERS of 1, the value reported is q + (q - q_2h) (``extrapolated``; the run's
own in ``run_value``, the trajectory returned is the run at h) and its step error
|(q + d1) - (q_2h + d2)| / 3, at least EXTRAPOLATION_FLOOR x the correction; outside the
window the run's own value stands and the next model halves the step (until the steps are
in the asymptotic range). The sweep's rows read the reported values
(:func:`reported_value`). Measured on nine of the map's points, 8 segments (against the
same segments at 0.5 and 1 ms, extrapolated; that reference's own spread up to 0.07 % of the
swing): at 25 ms the run's own peak-to-peak is 0.08-4.4 % of the swing off, the extrapolated
one 0.001-0.15 % (1.2 % at 100 mg, 1.5 V, where the order is outside the window). The
segments' error |q(F_2h) - q(S_2h)| / scale / ((N / n)^2 - 1) (order 2), and where F is
sampled coarser than its step (a user's interval) the sampling's, |q(F) - q(F every other
sample)| / 3, combined in quadrature. Each run is sampled every step otherwise: the drive
held over a step puts a square wave's peak one step after its switch, and a grid coarser
than the step reads the models' peaks unequally (on thick-trilayer's length sweep that hid
a 0.7 % error from the companions); such a run is read from the states ``mujoco.rollout``
returns for all its steps (:func:`run_from_states`), not sampled from Python, and a
refinement reuses the runs already made (its 2 h companion is the last chosen run where it
halves the step). Where a metric's estimate exceeds the target (or a boolean is undecided), the
error model e = sqrt((a / N^2)^2 + (b h)^2) takes a and b from the measured parts and a finer
model is run. Measured numbers: docs/concepts/accuracy.md, scripts/bench.py.
"""
from __future__ import annotations

import math
import threading
from collections import OrderedDict
import time as _time
from dataclasses import asdict
from typing import Dict, List, Optional, Sequence

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..errors import ParameterError
from ..model.modes import modal_frequencies
from .accuracy import (SAFETY, ErrorModel, Model, as_error_model, check_accuracy, check_targetable, choose_model,
                       fewer_segments)

__all__ = ["METRIC_SCALES", "check_metrics", "answerable", "relaxed_step_cap", "last_period",
           "peak_to_peak", "returns_margin", "metric_quantity", "metric_scale", "run_metrics_at_accuracy",
           "chain_kinematics", "run_from_states", "TipPath", "reported_value"]

#: the metrics a target may be put on, and the scale each one's error is relative to
METRIC_SCALES = {"peak_to_peak": "swing", "returns": "margin", "max_stress_proxy": "value",
                 "max_tip_deflection": "value", "settling_time": "period"}
#: metrics read on the last drive period: slow questions where the drive is (time-scale
#: separation); the others (a maximum over the run, a settling time) read the release
#: transient and keep the trajectory's step bound
LAST_PERIOD_METRICS = ("peak_to_peak", "returns")
#: a relaxed step divides the drive period / SAMPLES_PER_PERIOD (the square wave's switching
#: instants on its grid)
SAMPLES_PER_PERIOD = 100
#: bookkeeping columns of a sweep: not quantities, ignored where a target's metrics are read
BOOKKEEPING = ("estimated_error", "stopped_early")
#: the drive's fastest time constant must be this many x the first mode's 1 / omega_1
SEPARATION = 10.0
#: a mode as slow as the drive (omega tau < SEPARATION) is resolved by a relaxed step:
#: omega h at most this (about 60 steps a period)
RESOLVED_MODE = 0.1
#: steps per drive time constant and per drive period, at most
STEPS_PER_TAU = 20
STEPS_PER_DRIVE_PERIOD = 100
#: the first model tried without an error model: segments (the step: the cap)
START_SEGMENTS = 8
#: the step's error of a metric from one companion at 2 h: d / (2^p - 1) with the order p =
#: 1 assumed (backward Euler with the drive held over the step: the beam follows a step
#: late; measured first order on thick-trilayer's length sweep, where p = 1.5 gave 0.56 x
#: the true error): 3 x high where the order is 2
STEP_RICHARDSON = 1.0
MAX_REFINEMENTS = 3
#: Richardson extrapolation of a relaxed run's metrics (order 1 -> 2, :func:`_extrapolate`):
#: where the observed order from the runs at h, 2 h and 4 h, log2(d2 / d1), lies in this window
EXTRAPOLATION_ORDERS = (0.7, 1.4)
#: the extrapolated value's step error is taken as at least this fraction of the correction
#: it made: three steps see the h^2 term, not where the relaxed branch's limit (its fast modes
#: overdamped) differs from the resolved solution (measured on the map's points near the
#: column load, 70-82 mg at 25 ms against runs at 0.5 and 1 ms: 0.06-0.075 of it)
EXTRAPOLATION_FLOOR = 0.1
#: cost of a run of a model: RUN_OVERHEAD + steps x (c0 + c1 N) (us; this 2-core machine,
#: the map's scene under 'discrete', read from its states (:func:`run_from_states`): building
#: a variant and its native model about 12 ms, a step of 8 segments 12-15 us, of 16 27-35 us)
RUN_OVERHEAD_US = 15_000.0
COST_PER_STEP = (1.0, 1.6)
#: a model is never chosen with more steps than this (a boolean at its edge falls back to
#: the scene's own model instead)
MAX_MODEL_STEPS = 2_000_000


def check_metrics(metrics) -> tuple:
    """``metrics`` as a tuple of names of :data:`METRIC_SCALES`, refused otherwise."""
    if isinstance(metrics, str):
        metrics = (metrics,)
    try:
        names = tuple(str(m) for m in metrics)
    except TypeError:
        names = ()
    bad = [m for m in names if m not in METRIC_SCALES] if names else [metrics]
    if bad:
        raise ParameterError("metrics", bad[0], f"names among {', '.join(METRIC_SCALES)} (a target on the "
                             "trajectory: leave metrics out)")
    return names


def answerable(metrics: Sequence[str]) -> bool:
    """Whether a target on ``metrics`` (a sweep's, bookkeeping columns aside) is one this
    module answers: all of them tip-curvature metrics of :data:`METRIC_SCALES`."""
    names = [m for m in metrics if m not in BOOKKEEPING]
    return bool(names) and all(m in METRIC_SCALES for m in names)


def _drive_tau(drive) -> Optional[float]:
    """The drive's fastest time constant (s): 1 / its fastest pole or zero, else its
    ``time_constant`` parameter; None without either (an instantaneous drive)."""
    tf = getattr(drive, "transfer_function", None)
    if tf is None:
        tau = getattr(drive, "params", {}).get("time_constant")
        return float(tau) if tau else None
    try:
        f = tf()
        rates = [abs(complex(x)) for x in list(f.poles) + list(f.zeros)]
    except Exception:           # a drive without a linear form
        return None
    rates = [x for x in rates if x > 0]
    return 1.0 / max(rates) if rates else None


def relaxed_step_cap(scene, drive, wave, metrics: Sequence[str] = LAST_PERIOD_METRICS) -> tuple:
    """(h_cap s, why) for a target on ``metrics``: the drive's fastest time constant /
    STEPS_PER_TAU and the waveform's period / STEPS_PER_DRIVE_PERIOD where every metric reads
    the last period and the drive is slow against the beam's modes (time-scale separation),
    else (None, why not). A mode that is not (omega tau < SEPARATION: the first one near the
    column load, where it softens towards zero, or a buckled beam's growth rate) is followed
    instead of damped: the step then resolves it, omega h <= RESOLVED_MODE; where that leaves
    no step beyond beta / 2 the steps are not relaxed."""
    fast = [m for m in metrics if m not in LAST_PERIOD_METRICS]
    if fast:
        return None, f"{fast[0]} reads the whole run (its release transient is as fast as the beam's modes)"
    if wave is None or not getattr(wave, "frequency", 0):
        return None, "no drive period (the metrics' last period is the run's second half)"
    tau = _drive_tau(drive)
    if tau is None:
        return None, f"the {getattr(drive, 'name', 'drive')} drive has no time constant to bound the step"
    # the beam's rates (rad/s, gravity's load included; a negative eigenvalue: a growth rate)
    rates = np.sqrt(np.abs(modal_frequencies(scene.linearization))) / scene.units.time
    slow = rates[rates * tau < SEPARATION]
    cap = tau / STEPS_PER_TAU
    f = getattr(wave, "max_frequency", 0.0) or getattr(wave, "frequency", 0.0) or 0.0
    if f > 0:
        cap = min(cap, 1.0 / (STEPS_PER_DRIVE_PERIOD * f))
    why = (f"time-scale separation: the drive's fastest time constant {tau:.3g} s against the beam's modes; step at "
           f"most tau / {STEPS_PER_TAU}" + (f" and the drive period / {STEPS_PER_DRIVE_PERIOD}" if f > 0 else ""))
    if slow.size:
        w = float(slow.max())
        if w > 0:
            cap = min(cap, RESOLVED_MODE / w)
        if cap <= 0.5 * scene.choice.rayleigh_beta:
            return None, (f"the drive's fastest time constant {tau:.3g} s is not {SEPARATION:g} x slower than the "
                          f"beam's mode at {w / (2 * math.pi):.3g} Hz, nor can a relaxed step resolve it")
        why += (f"; {slow.size} mode(s) as slow as the drive (up to {w / (2 * math.pi):.3g} Hz) followed, not damped: "
                f"omega h <= {RESOLVED_MODE:g}")
    return cap, why


# ---------------------------------------------------------------- the quantities
def last_period(time: np.ndarray, period: Optional[float]) -> np.ndarray:
    """Mask of the samples in the last drive period (``period`` s; the second half of the
    run without one, or where the run is not longer than it)."""
    t_end = time[-1]
    t0 = t_end - period if period and period < t_end else 0.5 * t_end
    return time >= t0 - 1e-9 * t_end           # the sample at the period's start (round-off) included


def peak_to_peak(time, kappa, period) -> float:
    """Peak-to-peak tip curvature (1/m) over the last drive period."""
    return float(np.ptp(kappa[last_period(time, period)]))


def returns_margin(time, kappa, period) -> float:
    """min(max kappa, -min kappa) over the last drive period (1/m): > 0 where the tip
    curvature changes sign there (Dadras et al. 2021's criterion), its distance from deciding else."""
    k = kappa[last_period(time, period)]
    return float(min(k.max(), -k.min()))


def _settling_time(r) -> float:
    k = r.tip_curvature
    band = 0.02 * max(abs(k[-1] - k[0]), 1e-300)
    outside = np.nonzero(np.abs(k - k[-1]) > band)[0]
    return float(r.time[outside[-1] + 1]) if outside.size and outside[-1] + 1 < k.size else 0.0


def metric_quantity(name: str, r, period: Optional[float]) -> float:
    """The number behind metric ``name`` in run ``r`` (its margin for ``returns``)."""
    if name == "peak_to_peak":
        return peak_to_peak(r.time, r.tip_curvature, period)
    if name == "returns":
        return returns_margin(r.time, r.tip_curvature, period)
    if name == "max_stress_proxy":
        return float(np.abs(r.tip_curvature).max())
    if name == "max_tip_deflection":
        return float(np.abs(r.tip_position[:, 1]).max())
    return _settling_time(r)


def metric_scale(name: str, r, value: float, period: Optional[float], duration: float) -> float:
    """The scale of metric ``name``'s error in run ``r`` (:data:`METRIC_SCALES`)."""
    kind = METRIC_SCALES[name]
    if kind in ("swing", "margin"):
        return float(np.ptp(r.tip_curvature))
    if kind == "period":
        return period or duration
    return abs(value)


def _relative(x: float, scale: float) -> float:
    return x / scale if scale > 0 else (0.0 if x == 0 else math.inf)


# ---------------------------------------------------------------- a run read from its states
def _hinge_rotations(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations by ``angle`` (n,) rad about the unit ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


_EYE = np.eye(3)


#: the structure :func:`chain_kinematics` reads from a model, by (model, bodies, frame_of): a
#: choice's runs and a map's amplitudes step the same native models. Oldest dropped past 128
_CHAINS: "OrderedDict[tuple, tuple]" = OrderedDict()
_CHAINS_LOCK = threading.Lock()


def clear_chains() -> None:
    """Forget the chain structures kept (:func:`chain_kinematics`)."""
    with _CHAINS_LOCK:
        _CHAINS.clear()


def _chain_structure(model, bodies: tuple, frame_of: int):
    """What :func:`chain_kinematics` needs of ``model`` (None where it does not apply)."""
    nb = max(*bodies, frame_of) + 1
    frames = [(np.eye(3), None)]                # per body: F, axis a (None: not rotating)
    hinges = np.zeros((model.nq, nb))           # body b's angle: qpos @ hinges[:, b]
    offsets = np.zeros((3, nb, 3))              # body b's offset from its parent: cos, sin, 1 terms
    rotating = np.zeros(nb, bool)               # whether body b's parent frame rotates
    above = np.eye(nb)                          # above[k, b]: k is b or one of its ancestors
    for b in range(1, nb):
        p, nj = model.body_parentid[b], model.body_jntnum[b]
        f, a = frames[p]
        v = model.body_pos[b]
        above[:, b] += above[:, p]
        hinges[:, b] = hinges[:, p]
        if a is None:
            offsets[2, b] = f @ v
        else:
            rotating[b] = True
            axv = np.array([a[1] * v[2] - a[2] * v[1], a[2] * v[0] - a[0] * v[2], a[0] * v[1] - a[1] * v[0]])
            fa_av = (f @ a) * (a @ v)
            offsets[0, b], offsets[1, b], offsets[2, b] = f @ v - fa_av, f @ axv, fa_av
        local = np.empty(9)
        mujoco.mju_quat2Mat(local, model.body_quat[b])
        local = local.reshape(3, 3)
        if nj > 1:
            return None
        j = model.body_jntadr[b]
        if nj and (model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE or np.any(model.jnt_pos[j])):
            return None
        if a is not None and (not np.abs(local - _EYE).max() <= 1e-15 or
                              (nj and not np.array_equal(model.jnt_axis[j], a))):
            return None
        if nj:
            hinges[model.jnt_qposadr[j], b] += 1.0
            frames.append((f @ local, model.jnt_axis[j].copy()) if a is None else (f, a))
        else:
            frames.append((f @ local, None) if a is None else (f, a))
    # only the bodies above those asked for (the world first): their angles and offsets
    keep = np.nonzero(above[:, list(bodies) + [frame_of]].any(axis=1))[0]
    where = np.full(nb, -1)
    where[keep] = np.arange(len(keep))
    parent = where[model.body_parentid[keep]]
    return (hinges[:, keep], offsets[:, keep], rotating[keep], np.maximum(parent, 0), above[keep[1:]][:, list(bodies)],
            int(where[frame_of]), frames[frame_of])


def chain_kinematics(model, qpos: np.ndarray, bodies: Sequence[int], frame_of: int):
    """World positions (n, B, 3) of ``bodies`` and orientation (n, 3, 3) of body ``frame_of`` for the joint
    positions ``qpos`` (n, nq), all samples at once, down a planar chain: each body's frame
    is a fixed rotation F times a rotation by the summed angle phi of the hinges above it
    about their one axis, so a point v of a body sits at x + F (v cos phi + (a x v) sin phi
    + a (a . v)(1 - cos phi)). The structure is read once per model (a pass over the bodies,
    kept), then every body's angle (qpos times a 0/1 matrix) and the positions (their
    ancestors' offsets summed, one matrix product) for all samples together. None where a
    body moves otherwise (a joint other than one hinge through its origin, hinges on
    different axes, a rotated body below a hinge)."""
    key = (id(model), tuple(int(b) for b in bodies), int(frame_of))
    with _CHAINS_LOCK:
        kept = _CHAINS.get(key)
        if kept is None or kept[0] is not model:
            kept = _CHAINS[key] = (model, _chain_structure(model, key[1], key[2]))
            while len(_CHAINS) > 128:
                _CHAINS.popitem(last=False)
        else:
            _CHAINS.move_to_end(key)
    structure = kept[1]
    if structure is None:
        return None
    hinges, offsets, rotating, parent, picked, frame_at, (f, a) = structure
    n = len(qpos)
    phi = qpos @ hinges                         # (n, nb): each body's summed hinge angle
    c, s = np.cos(phi), np.sin(phi)
    cp = np.where(rotating, c[:, parent], 1.0)
    sp = np.where(rotating, s[:, parent], 0.0)
    step = cp[:, :, None] * offsets[0] + sp[:, :, None] * offsets[1] + offsets[2]      # (n, nb, 3)
    nb = step.shape[1]
    pos = (step[:, 1:].transpose(0, 2, 1).reshape(3 * n, nb - 1) @ picked).reshape(n, 3, -1).transpose(0, 2, 1)
    return pos, np.broadcast_to(f, (n, 3, 3)) if a is None else f @ _hinge_rotations(a, phi[:, frame_at])


class TipPath:
    """What a companion run gives the metrics: ``time`` (s), ``tip_position`` (n, 3; m,
    clamp frame) and ``tip_curvature`` (1/m), read as a RolloutResult reads them."""

    def __init__(self, time: np.ndarray, tip_position: np.ndarray):
        from ..model.analytical import arc_curvature
        self.time, self.tip_position = time, tip_position
        self.tip_curvature = arc_curvature(tip_position[:, 0], tip_position[:, 1])


def run_from_states(scene, drive, wave, duration: float, initial_curvature: float = 0.0, tip_only: bool = False):
    """One native run of ``scene`` sampled at every step, its samples read from the states
    ``mujoco.rollout`` returns (one call, no Python per step; the beam's points by
    :func:`chain_kinematics`, the drive's signals by its ``native_signal_history``): the
    RolloutResult the native engine gives sampled every step, at a fraction of the cost
    (``tip_only``: a :class:`TipPath`, the tip alone, what a companion's metrics read). None
    where that does not apply (no native form, a moving clamp, tip loads, a drive reading
    its signals one sample at a time, joints other than hinges) or where the run goes bad
    (the caller then runs it the ordinary way, which says why)."""
    from ..engines.frame import Samples, voltage_steps
    from ..engines.native import why_not
    from ..drives.base import NativeForm
    from ..engines.threaded import MAXVAL, NATIVE_CONTROL, STATE
    from ..io.outputs import provenance
    if why_not(scene, drive) is not None or scene.part.has_tip_load() or \
            type(drive).native_signal_history is NativeForm.native_signal_history:
        return None
    t0 = _time.perf_counter()
    native = scene.native_model(drive)
    m, d, part = native.model, native.data, native.part
    dt = scene.timestep
    v = voltage_steps(wave, duration, dt, drive)
    n = len(v)
    native.reset(initial_curvature)
    state0 = np.empty(mujoco.mj_stateSize(m, STATE))
    mujoco.mj_getState(m, d, state0, STATE)
    control = np.empty(mujoco.mj_stateSize(m, NATIVE_CONTROL))
    mujoco.mj_getState(m, d, control, NATIVE_CONTROL)
    drive.native_prepare(v)
    ctl = np.broadcast_to(control, (1, n, len(control))).copy()
    ctl[0, :, native.actuator_id] = v
    states, _ = mj_rollout.rollout(m, d, state0[None], ctl, control_spec=NATIVE_CONTROL, nstep=n)
    # bad: not finite or beyond mjMAXVAL, or a step on which MuJoCo warned (time stops)
    if not (np.abs(states[0, :, 1:]) < MAXVAL).all() or not (np.diff(states[0, :, 0]) > 0).all() or \
            d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
        return None
    rows = np.concatenate([state0[None], states[0]])
    steps = np.arange(n + 1)
    if tip_only:
        kin = chain_kinematics(m, rows[:, 1:1 + m.nq], [part.clamp_id, part.tip_body_id], part.tip_body_id)
        if kin is None:
            return None
        pos, rot = kin
        site = pos[:, 1] + rot @ m.site_pos[part.tip_site_id]
        return TipPath(steps * dt, part.clamp_frame(site - pos[:, 0]))
    drive.part = part
    try:
        sig = drive.native_signal_history(steps, rows, part, native.handles)
    finally:
        drive.part = scene.part
    bodies = [part.clamp_id, *part.link_ids, part.tip_body_id] + ([part.payload_id] if part.payload_id >= 0 else [])
    kin = chain_kinematics(m, rows[:, 1:1 + m.nq], bodies, part.tip_body_id)
    if sig is None or kin is None:
        return None
    pos, rot = kin
    N = len(part.link_ids)
    site = pos[:, N + 1] + rot @ m.site_pos[part.tip_site_id]
    raw = np.concatenate([pos[:, :N + 1], site[:, None]] + ([pos[:, N + 2:]] if part.payload_id >= 0 else []), axis=1)
    samples = Samples(part, n + 1)
    samples.take_all(steps * dt, np.r_[v[0], v], raw, rot.reshape(-1, 9), sig)
    meta = {**provenance(), "actuator": scene.actuator.id, "drive": drive.describe(),
            "voltage": getattr(wave, "text", str(wave)), "duration_s": duration,
            "initial_curvature_per_m": initial_curvature, "steps": n,
            "engine": "native (every step read from mujoco.rollout's states)", "scene": scene.summary(),
            "wall_time_s": _time.perf_counter() - t0}
    if scene.choice.buckled:
        meta["warnings"] = [scene.buckled_warning()]
    return samples.result(drive, initial_curvature, meta)


# ---------------------------------------------------------------- the choice
def _cost(model: Model, duration: float) -> float:
    c0, c1 = COST_PER_STEP
    return RUN_OVERHEAD_US + duration / model.timestep * (c0 + c1 * model.segments)


def _on_grid(h: float, grid: float) -> float:
    return grid / max(1, math.ceil(grid / h * (1 - 1e-12)))


def _integrator(scene, h: float) -> str:
    """'implicitfast' where h and the 2 h companion stay within the Rayleigh beta (about its
    stability limit), else 'discrete'."""
    return "implicitfast" if 2 * h <= scene.choice.rayleigh_beta else "discrete"


def _choose(scene, em: ErrorModel, target: float, duration: float, grid: float, h_cap: float,
            widest: int = 2) -> Model:
    """The cheapest model with predicted error <= target / SAFETY, h on the grid / ``widest``
    (the widest companion's step divides it: 2 h, or 4 h where it extrapolates), a run's
    overhead in its cost."""
    return choose_model(scene, em, target, duration, grid, h_cap, widest=widest, cost=_cost, integrator=_integrator)


class _EveryOther:
    """A run's samples, every other one (the sampling's own companion)."""

    def __init__(self, r):
        self.time, self.tip_curvature, self.tip_position = r.time[::2], r.tip_curvature[::2], r.tip_position[::2]


#: the sampling's error of a metric from its value on every other sample: d / (2^2 - 1), a
#: smooth extremum read between samples being off by O(interval^2)
SAMPLING_RICHARDSON = 3.0


def _extrapolate(q: float, q_2h: float, q_4h: float) -> Optional[tuple]:
    """(value, step error) of a metric from its values at h, 2 h and 4 h by Richardson's
    extrapolation at order 1 (backward Euler, the drive held over the step): d1 = q - q_2h,
    d2 = q_2h - q_4h; where the observed order log2(d2 / d1) is within
    EXTRAPOLATION_ORDERS the value is q + d1 (its first-order error removed) and its error
    |(q + d1) - (q_2h + d2)| / 3 (order 2) plus |d1| |1 - 1 / (2^p - 1)| (the order-p
    sequence's limit against order 1's), at least EXTRAPOLATION_FLOOR x |d1|; None outside
    the window (not in the asymptotic range: the run's own value stands)."""
    p = _observed_order(q, q_2h, q_4h)
    if p is None or not EXTRAPOLATION_ORDERS[0] <= p <= EXTRAPOLATION_ORDERS[1]:
        return None
    d1, d2 = q - q_2h, q_2h - q_4h
    # the h^2 remainder, and what assuming order 1 leaves where the observed order is p: the
    # limit of an order-p sequence is q + d1 / (2^p - 1)
    err = abs(2 * d1 - d2) / 3.0 + abs(d1) * abs(1.0 - 1.0 / (2.0 ** p - 1.0))
    return q + d1, max(err, EXTRAPOLATION_FLOOR * abs(d1))


def _observed_order(q: float, q_2h: float, q_4h: float) -> Optional[float]:
    """log2(d2 / d1) of :func:`_extrapolate` (None where d1 is 0 or the signs differ)."""
    d1, d2 = q - q_2h, q_2h - q_4h
    return math.log2(d2 / d1) if d1 != 0 and d2 / d1 > 0 else None


def _evaluate(metrics, runs, period, duration, step) -> Dict[str, dict]:
    """Each metric's value and its (step, segments, sampling) errors relative to its scale,
    from the runs (F, F_2h, S_2h, F_4h or None) and the segment counts (N, n): the value
    F's own, or extrapolated where F_4h was run and the step's order is observed to be 1
    (:func:`_extrapolate`; ``run_value`` then holds F's own); the sampling's error only
    where F was sampled coarser than its ``step``."""
    (f, mid, fewer, quad), (n_f, n_s) = runs
    coarse = len(f.time) > 1 and f.time[1] - f.time[0] > 1.5 * step      # sampled coarser than its step
    sparse = _EveryOther(f)
    out = {}
    for name in metrics:
        q = [metric_quantity(name, r, period) for r in (f, mid, fewer, sparse)]
        scale = metric_scale(name, f, q[0], period, duration)
        e_h = _relative(abs(q[0] - q[1]), scale) / STEP_RICHARDSON
        e_s = _relative(abs(q[1] - q[2]), scale) / ((n_f / n_s) ** 2 - 1)
        e_t = _relative(abs(q[0] - q[3]), scale) / SAMPLING_RICHARDSON if coarse else 0.0
        q4 = None if quad is None or coarse else metric_quantity(name, quad, period)
        x = None if q4 is None else _extrapolate(q[0], q[1], q4)
        value = q[0]
        if x is not None:
            value, e_h = x[0], _relative(x[1], scale)
        e = math.sqrt(e_h ** 2 + e_s ** 2 + e_t ** 2)
        row = {"value": value, "estimated_error": e, "step_error": e_h, "segments_error": e_s,
               "sampling_error": e_t, "scale": METRIC_SCALES[name], "extrapolated": x is not None}
        if q4 is not None:
            row["observed_step_order"] = _observed_order(q[0], q[1], q4)
        if x is not None:
            row["run_value"] = q[0]
        if name == "returns":       # decided beyond its error, and on the run's own side where extrapolated
            margin = _relative(value, scale)
            row.update(margin=margin, decided=abs(margin) > e and (x is None or (value > 0) == (q[0] > 0)))
        out[name] = row
    return out


def reported_value(result, name: str, period: Optional[float]) -> float:
    """The value of metric ``name`` a run at a target on metrics reports (its margin for
    ``returns``): ``meta['accuracy']['metrics'][name]['value']`` where the target was on
    it (extrapolated where the report says so), else read from the run's samples."""
    found = result.meta.get("accuracy", {}).get("metrics", {}).get(name)
    return float(found["value"]) if found and "value" in found else metric_quantity(name, result, period)


def _needs(metrics: Dict[str, dict], target: float) -> float:
    """The error the next model must reach: the target (for the metrics that are numbers),
    and below each undecided boolean's margin (a boolean's target is its decision); 0 where
    the run is good enough."""
    worst = max([m["estimated_error"] for m in metrics.values() if "decided" not in m] or [0.0])
    need = target if worst > target else math.inf
    for m in metrics.values():
        if "decided" in m and not m["decided"]:
            need = min(need, abs(m["margin"]) / 2)
    return 0.0 if need == math.inf else need


def run_metrics_at_accuracy(scene, run, *, metrics: Sequence[str], accuracy: float, duration: float, drive,
                            wave=None, sample_interval: Optional[float] = None, error_model=None, every_step=None):
    """Choose, run and check a model of ``scene`` whose ``metrics`` (names of
    :data:`METRIC_SCALES`) are within ``accuracy`` of their scales. ``run(scene, interval)``
    runs one model sampled every ``interval`` s (None: every step) and returns a
    RolloutResult; ``every_step(scene, tip_only)``, where given, runs one sampled every step
    the faster way (:func:`run_from_states`; the companions ``tip_only``; None where that does
    not apply: ``run`` then runs it);
    ``drive`` (the question's drive) bounds the relaxed step. ``error_model``:
    (a, b) of a similar question (a sweep's earlier point) choosing the first model. Returns
    (result, scene of the chosen model, report), the report also in
    ``result.meta['accuracy']`` with one entry per metric under ``'metrics'``. The chosen
    scene is shared (:meth:`mjeap.Scene.variant`): a later run of the same model in this
    thread resets its state."""
    target = check_accuracy(accuracy)
    names = check_metrics(metrics)
    given = None if error_model is None else as_error_model(error_model)
    check_targetable(scene, accuracy)
    t0 = _time.perf_counter()
    period = 1.0 / wave.frequency if wave is not None and getattr(wave, "frequency", 0) else None
    relaxed, why = relaxed_step_cap(scene, drive, wave, names)
    # not relaxed: 1/8 of the first mode's period, and beta / 2 (the step's own damping under
    # 'discrete' at most half the beam's: a maximum over the release transient reads its
    # ringing, which a larger step damps in the run and its companions alike, unseen)
    trajectory_cap = min(1.0 / (8 * scene.choice.first_frequency), 0.5 * scene.choice.rayleigh_beta or math.inf)
    h_cap = relaxed if relaxed is not None else trajectory_cap
    # each run sampled every step (a peak one step after a switch, the drive held over the
    # step, is then each model's own); the relaxed step on a grid of the drive period
    own_grid = relaxed is not None and sample_interval is None
    grid = period / SAMPLES_PER_PERIOD if own_grid else (sample_interval or duration)
    h_cap = min(h_cap, grid)
    widest = 4 if relaxed is not None and own_grid else 2      # the widest companion's step factor
    log: List[dict] = []
    done: Dict[tuple, tuple] = {}        # (model, interval) -> (scene, result): a refinement's companions reuse them

    def one(model: Model, role: str, interval=None, tip_only: bool = False):
        """The run of ``model`` sampled every ``interval`` s (a companion's: ``tip_only``,
        where it is read from its states: the tip alone, all its metrics read)."""
        if (model, interval) in done and (tip_only or not isinstance(done[model, interval][1], TipPath)):
            log.append({"role": role + " (reused)", **asdict(model), "wall_time_s": 0.0})
            return done[model, interval]
        s = scene.variant(model.segments, model.timestep, model.integrator)
        t = _time.perf_counter()
        out = every_step(s, tip_only) if every_step is not None and interval == model.timestep else None
        if out is None:
            out = run(s, interval)
        log.append({"role": role, **asdict(model), "wall_time_s": _time.perf_counter() - t})
        done[model, interval] = s, out
        return s, out

    def extrapolating(model: Model) -> bool:
        """Whether an attempt at ``model`` adds the run at 4 h (:func:`_extrapolate`): relaxed
        steps under 'discrete', each run sampled every step, 4 h dividing the drive's grid."""
        k = grid / (4 * model.timestep)
        return relaxed is not None and own_grid and model.integrator == "discrete" and k >= 1 - 1e-9 and \
            abs(k - round(k)) <= 1e-9 * k

    def runs_of(model: Model) -> list:
        """The runs an attempt at ``model`` needs: it and its companions (2 h, fewer segments
        at 2 h, and 4 h where it extrapolates)."""
        h2 = 2 * model.timestep
        out = [(model, sample_interval or model.timestep),
               (Model(model.segments, h2, model.integrator), sample_interval or h2),
               (Model(fewer_segments(model.segments), h2, model.integrator), sample_interval or h2)]
        if extrapolating(model):
            out.append((Model(model.segments, 2 * h2, model.integrator), 2 * h2))
        return out

    def new_cost(model: Model) -> float:
        """The cost of an attempt at ``model``, less the runs already done."""
        return sum(_cost(m, duration) for m, i in runs_of(model) if (m, i) not in done)

    def refine(em: ErrorModel, need: float, last: Model, pre_asymptotic: bool) -> Model:
        """The cheapest next model by the error model: :func:`_choose`'s, or ``last``'s
        segments at an integer fraction of its step (its runs then serve as companions);
        where ``last``'s step was outside the asymptotic range (``pre_asymptotic``: a
        metric's observed order outside EXTRAPOLATION_ORDERS), half its step: at its
        segments where the error model's spatial part allows them (the runs at h and 2 h
        then serve as companions), else at the segments that part needs."""
        if pre_asymptotic:
            h = min(h_cap, last.timestep / 2)
            if em.spatial / last.segments ** 2 <= need / SAFETY:
                return Model(last.segments, h, _integrator(scene, h))
            return _choose(scene, ErrorModel(em.spatial, 0.0), need, duration, grid, h, widest)
        best = _choose(scene, em, need, duration, grid, h_cap, widest)
        for k in (2, 3, 4, 6, 8):
            m = Model(last.segments, last.timestep / k, last.integrator)
            if em.predict(m) <= need / SAFETY and _integrator(scene, m.timestep) == last.integrator and \
                    new_cost(m) < new_cost(best):
                best = m
        return best

    def attempt(model: Model, role: str):
        (m_f, i_f), (m_mid, i_mid), (m_s, i_s), *rest = runs_of(model)
        chosen, f = one(m_f, role, i_f)
        _, mid = one(m_mid, "companion", i_mid, tip_only=True)
        _, fewer = one(m_s, "spatial companion", i_s, tip_only=True)
        quad = one(rest[0][0], "extrapolation companion", rest[0][1], tip_only=True)[1] if rest else None
        return chosen, f, _evaluate(names, ((f, mid, fewer, quad), (model.segments, m_s.segments)), period,
                                    duration, model.timestep)

    if given is not None:       # not below START_SEGMENTS: a family's first point (its lightest load, on the
        # map) predicts too few for the rest (from 4 segments 13 of the map's 23 other points were refined)
        model = _choose(scene, given, target, duration, grid, h_cap, widest)
        model = Model(max(model.segments, START_SEGMENTS), model.timestep, model.integrator)
    else:
        h0 = _on_grid(h_cap, grid / widest)
        model = Model(START_SEGMENTS, h0, _integrator(scene, h0))
    chosen, result, found = attempt(model, "chosen")
    em = given or ErrorModel(0.0, 0.0)
    own_cost = _cost(Model(scene.layout.segments, scene.timestep, scene.integrator), duration)
    refinements, decided_by = 0, None
    need = _needs(found, target)
    while need > 0 and refinements < MAX_REFINEMENTS:
        # the metrics that ask for more: numbers beyond the target, undecided booleans
        short = [m for m in found.values() if (not m["decided"] if "decided" in m else m["estimated_error"] > target)]
        em = ErrorModel(max(max(m["segments_error"] for m in short) * model.segments ** 2, 1e-12),
                        max(max(m["step_error"] for m in short) / model.timestep, 1e-12))
        nxt = refine(em, need, model, any("observed_step_order" in m and not m["extrapolated"] for m in short))
        if duration / nxt.timestep > MAX_MODEL_STEPS or \
                (nxt.segments <= model.segments and nxt.timestep >= model.timestep):
            break
        if all("decided" in m for m in short) and new_cost(nxt) > own_cost:
            break       # only a boolean at its edge: the scene's own model decides it for less
        refinements += 1
        model = nxt
        chosen, result, found = attempt(model, "refined")
        need = _needs(found, target)
    undecided = [k for k, m in found.items() if "decided" in m and not m["decided"]]
    if undecided:           # a boolean at its edge: the scene's own model decides it
        t = _time.perf_counter()
        result = run(scene, sample_interval)
        log.append({"role": "default model (undecided at the target)", "segments": scene.layout.segments,
                    "timestep": scene.timestep, "integrator": scene.integrator,
                    "wall_time_s": _time.perf_counter() - t})
        chosen, decided_by = scene, "the scene's own model: undecided by the chosen model's estimate"
        for k in undecided:
            value = metric_quantity(k, result, period)
            for gone in ("run_value", "observed_step_order"):
                found[k].pop(gone, None)
            found[k].update(value=value, margin=_relative(value, metric_scale(k, result, value, period, duration)),
                            extrapolated=False, decided=True, decided_by=decided_by)
    # the error reported and held to the target: the numbers' (a boolean's target is its decision)
    numbers = [m["estimated_error"] for m in found.values() if "decided" not in m]
    worst = max(numbers or [m["estimated_error"] for m in found.values()])
    met = all(m["decided"] if "decided" in m else m["estimated_error"] <= target for m in found.values())
    h = model.timestep
    damped = None
    if h > scene.choice.rayleigh_beta and model.integrator == "discrete":
        damped = (f"modes above {1 / (math.pi * h):.3g} Hz overdamped by the step (backward Euler, h = {h:.3g} s; "
                  f"first mode {scene.choice.first_frequency:.3g} Hz, its damping ratio raised to about "
                  f"{math.pi * scene.choice.first_frequency * h:.2g}): the answer is the slow path")
    report = {"quantity": "metrics: " + ", ".join(f"{k} (relative to its {METRIC_SCALES[k]})" for k in names),
              "target": target, "model": asdict(model), "estimated_error": worst, "met": met,
              "metrics": found, "relaxed_step": why if relaxed is not None else None,
              "relaxed_step_refused": None if relaxed is not None else why, "damped_modes": damped,
              "decided_by": decided_by,
              "estimate": "each metric on the chosen run against companions of the same segments at 2 h (step, "
                          "order 1 assumed) and of fewer segments at 2 h (segments, order 2), in quadrature; with "
                          "relaxed steps also at 4 h: Richardson-extrapolated where the observed order is near 1",
              "values_from": ("the chosen model's runs (the numbers); the trajectory and the undecided booleans "
                              "from the scene's own model" if decided_by else "the chosen model's runs"),
              "error_model": {"spatial_a": em.spatial, "temporal_b_per_s": em.temporal,
                              "form": "e = sqrt((a / N^2)^2 + (b h)^2)",
                              "pilots": "given" if given is not None else "none: measured on the runs"},
              "refinements": refinements, "runs": log, "wall_time_s": _time.perf_counter() - t0}
    if refinements == 0 and given is None:      # the error model of this question, for the next
        report["error_model"].update(
            spatial_a=max(max(m["segments_error"] for m in found.values()) * model.segments ** 2, 1e-12),
            temporal_b_per_s=max(max(m["step_error"] for m in found.values()) / model.timestep, 1e-12))
    result.meta["accuracy"] = report
    if damped:
        result.meta.setdefault("warnings", []).append(damped)
    if not met:
        result.meta.setdefault("warnings", []).append(
            f"accuracy target {target:g} on {', '.join(names)} not met: estimated error {worst:.3g} with "
            f"{Model(**report['model']).describe()} after {refinements} refinements")
    return result, chosen, report
