"""The ``warp`` engine: the native engine's model (the drive compiled in, the voltages its
actuator's ctrl) stepped by MuJoCo Warp (``mujoco_warp``) in float32, all runs of a batch
as Warp's worlds at once; on a GPU where Warp finds one, else on Warp's CPU device.

What it runs is what the native engine runs (:mod:`mjeap.engines.native`), read out the same
way: the sampled states go back into the native model's MjData (``mj_setState`` +
``mj_kinematics``) and the drive's native read-outs, so the results are the native engine's
to float32 round-off. Optional: ``pip install -e ".[warp]"`` (mujoco-warp, warp-lang).

On the Warp path only (the result's ``meta['warp']`` says both):

* ``mjDSBL_AUTORESET`` cleared: mjeap sets it so that MuJoCo never resets a diverging run
  behind its back; MuJoCo Warp has no automatic reset at all (it refuses the flag), so
  clearing it changes nothing: a diverging run is caught at its samples here.
* where the model can make no constraint row (contact disabled, no equality, limit or
  friction loss: every beam scene), the implicit step goes without the constraint solver
  (:func:`_smooth_step`): its factor of the mass matrix alone goes NaN in float32 on seed
  000's standing beam with its payload (condition number 4.7e7), the step itself does not.

Refused before any work, with the reason in words: a controller (the voltages are the
batch's, fixed before the run), a drive stepped from Python (no native form), the rod's
flex (Warp refuses Newton with flex under the ``discrete`` integrator and it goes NaN under
CG), a state beyond time, positions, velocities and activations, and any feature MuJoCo Warp
does not implement (its own ``put_model`` checks, named).

Steps go in Warp graphs (CUDA graphs, or Warp's recorded CPU graphs) of a sample interval
each: the ctrl of those steps is written to one device buffer, the graph replays them, and
the state comes back once per sample. Kernels compile once per machine into Warp's kernel
cache (``WARP_CACHE_PATH``; ~50 s on 2 CPU cores for the native Dadras et al. 2021 model).
"""
from __future__ import annotations

import copy
from typing import Optional

import mujoco
import numpy as np

from ..errors import ParameterError
from .base import CONTROLLER_REASON, Engine
from .frame import Decided
from .native import run_native, why_not as native_why_not
from .threaded import MAXVAL, STATE

__all__ = ["WarpEngine", "warp_reason", "CLEARED"]

#: what the Warp path clears in the model, and why (the result's meta['warp']['cleared'])
CLEARED = {"mjDSBL_AUTORESET": "MuJoCo Warp has no automatic reset (it refuses the flag); mjeap sets it only to "
                               "keep MuJoCo from resetting a diverging run, which Warp never does"}
#: how the steps went where no constraint row can arise (meta['warp']['step'])
SMOOTH_STEP = ("mujoco_warp's implicit step without its constraint solver: the model makes no constraint rows, and "
               "the solver's factor of the mass matrix alone fails in float32 on a standing beam with a payload")
INSTALL = 'mujoco-warp is not installed (pip install -e ".[warp]")'


def _warp():
    """(warp, mujoco_warp), imported on first use, quiet (Warp reads its kernel cache folder from
    WARP_CACHE_PATH)."""
    import warp as wp
    import mujoco_warp as mjw
    wp.config.quiet = True
    wp.config.log_level = getattr(wp, "LOG_WARNING", wp.config.log_level)     # no line per module loaded
    wp.init()
    return wp, mjw


def _installed() -> Optional[str]:
    """None where mujoco_warp can be imported (found, not imported: ``auto`` asks this engine
    too); else the extra to install."""
    from importlib.util import find_spec
    return None if find_spec("mujoco_warp") is not None and find_spec("warp") is not None else INSTALL


def _flags(model) -> list:
    """Names of the option flags set in ``model`` that MuJoCo Warp does not implement, less
    those the Warp path clears (:data:`CLEARED`)."""
    from mujoco_warp._src import types
    out = []
    for field, kinds, enum in ((model.opt.disableflags, types.DisableBit, mujoco.mjtDisableBit),
                               (model.opt.enableflags, types.EnableBit, mujoco.mjtEnableBit)):
        known = int(np.bitwise_or.reduce([int(k) for k in kinds]))
        bad = int(field) & ~known
        out += [enum(1 << i).name for i in range(32) if bad >> i & 1]
    return [f for f in out if f not in CLEARED]


def warp_reason(scene, drive, controller=None) -> Optional[str]:
    """None where the warp engine runs this run of ``scene`` with ``drive``; else why not,
    in words of the model."""
    if controller is not None:
        return CONTROLLER_REASON
    if scene.model.nflex:
        return ("the rod's flex under the discrete integrator: MuJoCo Warp refuses Newton with flex there and the "
                "run goes NaN under CG")
    if drive.native_reason() is not None:
        return f"the {drive.name} drive is stepped from Python (no native form: {drive.native_reason()})"
    why = native_why_not(scene, drive)
    if why is not None:
        return why
    missing = _installed()
    if missing is not None:
        return missing
    bad = _flags(scene.model)
    if bad:
        return f"MuJoCo Warp does not implement {', '.join(bad)}, set in the scene's model"
    return None


def _constraint_rows(m) -> list:
    """What can make constraint rows in the native model ``m`` (contacts, equalities, joint
    and tendon limits, friction loss): none in a beam scene with contact disabled."""
    D = mujoco.mjtDisableBit
    sources = {"contacts": not (m.opt.disableflags & D.mjDSBL_CONTACT) and m.ngeom > 0,
               "equality constraints": m.neq > 0, "joint limits": bool(np.any(m.jnt_limited)),
               "tendon limits": bool(np.any(m.tendon_limited)),
               "friction loss": bool(np.any(m.dof_frictionloss) or np.any(m.tendon_frictionloss))}
    return [k for k, v in sources.items() if v]


#: the integrators whose step :func:`_smooth_step` takes
IMPLICIT = (mujoco.mjtIntegrator.mjINT_IMPLICITFAST, mujoco.mjtIntegrator.mjINT_IMPLICIT)


def _smooth_step(m, d) -> None:
    """MuJoCo Warp's implicit(fast) step of a model that makes no constraint rows, without its
    constraint solver: position, velocity, actuation, the smooth forces, then the implicit
    update with the smooth forces as its right-hand side (M qacc = qfrc_smooth exactly, no
    constraint force). Why: with no rows the Newton solver still factors the mass matrix
    alone, whose condition number reaches 4.7e7 on Dadras et al. 2021's standing beam with its
    12.6 mg payload (363 times a link's mass), beyond float32 (1 / eps = 1.7e7): the factor went
    NaN at step 1215 of the 1.333 V run. The implicit update factors M + h D (condition
    ~100 there) and never needs M alone. Sensors are not evaluated (none is read back)."""
    import warp as wp
    import mujoco_warp as mjw
    mjw.fwd_position(m, d, factorize=False)
    mjw.fwd_velocity(m, d)
    mjw.fwd_actuation(m, d)
    mjw.fwd_acceleration(m, d)
    wp.copy(d.efc.Ma, d.qfrc_smooth)
    mjw.implicit(m, d)


def _state_reason(m) -> Optional[str]:
    """None where the full-physics state of the native model ``m`` is time, qpos, qvel and
    act only (what Warp's data carries back); else what else it holds."""
    extra = mujoco.mj_stateSize(m, STATE) - (1 + m.nq + m.nv + m.na)
    return None if extra == 0 else (f"the native model's state holds {extra} values beyond time, positions, "
                                    "velocities and activations (actuator or sensor history, plugin or plastic "
                                    "state), which the warp engine does not carry")


class _Worlds:
    """The native model on Warp: the model (flags cleared), ``B`` worlds' data, a ctrl
    buffer and the step graphs by their length; kept on the native model per batch size."""

    def __init__(self, m, B: int):
        wp, mjw = _warp()
        self.wp, self.mjw, self.m, self.B = wp, mjw, m, B
        mm = copy.copy(m)       # the native engine's model is left as it is
        mm.opt.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)      # CLEARED: Warp has no reset
        try:
            self.model = mjw.put_model(mm)
            d = mujoco.MjData(mm)
            mujoco.mj_forward(mm, d)
            self.data = mjw.put_data(mm, d, nworld=B)
        except (NotImplementedError, ValueError) as e:
            raise ParameterError("engine", "warp", "a model MuJoCo Warp implements",
                                 f"MuJoCo Warp refuses the native model: {e}") from e
        self.ctrl = wp.zeros((1, B, m.nu), dtype=float)
        self.graphs = {}
        #: MuJoCo Warp's step, or where nothing can make a constraint row, the same step without
        #: the constraint solver (:func:`_smooth_step`)
        self.smooth = (not _constraint_rows(m) and m.opt.integrator in IMPLICIT
                       and self.data.efc.Ma.shape == self.data.qfrc_smooth.shape)
        self.step = _smooth_step if self.smooth else mjw.step
        self.device = str(wp.get_device())

    def _graph(self, L: int):
        """The graph of ``L`` steps, step i's ctrl from row i of the ctrl buffer."""
        if L not in self.graphs:
            wp = self.wp
            if self.ctrl.shape[0] < L:
                self.ctrl = wp.zeros((L, self.B, self.m.nu), dtype=float)
                self.graphs.clear()
            if not self.graphs:         # compile (or load) every kernel before the first capture
                self.step(self.model, self.mjw.put_data(self.m, mujoco.MjData(self.m), nworld=1))
            with wp.ScopedCapture() as cap:
                for i in range(L):
                    wp.copy(self.data.ctrl, self.ctrl[i])
                    self.step(self.model, self.data)
            self.graphs[L] = cap.graph
        return self.graphs[L]

    def put(self, states: np.ndarray) -> None:
        """Set every world's time, qpos, qvel, act from full-physics states (B, nstate)."""
        m, d = self.m, self.data
        nq, nv, na = m.nq, m.nv, m.na
        d.time.assign(states[:, 0].astype(np.float32))
        d.qpos.assign(states[:, 1:1 + nq].astype(np.float32))
        d.qvel.assign(states[:, 1 + nq:1 + nq + nv].astype(np.float32))
        if na:
            d.act.assign(states[:, 1 + nq + nv:1 + nq + nv + na].astype(np.float32))

    def get(self, template: np.ndarray) -> np.ndarray:
        """The worlds' full-physics states (B, nstate), float64, on ``template``'s other parts."""
        m, d = self.m, self.data
        nq, nv, na = m.nq, m.nv, m.na
        out = template.copy()
        out[:, 0] = d.time.numpy()
        out[:, 1:1 + nq] = d.qpos.numpy()
        out[:, 1 + nq:1 + nq + nv] = d.qvel.numpy()
        if na:
            out[:, 1 + nq + nv:1 + nq + nv + na] = d.act.numpy()
        return out

    def steps(self, ctrl: np.ndarray) -> None:
        """Step all worlds ``ctrl.shape[1]`` times, world b's ctrl of step i ``ctrl[b, i]``."""
        L = ctrl.shape[1]
        if L == 0:
            return
        graph = self._graph(L)
        self.ctrl[:L].assign(np.ascontiguousarray(np.swapaxes(ctrl, 0, 1), dtype=np.float32))
        self.wp.capture_launch(graph)


def _worlds(native, B: int) -> _Worlds:
    """The Warp worlds of ``native`` (a NativeModel) for batches of ``B`` runs, built once."""
    held = native.__dict__.setdefault("_warp_worlds", {})
    if B not in held or held[B].m is not native.model:
        held[B] = _Worlds(native.model, B)
    return held[B]


def _first_bad(states: np.ndarray, k: int):
    """(run, step, state) of the first run whose state after step ``k`` is bad (not finite or
    beyond mjMAXVAL, as :func:`mjeap.engines.threaded.roll` counts it); None: all good. Warp
    does not stop a diverging world, so the step is the sample's: it diverged by then."""
    good = (np.abs(states[:, 1:]) < MAXVAL).all(axis=1)          # NaN fails too
    if good.all():
        return None
    b = int(np.argmin(good))
    return b, k, states[b]


def _roller(native, meta: Optional[dict]):
    """A :func:`mjeap.engines.threaded.roll` on Warp for :func:`mjeap.engines.native.run_native`:
    the same arguments and returns (``take`` at every sample with its state and the one
    before, the first bad state found at a sample), float32 states read back per sample."""

    def roll(model, state0, controls, ncontrol, control_spec, n, sample_steps, take, *, nthread=0, max_chunk=None,
             spares=None):
        B = len(state0)
        w = _worlds(native, B)
        if meta is not None:
            meta["warp"] = {"device": w.device, "float": "float32", "cleared": dict(CLEARED), "worlds": B,
                            "step": SMOOTH_STEP if w.smooth else "mujoco_warp.step"}
        nu = model.nu
        loads = None
        if control_spec & mujoco.mjtState.mjSTATE_XFRC_APPLIED:
            probe = np.empty((B, 1, ncontrol))
            controls(0, 1, probe)
            loads = probe[:, 0, nu:].reshape(B, model.nbody, 6)
        w.put(state0)
        if loads is not None:
            w.data.xfrc_applied.assign(loads.astype(np.float32))
        ctl = np.empty((B, 0, ncontrol))
        before = state = state0
        done = 0

        def advance(to: int) -> np.ndarray:
            """Step every world from step ``done`` to step ``to``; their states then."""
            nonlocal done, ctl
            c = to - done
            if ctl.shape[1] < c:
                ctl = np.empty((B, c, ncontrol))
            controls(done, c, ctl[:, :c])
            w.steps(ctl[:, :c, :nu])
            done = to
            return w.get(state0)

        for k in sample_steps[1:]:
            k = int(k)
            if k - done > 1:
                before = advance(k - 1)
            elif k > 1:
                before = state
            state = advance(k)
            bad = _first_bad(state, k)
            if bad is not None:
                return None, bad, None
            for b in range(B):
                try:
                    take(b, k, state[b], before[b])
                except Decided as stop:     # the run ends here (Samples.stop): its state goes with it
                    stop.step, stop.state, stop.before = k, np.array(state[b]), np.array(before[b])
                    raise
        if done < n:
            before = advance(n - 1) if n - done > 1 else (state if done else state0)
            state = advance(n)
            bad = _first_bad(state, n)
            if bad is not None:
                return None, bad, None
        return state, None, before

    return roll


class WarpEngine(Engine):
    """The native model on MuJoCo Warp, float32 batches (:mod:`mjeap.engines.warp`)."""

    name, batched = "warp", True

    def why_not(self, scene, drive, controller=None) -> Optional[str]:
        return warp_reason(scene, drive, controller)

    def part(self, scene, drive):
        return scene.native_model(drive).part

    def run(self, scene, drives, v_steps, initial_curvatures, sample_steps, samples, *, nthread=0, progress=None,
            check_every=100, controller=None, meta=None) -> None:
        native = scene.native_model(drives[0])
        why = _state_reason(native.model)
        if why is not None:
            raise ParameterError("engine", "warp", "a run the warp engine applies to", why)
        _worlds(native, len(drives))            # refused here, before any step, where Warp refuses the model
        run_native(scene, native, drives, v_steps, initial_curvatures, sample_steps, samples, nthread=nthread,
                   roller=_roller(native, meta))
