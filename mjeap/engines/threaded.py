"""The ``threaded`` engine: open-loop rollouts on MuJoCo's threaded rollout (``mujoco.rollout``).

When it applies (:func:`why_not` says why not otherwise):

* the drive is open-loop: its moments follow from the voltage alone and it leaves the
  model unchanged (:meth:`Drive.closed_loop_reason` is None): the piezo bimorph, the
  blocking-force drive without a stiffness table, the electrostrictive drive without field
  stiffening. Dadras et al. 2021's rc-relaxation drive is not: its back-relaxation acts on the
  beam's own moments, a feedback on the hinge angles;
* no controller (its voltage depends on the state) and no tip load set on the scene.

How: the drive computes the moment history of the whole run up front
(:meth:`OpenLoop.open_loop_moments`, vectorised); it goes to ``mujoco.rollout`` as
``qfrc_applied`` controls, in internal units, and the states come back for every step, in
chunks that keep memory bounded. Steps run in C, many rollouts share a thread pool. The
samples are read back by putting the sampled state into the scene's MjData
(``mj_setState`` + ``mj_kinematics``) and the drive at that step (:meth:`OpenLoop.seek`,
which replays the drive's own step), so they are the lockstep loop's read-outs exactly.
"""
from __future__ import annotations

import weakref
from concurrent.futures import Future, ThreadPoolExecutor
from contextlib import nullcontext
from functools import partial
from typing import List, Optional, Sequence

import mujoco
import numpy as np
from mujoco import rollout as mj_rollout

from ..errors import DivergenceError
from ..model.mjcf import FIXED_BENDING_FORCES
from .base import CONTROLLER_REASON, Engine
from .frame import Decided

STATE = mujoco.mjtState.mjSTATE_FULLPHYSICS
CONTROL = mujoco.mjtState.mjSTATE_QFRC_APPLIED
NATIVE_CONTROL = mujoco.mjtState.mjSTATE_CTRL
LOADS = mujoco.mjtState.mjSTATE_XFRC_APPLIED
#: the state and control arrays of one chunk stay below this size
CHUNK_BYTES = 64 * 2**20
#: a run goes in at least this many chunks (the pipeline of :func:`roll`), each of at least
#: PIPELINE_MIN_STEPS steps over all its runs (a chunk costs ~0.1 ms to hand over)
PIPELINE_CHUNKS, PIPELINE_MIN_STEPS = 8, 20_000
#: MuJoCo's mjMAXVAL: larger state entries count as diverged, as mj_checkPos/Vel do
MAXVAL = 1e10


def _error(scene, drive, voltage, b, B, note="") -> DivergenceError:
    return DivergenceError(f"{note}{scene.divergence_error()} Drive: {drive.describe()}, voltage {voltage:.4g} V "
                           f"(threaded rollout {b + 1} of {B}).")


def why_not(scene, drive, controller=None) -> Optional[str]:
    """None where the threaded engine applies to this run; else the reason, in words."""
    if controller is not None:
        return CONTROLLER_REASON
    lack = scene.builder.lacks(FIXED_BENDING_FORCES)
    if lack is not None:
        return f"mujoco.rollout takes the drive's moments as fixed generalised forces (qfrc_applied controls): {lack}"
    reason = drive.closed_loop_reason()
    if reason is not None:
        return f"the {drive.name} drive is not open-loop: {reason}"
    if scene.part.has_tip_load():
        return "a tip load is set on the scene (mujoco.rollout does not carry xfrc_applied)"
    return None


def _first_bad(state0: np.ndarray, state: np.ndarray) -> tuple:
    """(step, run): the first step of a chunk after which any run is bad, and the first such
    run, or (len of the chunk, None). Bad: not finite or beyond mjMAXVAL (internal units keep
    it near 1), or a step on which MuJoCo warned: the rollout then stops and repeats its
    last state, so time stops advancing."""
    c = state.shape[1]
    good = (np.abs(state[:, :, 1:]) < MAXVAL).all(axis=2)          # (B, c)
    times = np.concatenate([state0[:, :1], state[:, :, 0]], axis=1)
    good[:, :-1] &= np.diff(times, axis=1)[:, 1:] > 0
    if good.all():
        return c, None
    step = int(np.argmin(good.all(axis=0)))
    return step, int(np.argmin(good[:, step]))


def roll(model, state0: np.ndarray, controls, ncontrol: int, control_spec, n: int, sample_steps: np.ndarray,
         take, *, nthread: int = 0, max_chunk: Optional[int] = None, spares: Optional[list] = None) -> tuple:
    """The core of both engines: ``mujoco.rollout`` of ``len(state0)`` runs of ``model`` over
    ``n`` steps, in chunks that keep memory bounded. ``controls(s0, c, out)`` fills the
    (B, c, ncontrol) controls of steps s0 .. s0 + c; ``take(b, k, state, before)`` is called
    for every run b at every sample step k >= 1 with its state after that step and the state
    before it (what a replayed drive step starts from). Returns (final states (B, nstate),
    None, the states one step before them) or, at the first bad state (not finite, beyond
    mjMAXVAL, or after a step on which MuJoCo warned), (None, (run, step, state), None),
    after taking the samples before it. A :class:`Decided` raised by ``take`` carries the
    run's ``state`` and ``before`` there.

    Pipelined: while the samples of one chunk are taken (Python, this thread), the next
    chunk rolls out (C, the GIL released) on ``nthread`` threads; a chunk is at most
    1 / PIPELINE_CHUNKS of the run (short runs go in one), so that little of either waits
    for the other. ``max_chunk`` (steps) caps a chunk: a run that may stop at a sample
    (Samples.stop) rolls out at most that far ahead of it. ``spares``: MjData to borrow
    and give back (:func:`spare_datas`)."""
    B = len(state0)
    nstate = mujoco.mj_stateSize(model, STATE)
    chunk = int(max(1, min(n, CHUNK_BYTES // (8 * B * (nstate + ncontrol)),
                           max(-(-n // PIPELINE_CHUNKS), -(-PIPELINE_MIN_STEPS // B)), max_chunk or n)))
    datas = _borrow_datas(model, max(nthread, 1), spares)
    try:
        return _roll(model, datas, state0, controls, ncontrol, control_spec, n, sample_steps, take=take,
                     nthread=nthread, chunk=chunk, B=B)
    finally:
        if spares is not None:
            spares.extend(datas)


#: owner (a scene or native model) -> (its model, its spare MjData), dropped with the owner
_SPARES: "weakref.WeakKeyDictionary" = weakref.WeakKeyDictionary()


def spare_datas(owner, model) -> list:
    """The list of spare MjData of ``model`` kept for ``owner`` (the scene or native model
    that holds the model, so they live and die together): :func:`roll` borrows from it and
    gives back (a new MjData of the native Dadras et al. 2021 model costs ~0.35 ms, a reset 3 us)."""
    held = _SPARES.get(owner)
    if held is None or held[0] is not model:        # a recompiled model: a fresh list
        held = _SPARES[owner] = (model, [])
    return held[1]


def _borrow_datas(model, k: int, spare: Optional[list]) -> list:
    """``k`` MjData of ``model``, reset (warnings cleared): spare ones first, then new."""
    spare = spare if spare is not None else []
    out = []
    while spare and len(out) < k:
        try:
            d = spare.pop()
        except IndexError:          # another thread took the last one
            break
        mujoco.mj_resetData(model, d)
        out.append(d)
    return out + [mujoco.MjData(model) for _ in range(k - len(out))]


def _roll(model, datas, state0, controls, ncontrol, control_spec, n, sample_steps, *, take, nthread, chunk, B):
    starts = list(range(0, n, chunk))
    control = [np.zeros((B, chunk, ncontrol)) for _ in starts[:2]]    # one per chunk in flight
    i_next = 1                                      # next sample index (same for all runs)
    with mj_rollout.Rollout(nthread=nthread) as pool, \
            (ThreadPoolExecutor(max_workers=1) if len(starts) > 1 else nullcontext()) as ahead:

        def submit(j, first):
            s0 = starts[j]
            c = min(chunk, n - s0)
            ctl = control[j % 2][:, :c]
            controls(s0, c, ctl)
            job = partial(pool.rollout, model, datas, first, ctl, control_spec=control_spec, nstep=c)
            if ahead is None:                   # one chunk: nothing to overlap
                done = Future()
                done.set_result(job())
                return done
            return ahead.submit(job)

        pending = submit(0, state0)
        before_last = state0
        for j, s0 in enumerate(starts):
            state = pending.result()[0]
            c = state.shape[1]
            bad, run = _first_bad(state0, state)
            last = np.ascontiguousarray(state[:, c - 1])
            if bad == c and j + 1 < len(starts):        # the next chunk rolls while these are sampled
                pending = submit(j + 1, last)
            # samples up to the first bad step of any run
            while i_next < len(sample_steps) and sample_steps[i_next] <= s0 + bad:
                k = int(sample_steps[i_next])
                for b in range(B):
                    i = k - s0 - 1
                    before = state[b, i - 1] if i > 0 else state0[b]
                    try:
                        take(b, k, state[b, i], before)
                    except Decided as stop:     # the run ends here: its state goes with the decision
                        stop.step, stop.state, stop.before = k, np.array(state[b, i]), np.array(before)
                        raise
                i_next += 1
            if run is not None:
                return None, (run, s0 + bad + 1, state[run, bad]), None
            before_last = np.array(state[:, c - 2]) if c > 1 else state0
            state0 = last
    if any(x.warning[mujoco.mjtWarning.mjWARN_BADQACC].number for x in datas):
        # a warning on the very last step leaves no repeated state behind it
        return None, (B - 1, n, None), None
    return state0, None, before_last


def run(scene, drives: Sequence, v_steps: Sequence[np.ndarray], initial_curvatures: Sequence[float],
        sample_steps: np.ndarray, samples: Sequence, nthread: int = 0) -> None:
    """Roll out ``len(drives)`` runs of ``scene`` (one drive, voltage history, initial
    curvature and sample store each) with ``nthread`` threads (0: the calling thread),
    filling the sample stores; the drives' moments are qfrc_applied controls. Raises
    DivergenceError at the first non-finite state."""
    m, d = scene.model, scene.data
    B, n = len(drives), len(v_steps[0])
    nstate, nv = mujoco.mj_stateSize(m, STATE), m.nv
    dt, bend, scale = scene.timestep, scene.bend_dof, 1.0 / scene.units.moment
    state0 = np.empty((B, nstate))
    moments: List[np.ndarray] = []
    for b in range(B):
        scene.reset(curvature=initial_curvatures[b])
        drives[b].reset(initial_curvatures[b])
        mujoco.mj_getState(m, d, state0[b], STATE)
        moments.append(drives[b].open_loop_moments(v_steps[b]) * scale)
        drives[b].seek(0)
        scene.update_kinematics()
        samples[b].take(0.0, v_steps[b][0], drives[b].signals())

    def controls(s0, c, out):
        for b in range(B):
            out[b][:, bend] = moments[b][s0:s0 + c]

    def replay(drive, k, state, before):
        """The drive's step k - 1 replayed from the state it started from (as the loop
        steps it), then the state after it (the read-outs')."""
        mujoco.mj_setState(m, d, before, STATE)
        drive.seek(k)
        mujoco.mj_setState(m, d, state, STATE)

    def take(b, k, state, before):
        replay(drives[b], k, state, before)
        scene.update_kinematics()
        samples[b].take(k * dt, v_steps[b][k - 1], drives[b].signals())

    try:
        final, bad, before = roll(m, state0, controls, nv, CONTROL, n, sample_steps, take, nthread=nthread,
                                  max_chunk=ahead_of_stop(samples, dt), spares=spare_datas(scene, m))
        decided = None
    except Decided as stop:             # the run ends at the decision (Samples.stop)
        final, bad, before, n, decided = stop.state[None], None, stop.before[None], stop.step, stop
    if bad is not None:
        raise_bad(scene, lambda x: mujoco.mj_setState(m, d, x, STATE), drives, v_steps, bad)
    # leave the scene and the (last) drive as the lockstep loop does: final state, the
    # moments of the last step still applied (seek replays that step)
    replay(drives[-1], n, final[-1], before[-1])
    scene.step_count = n
    scene.update_kinematics()
    if decided is not None:
        raise decided


def ahead_of_stop(samples, dt: float) -> Optional[int]:
    """The chunk (steps) of a run that may stop early: a tenth of the stop's period (the
    steps rolled out past a stop are wasted), else None."""
    stop = samples[0].stop if len(samples) == 1 else None
    return None if stop is None else max(1, int(0.1 * stop.period / dt))


def raise_bad(scene, put, drives, v_steps, bad) -> None:
    """Raise the DivergenceError of a bad state found by :func:`roll`, after ``put(state)``
    has put the scene in it."""
    b, step, state = bad
    B = len(drives)
    scene.step_count = step
    if state is None:
        raise _error(scene, drives[b], v_steps[b][-1], b, B, "MuJoCo warned of a bad acceleration on the last step; ")
    put(state)
    raise _error(scene, drives[b], v_steps[b][step - 1], b, B)


class ThreadedEngine(Engine):
    """Open-loop drives on ``mujoco.rollout``: the moments as qfrc_applied controls."""

    name, batched = "threaded", True

    def why_not(self, scene, drive, controller=None) -> Optional[str]:
        return why_not(scene, drive, controller)

    def run(self, scene, drives, v_steps, initial_curvatures, sample_steps, samples, *, nthread=0, progress=None,
            check_every=100, controller=None, meta=None) -> None:
        run(scene, drives, v_steps, initial_curvatures, sample_steps, samples, nthread=nthread)
