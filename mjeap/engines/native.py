"""The ``native`` engine: the drive compiled into the model (:class:`mjeap.simulation.native_model.NativeModel`),
the voltages its actuator's ctrl, stepped by ``mujoco.rollout`` (no Python per step; many
rollouts over a thread pool)."""
from __future__ import annotations

from typing import Optional, Sequence

import mujoco
import numpy as np

from mujoco import rollout as mj_rollout

from ..drives.base import NativeForm
from ..model.chain import chain_kinematics
from ..model.mjcf import HINGE_TENDON
from .base import CONTROLLER_REASON, Engine
from .frame import Decided
from .result import TipPath
from .threaded import LOADS, MAXVAL, NATIVE_CONTROL, STATE, ahead_of_stop, raise_bad, roll, spare_datas


class StatesUnread(Exception):
    """A run the native engine cannot read from its states (:meth:`NativeEngine.read_states`):
    the run goes the ordinary way, which says why where it fails."""


def why_not(scene, drive, controller=None) -> Optional[str]:
    """None where the native engine applies to this run of ``scene``; else why not."""
    if controller is not None:
        return CONTROLLER_REASON
    lack = scene.builder.lacks(HINGE_TENDON)
    if lack is not None:
        return f"the native drives' moment is a fixed tendon over one bending joint per hinge: {lack}"
    reason = drive.native_reason()
    if reason is not None:
        return f"the {drive.name} drive has no native form: {reason}"
    return None


class NativeEngine(Engine):
    """Drives with a native form, open loop (:func:`why_not`)."""

    name, batched = "native", True

    def why_not(self, scene, drive, controller=None) -> Optional[str]:
        return why_not(scene, drive, controller)

    def part(self, scene, drive):
        return scene.native_model(drive).part

    def run(self, scene, drives, v_steps, initial_curvatures, sample_steps, samples, *, nthread=0, progress=None,
            check_every=100, controller=None, meta=None) -> None:
        run_native(scene, scene.native_model(drives[0]), drives, v_steps, initial_curvatures, sample_steps, samples,
                   nthread=nthread)

    # -- a mode: the run sampled every step, read from the states mujoco.rollout returns ----
    def states_reason(self, scene, drive) -> Optional[str]:
        """None where a run of ``scene`` with ``drive`` can be read from its states
        (:meth:`read_states`); else why not."""
        why = why_not(scene, drive)
        if why is not None:
            return why
        if scene.part.has_tip_load():
            return "the tip loads are per-step controls"
        if type(drive).native_signal_history is NativeForm.native_signal_history:
            return f"the {drive.name} drive reads its signals one sample at a time"
        return None

    def read_states(self, scene, drive, v_steps: np.ndarray, initial_curvature: float, samples, *,
                    tip_only: bool = False) -> Optional[TipPath]:
        """One run of ``scene`` (:meth:`states_reason` None) with the voltages ``v_steps`` (V
        per step) from rest at ``initial_curvature`` (1/m), sampled every step, its samples
        read from the states ``mujoco.rollout`` returns (one call, no Python per step; the
        beam's points by :func:`mjeap.model.chain.chain_kinematics`, the drive's signals by
        its ``native_signal_history``) into ``samples`` (n + 1 planned; the store the
        native engine's run fills); with ``tip_only`` the tip alone, a :class:`TipPath`
        (what an accuracy target's companion reads), returned. Raises :class:`StatesUnread`
        where the chain's kinematics do not apply or the run goes bad (not finite, beyond
        mjMAXVAL, or MuJoCo warned): the ordinary run then says why. The scene is left as
        it was."""
        native = scene.native_model(drive)
        m, d, part = native.model, native.data, native.part
        dt, n = scene.timestep, len(v_steps)
        native.reset(initial_curvature)
        state0 = np.empty(mujoco.mj_stateSize(m, STATE))
        mujoco.mj_getState(m, d, state0, STATE)
        control = np.empty(mujoco.mj_stateSize(m, NATIVE_CONTROL))
        mujoco.mj_getState(m, d, control, NATIVE_CONTROL)
        drive.native_prepare(v_steps)
        ctl = np.broadcast_to(control, (1, n, len(control))).copy()
        ctl[0, :, native.actuator_id] = v_steps
        states, _ = mj_rollout.rollout(m, d, state0[None], ctl, control_spec=NATIVE_CONTROL, nstep=n)
        if not (np.abs(states[0, :, 1:]) < MAXVAL).all() or not (np.diff(states[0, :, 0]) > 0).all() or \
                d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number:
            raise StatesUnread("the run went bad")
        rows = np.concatenate([state0[None], states[0]])
        steps = np.arange(n + 1)
        if tip_only:
            kin = chain_kinematics(m, rows[:, 1:1 + m.nq], [part.clamp_id, part.tip_body_id], part.tip_body_id)
            if kin is None:
                raise StatesUnread("the beam's bodies move otherwise than a planar hinge chain")
            pos, rot = kin
            site = pos[:, 1] + rot @ m.site_pos[part.tip_site_id]
            return TipPath(steps * dt, part.clamp_frame(site - pos[:, 0]))
        sig = drive.native_signal_history(steps, rows, part, native.handles)
        bodies = [part.clamp_id, *part.link_ids, part.tip_body_id] + ([part.payload_id] if part.payload_id >= 0
                                                                        else [])
        kin = chain_kinematics(m, rows[:, 1:1 + m.nq], bodies, part.tip_body_id)
        if sig is None or kin is None:
            raise StatesUnread("the drive's signals or the beam's kinematics cannot be read from the states")
        pos, rot = kin
        N = len(part.link_ids)
        site = pos[:, N + 1] + rot @ m.site_pos[part.tip_site_id]
        raw = np.concatenate([pos[:, :N + 1], site[:, None]] + ([pos[:, N + 2:]] if part.payload_id >= 0 else []),
                             axis=1)
        samples.take_all(steps * dt, np.r_[v_steps[0], v_steps], raw, rot.reshape(-1, 9), sig)
        return None


def run_native(scene, native, drives: Sequence, v_steps: Sequence[np.ndarray], initial_curvatures: Sequence[float],
               sample_steps: np.ndarray, samples: Sequence, *, nthread: int = 0, roller=roll) -> None:
    """As :func:`run`, on the scene's native model (:class:`mjeap.simulation.native_model.NativeModel`): the
    controls are the voltages themselves (the actuator's ctrl), the drive runs inside
    MuJoCo. The scene is left in the final state of the last run (its beam dofs).
    ``roller``: what rolls the runs out, :func:`mjeap.engines.threaded.roll`'s arguments and
    returns (``mujoco.rollout``; the warp engine's steps MuJoCo Warp)."""
    m, d, part, h = native.model, native.data, native.part, native.handles
    B, n = len(drives), len(v_steps[0])
    dt, a = scene.timestep, native.actuator_id
    state0 = np.empty((B, mujoco.mj_stateSize(m, STATE)))
    # the controls: the voltage (ctrl), and the tip loads where the scene has them
    spec = NATIVE_CONTROL | (LOADS if scene.part.has_tip_load() else 0)
    template = np.empty(mujoco.mj_stateSize(m, spec))
    # drives that compute their signals from the states at the end keep those rows
    batch = [type(drv).native_signal_history is not NativeForm.native_signal_history for drv in drives]
    rows = [np.empty((len(sample_steps), state0.shape[1])) if bt else None for bt in batch]
    for b in range(B):
        native.drive = drives[b]
        native.reset(initial_curvatures[b])
        mujoco.mj_getState(m, d, state0[b], STATE)
        mujoco.mj_getState(m, d, template, spec)
        drives[b].native_prepare(v_steps[b])
        if batch[b]:
            rows[b][0] = state0[b]
        samples[b].take(0.0, v_steps[b][0], {} if batch[b] else drives[b].native_signals(0, part, h))

    def controls(s0, c, out):
        out[:] = template
        for b in range(B):
            out[b][:, a] = v_steps[b][s0:s0 + c]     # ctrl comes first in a composite state

    def put(state):
        mujoco.mj_setState(m, d, state, STATE)
        mujoco.mj_kinematics(m, d)
        sd, nq, nv = scene.data, scene.model.nq, scene.model.nv     # the beam's dofs come first
        sd.qpos[:], sd.qvel[:], sd.time = d.qpos[:nq], d.qvel[:nv], d.time
        scene.update_kinematics()

    def take(b, k, state, before):
        mujoco.mj_setState(m, d, state, STATE)
        mujoco.mj_kinematics(m, d)
        if batch[b]:
            rows[b][samples[b].n] = state
        samples[b].take(k * dt, v_steps[b][k - 1],
                        {} if batch[b] else drives[b].native_signals(k, part, h, before=before))

    decided = None
    try:
        try:
            final, bad, before = roller(m, state0, controls, len(template), spec, n, sample_steps, take,
                                        nthread=nthread, max_chunk=ahead_of_stop(samples, dt),
                                        spares=spare_datas(native, m))
        except Decided as stop:         # the run ends at the decision (Samples.stop)
            final, bad, before, n, decided = stop.state[None], None, stop.before[None], stop.step, stop
        if bad is not None:
            raise_bad(scene, put, drives, v_steps, bad)
        put(final[-1])
    finally:
        for b in range(B):
            if batch[b]:
                n_b = samples[b].n
                samples[b].sig = drives[b].native_signal_history(sample_steps[:n_b], rows[b][:n_b], part, h)
    # the scene and the (last) drive as the loop leaves them: final state, last moments applied
    mujoco.mj_setState(m, d, final[-1], STATE)
    mujoco.mj_kinematics(m, d)
    drives[-1].native_leave(n, part, h, before=before[-1])
    scene.step_count = n
    if decided is not None:
        raise decided
