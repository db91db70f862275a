"""The ``loop`` engine: the drive, then ``mj_step``, once per step from Python
(:func:`mjeap.engines.frame.lockstep`). It serves every drive and closed-loop controllers.

Why not MuJoCo's ``mjcb_control`` hook: that callback is one global per process (two
scenes, or a scene and an environment, would fight over it) and costs a C-to-Python call
per step anyway.
"""
from __future__ import annotations

import math
import warnings
from typing import Optional

import mujoco
import numpy as np

from ..errors import DivergenceError
from .base import Engine
from .frame import Decided, controller_every, lockstep, one_voltage, reset_controller


def advance(model, data, drive, voltage: float, dt: float, nstep: int = 1) -> None:
    """``nstep`` lockstep steps at a held ``voltage`` (V): the drive's step of ``dt`` s, then
    MuJoCo's; the environments' step."""
    for _ in range(nstep):
        drive.step(voltage, dt)
        mujoco.mj_step(model, data)


#: what a divergence check keeps of the state at its window's start (state and applied forces)
WINDOW_STATE = mujoco.mjtState.mjSTATE_INTEGRATION


def window_state(scene, out: Optional[np.ndarray] = None) -> np.ndarray:
    """The scene's state and applied forces now (:data:`WINDOW_STATE`): the start of the
    window a later :func:`divergence_error` replays."""
    m, d = scene.model, scene.data
    if out is None:
        out = np.empty(mujoco.mj_stateSize(m, WINDOW_STATE))
    mujoco.mj_getState(m, d, out, WINDOW_STATE)
    return out


def beam_diverges_alone(scene, start: np.ndarray, nstep: int) -> bool:
    """Whether the beam, replayed for ``nstep`` steps from ``start`` (:func:`window_state`, a
    finite state) with the forces applied then held and no drive, diverges: then a drive's
    moment found non-finite at the end of the window followed the beam's state (it reads it)
    and is not the cause. The scene's data is put back as it was."""
    m, d = scene.model, scene.data
    now, counts = window_state(scene), [w.number for w in d.warning]
    try:
        mujoco.mj_setState(m, d, start, WINDOW_STATE)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")         # MuJoCo's bad-state warnings of the replay
            for _ in range(max(1, int(nstep))):
                mujoco.mj_step(m, d)
                if diverged_state(d):
                    return True
        return False
    finally:
        mujoco.mj_setState(m, d, now, WINDOW_STATE)
        for w, n in zip(d.warning, counts):
            w.number = n


def diverged_state(d) -> bool:
    """The state (qpos, qvel) is no longer finite."""
    return not math.isfinite(float(d.qpos.sum()) + float(d.qvel.sum()))


def divergence_error(scene, drv, voltage: float, step: int, who: str = "", window=None) -> DivergenceError:
    """The error of a lockstep run of ``scene`` and ``drv`` that blew up by ``step`` (the
    last with ``voltage`` V held): a drive whose own moment is not finite is named as the
    cause, else the scene's error (timestep against its stability limit, a payload of the
    wrong unit) with the drive and voltage, and ``who`` (a controller) added. ``window``
    (start state, steps; :func:`window_state`): where the beam's state is not finite either,
    the steps since the last check are replayed without the drive
    (:func:`beam_diverges_alone`) and a beam that diverges on its own is not blamed on the drive."""
    d = scene.data
    bad = d.qfrc_applied[~np.isfinite(d.qfrc_applied)]
    if bad.size and window is not None and diverged_state(d) and beam_diverges_alone(scene, *window):
        bad = bad[:0]            # the drive read a beam already gone: the beam's error
    if bad.size:                 # the drive's own output, not the timestep
        return DivergenceError(
            f"the drive {drv.describe()} applied a non-finite moment ({bad[0]}) by t = "
            f"{step * scene.timestep:.6g} s (step {step}), voltage {voltage:.4g} V; the beam was finite "
            "until then: check the drive, not the timestep")
    return DivergenceError(f"{scene.divergence_error()} Drive: {drv.describe()}, voltage {voltage:.4g} V.{who}")


class LoopEngine(Engine):
    """Every drive, open or closed loop, one run at a time; systems (their drives compiled
    in, the ctrl set per step) and environments, step by step."""

    name, batched = "loop", False

    def system_reason(self, system, controller=None, on_sample=None):
        return None

    def run_system(self, system, n_steps, sample_steps, before, sample, check) -> None:
        lockstep(system.model, system.data, n_steps, sample_steps, before, sample, check)

    def advance(self, scene, drive, voltage, nstep=1) -> None:
        advance(scene.model, scene.data, drive, voltage, scene.timestep, nstep)

    def run(self, scene, drives, v_steps, initial_curvatures, sample_steps, samples, *, nthread=0, progress=None,
            check_every=100, controller=None, meta=None) -> None:
        (drv,), (v,), (kappa0,), (store,) = drives, v_steps, initial_curvatures, samples
        run_loop(scene, drv, v, kappa0, sample_steps, store, check_every=check_every, controller=controller,
                 meta={} if meta is None else meta)


def run_loop(scene, drv, v_steps, initial_curvature, sample_steps, samples, *, check_every,
             controller, meta) -> None:
    """One lockstep run of ``scene`` with ``drv``: ``v_steps`` (V per step; a controller's
    commands are written into it), sampled at ``sample_steps`` into ``samples``."""
    dt, n_steps = scene.timestep, len(v_steps)
    scene.reset(curvature=initial_curvature)
    drv.reset(initial_curvature)
    ctrl_every, (v_lo, v_hi) = n_steps + 1, drv.voltage_range()
    state = {"saturated": 0, "hold": 0.0}
    ctrl_name = None
    if controller is not None:          # the contract: mjeap.engines.frame.check_controller
        reset_controller(controller, scene, drv)
        ctrl_every = controller_every(controller, dt)
        ctrl_name = meta["controller"]
    m, d = scene.model, scene.data
    drive_step = drv.step

    def closed_loop(k):
        if k % ctrl_every == 0:
            scene.update_kinematics()
            u = controller(k * dt, scene)
            if not isinstance(u, float) or not math.isfinite(u):
                u = one_voltage(u, "controller command", f"{ctrl_name} at t = {k * dt:.6g} s")
            state["hold"] = min(max(u, v_lo), v_hi)
            state["saturated"] += state["hold"] != u
        v_steps[k] = state["hold"]
        drive_step(v_steps[k], dt)

    voltage_at = v_steps.item      # a Python float: cheaper to take and to multiply

    def open_loop(k):
        drive_step(voltage_at(k), dt)

    def sample(i, step):
        scene.update_kinematics()
        try:
            samples.take(step * dt, state["hold"] if controller is not None else v_steps[max(step - 1, 0)],
                         drv.signals(), controller)
        except Decided as stop:         # the run ends here (Samples.stop): the scene is in its state
            stop.step = scene.step_count = step
            raise

    window = [window_state(scene), 0]        # the last state checked: a divergence replays from it

    def check(done, k):
        try:
            scene.step_count = done
            scene.check_finite()
        except DivergenceError:
            who = f" Controller: {ctrl_name} (check its gains)." if controller is not None else ""
            raise divergence_error(scene, drv, v_steps[k], done, who, (window[0], done - window[1])) from None
        window_state(scene, window[0])
        window[1] = done

    try:
        lockstep(m, d, n_steps, sample_steps, open_loop if controller is None else closed_loop, sample, check,
                 check_every=check_every)
    finally:
        if controller is not None:
            saturated = state["saturated"]
            meta["saturated_updates"] = int(saturated)
            if saturated:
                meta.setdefault("warnings", []).append(
                    f"{ctrl_name}: {saturated} voltage commands clipped to the safe range [{v_lo:g}, {v_hi:g}] V "
                    "(reference beyond reach or gains too high)")
