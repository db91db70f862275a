"""The stepping frame of a :class:`mjeap.System`'s run (a :class:`mjeap.engines.SystemTarget`):
what acts over every step (the ctrl held, a controller's voltages), the samples (each
actuator's store, the bodies' poses and contact forces) and the divergence check, handed to
the engine that steps the system (:meth:`mjeap.engines.Engine.run_system`); its result a
:class:`mjeap.engines.result.SystemResult`. A scene's run has its frame in each engine."""
from __future__ import annotations

from typing import Optional

import mujoco
import numpy as np

from .frame import controller_every, reset_controller
from .result import SystemResult

__all__ = ["SystemRun"]


class SystemRun:
    """One planned run of ``system`` (``plan``: :class:`mjeap.simulation.pipeline.Plan`) from
    its reset state at ``initial_curvatures`` (1/m): :meth:`run` steps it on the plan's
    engine, :meth:`result` is the :class:`SystemResult` of the samples taken.
    ``on_sample(system)`` is called at every sample; ``controller`` (named ``ctrl_name``)
    sets the voltages, checked by the system (:meth:`mjeap.System.hold_voltages`)."""

    def __init__(self, system, plan, initial_curvatures, *, on_sample=None, controller=None,
                 ctrl_name: Optional[str] = None):
        self.system, self.plan = system, plan
        self.on_sample, self.controller, self.ctrl_name = on_sample, controller, ctrl_name
        m = system.model
        ns, nb = len(plan.sample_steps), m.nbody
        self.pos, self.quat, self.fc = np.empty((ns, nb, 3)), np.empty((ns, nb, 4)), np.empty((ns, nb, 3))
        system.reset(initial_curvatures)
        for a, v in zip(system.actuators, plan.v_steps):
            if v is not None:
                a.drive.native_prepare(v, system.timestep)
        self.active = [(i, v) for i, v in zip(system.actuator_ids, plan.v_steps) if v is not None]
        self._ws = np.empty(m.nv)
        # the state before each sampled step: a drive's signals replay that step from it
        # (the piezo bimorph's motional current is at the held voltage's instant)
        self._full = mujoco.mjtState.mjSTATE_FULLPHYSICS
        self._pre = np.empty(mujoco.mj_stateSize(m, self._full))
        self._sampled = np.zeros(plan.n_steps + 1, dtype=bool)
        self._sampled[plan.sample_steps] = True
        self._ctrl_every = 1

    def sample(self, i: int, k: int) -> None:
        """Sample ``i``, after step ``k``: each actuator's store, the bodies' poses and the
        contact forces at this state (the warm start kept as the step left it)."""
        s, d = self.system, self.system.data
        self._ws[:] = d.qacc_warmstart
        mujoco.mj_forward(s.model, d)
        d.qacc_warmstart[:] = self._ws
        for a, p, smp, v in zip(s.actuators, s.parts, self.plan.samples, self.plan.v_steps):
            sig = {} if a.drive is None else a.drive.native_signals(k, p, a.native, a.prefix,
                                                                    before=self._pre if k else None)
            smp.take(k * s.timestep, np.nan if v is None else v[max(k - 1, 0)], sig)
        self.pos[i] = d.xpos * s.units.length
        self.quat[i] = d.xquat
        self.fc[i] = s.contact_forces()
        if self.on_sample is not None:
            self.on_sample(s)

    def before(self, k: int) -> None:
        """What acts over step ``k``: a controller's voltages (held between its calls), the
        actuators' ctrl; the state kept where the step ends on a sample."""
        s, v_steps = self.system, self.plan.v_steps
        if self.controller is not None and k:
            if k % self._ctrl_every == 0:
                s.hold_voltages(self.controller(k * s.timestep, s), v_steps, k, self.ctrl_name)
            else:
                for vs in v_steps:
                    if vs is not None:
                        vs[k] = vs[k - 1]
        d = s.data
        for i, v in self.active:
            d.ctrl[i] = v[k]
        if self._sampled[k + 1]:
            mujoco.mj_getState(s.model, d, self._pre, self._full)

    def check(self, done: int, k: int) -> None:
        """Raise on a diverged state after ``done`` steps."""
        self.system.step_count = done
        self.system.check_finite()

    def run(self) -> None:
        """Step the system on the plan's engine (:func:`mjeap.engines.run_system_checked`)."""
        from . import run_system_checked
        s, plan = self.system, self.plan
        if self.controller is not None:          # the voltage over step 0 is the first sample's
            reset_controller(self.controller, s, None)
            self._ctrl_every = controller_every(self.controller, s.timestep)
            s.hold_voltages(self.controller(0.0, s), plan.v_steps, 0, self.ctrl_name)
        run_system_checked(plan.engine, s, plan.n_steps, plan.sample_steps, self.before, self.sample, self.check)
        s.step_count = plan.n_steps

    def result(self) -> SystemResult:
        """The :class:`SystemResult` of the samples taken (each actuator's result by prefix)."""
        s, samples = self.system, self.plan.samples
        n = samples[0].n if samples else 0
        results = {}
        for a, smp in zip(s.actuators, samples):
            r = smp.result(a.drive, 0.0, dict(self.plan.meta))
            r.reference_curvature = None if a.drive is None else r.reference_curvature
            results[a.prefix.rstrip("/")] = r
        m = s.model
        names = [mujoco.mj_id2name(m, mujoco.mjtObj.mjOBJ_BODY, b) or f"body{b}" for b in range(m.nbody)]
        return SystemResult(samples[0].t[:n] if samples else np.zeros(0), results, names, self.pos[:n],
                            self.quat[:n], self.fc[:n], self.plan.meta)
