"""Several actuators in one system with other bodies and contact.

:func:`attach` (:mod:`mjeap.simulation.attach`) places an actuator into a user's ``MjSpec``;
:class:`System` compiles the host with its attached actuators: the timestep is the
smallest of the actuators' own choices (each already below its stability limit), contact
parameters are set for micro scale (:class:`ContactParameters`), and the model declares its
units in ``mjeap_units``. Each actuator is an :class:`~mjeap.simulation.part.ActuatorPart` with
SI read-outs in its own clamp frame; rollouts take one voltage per actuator.

Units: the host is written in the internal units the caller declares (``units``, default
mjeap's mm, mg, ms); a host in SI is refused where a beam's segments would fall below
MuJoCo's 1e-15 floors, with the part named and a unit system that works.
"""
from __future__ import annotations

from pathlib import Path
from typing import List, Optional, Sequence, Union

import mujoco
import numpy as np

from .attach import (AttachedActuator, add_transmission, attach, check_finite_model, check_spec,  # noqa: F401
                     host_gravity)
from .contact import ContactParameters
from .part import ActuatorPart
from ..errors import DivergenceError, ParameterError, UnknownNameError, check_positive
from ..io.outputs import guarded
from ..versions import newton_sparse_broken
from ..engines.frame import check_work, one_voltage
from ..engines.result import SystemResult
from ..model.fields import add_units, apply_dof_damping
from .scene import INTEGRATORS, diverged, input_files
from ..units import DEFAULT_UNITS, UnitSystem

#: the system and what is attached to it (:func:`attach`, :func:`add_transmission`,
#: :class:`ContactParameters` are re-exported here, where they were first documented)
__all__ = ["System", "SystemResult", "SYSTEM_TIMESTEP", "attach", "add_transmission", "AttachedActuator",
           "ContactParameters"]

#: what to change when a voltage is above a system's Nyquist frequency: the system's step
#: (its actuators' twin Scenes do not set it)
SYSTEM_TIMESTEP = "pass a smaller timestep to the System (System(spec, actuators, timestep=...))"


class System:
    """A compiled MuJoCo system: a host ``spec`` with ``actuators`` attached by
    :func:`attach` (all in ``units``), other bodies, joints, constraints and contact.
    ``timestep`` (s) defaults to the smallest of the actuators' own choices; one beyond an
    actuator's limits (:meth:`~mjeap.Scene.check_timestep`: stability, and under 'discrete'
    accuracy and beta / 2) is refused with the limit; under 'discrete' the hinges' damping
    is (beta - h) k of the system's h. The host's flags and gravity must still be those the
    actuators were attached under. The integrator is the actuators' (they were attached for one:
    'discrete' with contact, see :func:`attach`); ``integrator`` is needed only without
    actuators. ``contact``: :class:`ContactParameters` (None: the host's own). ``loaded``: the
    actuators drive heavy host parts (a transmission and a leg on each tip), so their loaded
    modes, not the free beam's, set the dynamics: a given ``timestep`` is then checked only
    against each actuator's stability limit (none under 'discrete', which takes the beam's
    springs implicitly), not against the free beam's accuracy (T_1 / 50) and damping (beta /
    2) limits, and the caller sizes it for the loaded system and checks it (e.g. against a
    run at half the step: :meth:`half_step`). Above beta the step's own damping h K
    exceeds the beam's Rayleigh damping (the joints then carry none)."""

    def __init__(self, spec: mujoco.MjSpec, actuators: Sequence[AttachedActuator], units: Optional[UnitSystem] = None,
                 timestep: Optional[float] = None, integrator: Optional[str] = None,
                 contact: Optional[ContactParameters] = ContactParameters(), *, loaded: bool = False):
        check_spec(spec)
        self.units = units = units or DEFAULT_UNITS
        self.actuators = list(actuators)
        prefixes = [a.prefix for a in self.actuators]
        if len(set(prefixes)) != len(prefixes):
            raise ParameterError("actuators", prefixes, "actuators with distinct prefixes")
        for a in self.actuators:
            if a.twin.units != units:
                raise ParameterError("units", units.describe(), f"the units actuator '{a.prefix}' was attached in "
                                     f"({a.twin.units.describe()}): pass the same units= to attach and System")
        used = {a.twin.integrator for a in self.actuators}
        if len(used) > 1 or (integrator is not None and used and used != {integrator}):
            raise ParameterError("integrator", integrator or sorted(used), "one integrator for every actuator "
                                 f"(attached with {', '.join(f'{a.prefix} {a.twin.integrator}' for a in self.actuators)}): "
                                 "pass the same integrator= (or contact=) to attach")
        integrator = integrator or (used.pop() if used else "implicitfast")
        if integrator not in INTEGRATORS:
            raise ParameterError("integrator", integrator, f"one of {', '.join(INTEGRATORS)}")
        self.integrator = integrator
        if self.actuators:
            # the host's flags and gravity now, against those each twin was sized for at attach
            g = host_gravity(spec.option, driven=any(a.drive is not None for a in self.actuators))
            for a in self.actuators:
                g_twin = a.twin.model.opt.gravity * units.acceleration
                if not np.allclose(g * units.acceleration, g_twin, rtol=2e-3):
                    raise ParameterError(
                        "spec.option.gravity", f"{g * units.acceleration} m/s^2 (with its gravity flag)",
                        f"the gravity actuator '{a.prefix.rstrip('/')}' was attached under, {g_twin} m/s^2",
                        "its damping and timestep were chosen for that gravity: set the host's gravity and its flag "
                        "before attach")
        self.loaded = bool(loaded)
        if timestep is None:
            if not self.actuators:
                raise ParameterError("timestep", None, "a timestep in s for a system without actuators")
            h = min(a.twin.timestep for a in self.actuators)
            self.timestep_reason = "the smallest of the actuators' own timesteps"
        else:
            h = check_positive("timestep", timestep, "s")
            for a in self.actuators:          # stability; accuracy and the joints' damping under discrete
                if not loaded:
                    a.twin.check_timestep(timestep)
                elif timestep > a.twin.choice.stability_limit:
                    raise ParameterError("timestep", timestep, f"a timestep <= {a.twin.choice.stability_limit:.4g} s",
                                         f"the stability limit of actuator '{a.prefix.rstrip('/')}'")
            self.timestep_reason = "given by the user" + (" for the loaded system (stability checked)" if loaded else "")
        self.spec = spec
        for a in self.actuators:
            if a.twin.builder.implicit_stiffness(a.twin.integrator):
                # discrete damps the beam by h K itself: the joints carry beta - h of the system's h
                for name, b in zip(a.joints, a.twin.joint_damping(h)):
                    spec.joint(name).damping = [float(b), 0.0, 0.0]
        spec.option.timestep = h / units.time
        spec.option.integrator = INTEGRATORS[integrator]
        spec.option.disableflags |= int(mujoco.mjtDisableBit.mjDSBL_AUTORESET)
        if newton_sparse_broken():          # MuJoCo 4.0.0's sparse Cholesky bug (mjeap.versions)
            spec.option.jacobian = mujoco.mjtJacobian.mjJAC_DENSE
        if contact is not None and any(a.contact for a in self.actuators):
            t_min = min(a.twin.layout.thickness for a in self.actuators if a.contact) / units.length
            contact.apply(spec, h / units.time, t_min, units.length)
        self.contact = contact
        add_units(spec, units)
        try:
            model = spec.compile()
        except ValueError as e:
            raise ParameterError("spec", spec.modelname, "a host model that compiles with its actuators",
                                 str(e).splitlines()[0]) from None
        self.model = apply_dof_damping(model)         # a cable's per-dof damping (PREFIX/mjeap_dof_damping)
        check_finite_model(self.model)
        self.data = mujoco.MjData(self.model)
        m = self.model
        self.parts: List[ActuatorPart] = []
        self.actuator_ids: List[int] = []
        for a in self.actuators:
            tw = a.twin
            clamp = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, a.prefix + tw.handles.clamp_body)
            fixed = m.body_weldid[clamp] == 0          # welded to the world: a constant clamp frame
            part = ActuatorPart(m, tw.handles, tw.layout, tw.actuator, units, tw.representation, payload=tw.payload,
                                prefix=a.prefix, rotation=None)
            part.bind(self.data)
            if fixed:
                mujoco.mj_kinematics(m, self.data)
                part.fix_rotation(self.data.xmat[clamp].reshape(3, 3))
            self.parts.append(part)
            self.actuator_ids.append(-1 if a.actuator_name is None else
                                     mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, a.actuator_name))
        #: steps since the last reset (the engines that step the system advance it)
        self.step_count = 0
        self.reset()

    # ------------------------------------------------------------------ access
    def __len__(self) -> int:
        return len(self.actuators)

    def index(self, prefix: str) -> int:
        names = [a.prefix.rstrip("/") for a in self.actuators]
        p = prefix.rstrip("/")
        if p not in names:
            raise UnknownNameError("actuator prefix", p, names)
        return names.index(p)

    def part(self, prefix: str) -> ActuatorPart:
        """The actuator attached under ``prefix``: SI read-outs in its clamp frame."""
        return self.parts[self.index(prefix)]

    @property
    def timestep(self) -> float:
        return self.model.opt.timestep * self.units.time

    @property
    def time(self) -> float:
        return self.data.time * self.units.time

    def drive_observer(self, prefix: str):
        """A copy of the drive of the actuator under ``prefix`` that reads this system's beam
        and never acts on it (the native model drives it): call its ``step(v, dt)`` with the
        voltage (V) held over each step, in lockstep with :meth:`step`, and its
        ``signals()`` (the drive current, A, ...) read what a lockstep loop would, e.g. for
        a controller that senses the actuator's own current."""
        from ..drives import make_drive
        from ..drives.base import ReadOnlyPart
        i = self.index(prefix)
        a = self.actuators[i]
        if a.drive is None:
            raise ParameterError("prefix", prefix, "an actuator attached with a drive (this one is passive)")
        obs = make_drive(a.drive.name, a.twin, **a.drive.params)
        obs.part = ReadOnlyPart(self.parts[i])
        obs.reset()
        return obs

    # ------------------------------------------------------------------ state
    def reset(self, initial_curvatures: Union[float, Sequence[float]] = 0.0) -> None:
        """Reset to the host's qpos0 with each beam a uniform arc of its initial curvature
        (1/m), the drives at rest there (relaxation holding the shape, no charge)."""
        k0 = self._per_actuator("initial_curvatures", initial_curvatures)
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        mujoco.mj_kinematics(m, d)           # the clamp frames, the tip moments' axes
        from ..engines.frame import check_initial_curvature
        for p, k in zip(self.parts, k0):
            p.after_data_reset()
            k = check_initial_curvature(k, p.layout.length, "initial_curvatures")
            if k:
                p.set_hinge_angles(np.full(p.layout.segments, float(k) * p.layout.ds), forward=False)
        mujoco.mj_forward(m, d)
        for a, p in zip(self.actuators, self.parts):
            if a.drive is not None:
                a.drive.native_reset(p, a.native, a.prefix)
        for a, i in zip(self.actuators, self.actuator_ids):
            if i >= 0:
                d.ctrl[i] = a.drive.rest_voltage()
        self.step_count = 0

    def _per_actuator(self, name: str, values) -> list:
        """One value per actuator from a list, a dict by prefix or one value for all; a bare
        text (a waveform) is one actuator's, so only a system of one takes it."""
        if isinstance(values, str):
            if len(self) == 1:
                return [values]
            raise ParameterError(name, values, f"one per actuator ({len(self)}: "
                                 f"{', '.join(a.prefix.rstrip('/') for a in self.actuators)}) as a list or a dict "
                                 "by prefix: a single text is taken for a system of one actuator only")
        if np.ndim(values) == 0 and not isinstance(values, dict):
            return [values] * len(self)
        if isinstance(values, dict):
            out = [None] * len(self)
            for k, v in values.items():
                out[self.index(k)] = v
            return out
        values = list(values)
        if len(values) != len(self):
            raise ParameterError(name, f"{len(values)} values", f"one per actuator ({len(self)}: "
                                 f"{', '.join(a.prefix.rstrip('/') for a in self.actuators)}) or a dict by prefix")
        return values

    def set_voltages(self, voltages: Sequence[float]) -> None:
        """Hold these voltages (V), one per actuator, from now on (the actuators' ctrl)."""
        for a, i, v in zip(self.actuators, self.actuator_ids, self._per_actuator("voltages", voltages)):
            if i < 0 or v is None:
                continue
            v = one_voltage(v, f"voltage of '{a.prefix.rstrip('/')}'")
            a.drive.check_voltage(np.asarray([v], dtype=float))
            self.data.ctrl[i] = v

    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps; raises :class:`DivergenceError` if the state blows up."""
        mujoco.mj_step(self.model, self.data, nstep=n)
        self.step_count += n
        self.check_finite()
        mujoco.mj_kinematics(self.model, self.data)

    def check_finite(self) -> None:
        if diverged(self.data):
            raise DivergenceError(
                f"system of {len(self)} actuators diverged by step {self.step_count} (t = {self.time:.6g} s): "
                f"timestep {self.timestep:.4g} s ({self.timestep_reason}); check the host's bodies, joints and "
                "contacts (a stiff or light part may need a smaller timestep)")

    # ------------------------------------------------------------------ contact
    def contact_forces(self) -> np.ndarray:
        """Net contact force (N, world frame) on every body at the present state, (nbody, 3)."""
        m, d = self.model, self.data
        out = np.zeros((m.nbody, 3))
        f6 = np.zeros(6)
        for i in range(d.ncon):
            c = d.contact[i]
            mujoco.mj_contactForce(m, d, i, f6)
            fw = c.frame.reshape(3, 3).T @ f6[:3]        # force of geom1 on geom2, world
            out[m.geom_bodyid[c.geom2]] += fw
            out[m.geom_bodyid[c.geom1]] -= fw
        return out * self.units.force

    def penetration(self) -> float:
        """Deepest penetration (m) among the present contacts (0 if none)."""
        d = self.data
        dist = [d.contact[i].dist for i in range(d.ncon)]
        return max(0.0, -min(dist, default=0.0)) * self.units.length

    def hold_voltages(self, voltages, v_steps, k: int, who: str) -> None:
        """Hold a controller's ``voltages`` (V) from step ``k`` on, each checked first: one
        number per actuator (or one for all, or a dict by prefix; None: unchanged)."""
        t = self.time
        try:
            if isinstance(voltages, (str, bytes)):
                raise ValueError
            listed = isinstance(voltages, (list, tuple)) and len(voltages) == len(self)    # checked one by one
            values = list(voltages) if listed else self._per_actuator("controller voltages", voltages)
        except (ParameterError, ValueError, TypeError):      # text, a wrong length, ragged
            shown = voltages if isinstance(voltages, (str, bytes)) else \
                f"{len(voltages)} values" if hasattr(voltages, "__len__") else type(voltages).__name__
            raise ParameterError("controller voltages", shown, f"one number (V) for all or one per actuator "
                                 f"({len(self)}: {', '.join(a.prefix.rstrip('/') for a in self.actuators)}), "
                                 "or a dict by prefix", f"{who} at t = {t:.6g} s") from None
        for a, vs, v in zip(self.actuators, v_steps, values):
            if vs is None:
                continue
            if v is None:
                if k:
                    vs[k] = vs[k - 1]
                continue
            v = one_voltage(v, f"controller voltage of '{a.prefix.rstrip('/')}'", f"{who} at t = {t:.6g} s")
            lo, hi = a.drive.voltage_range()
            if not (lo - 1e-12 <= v <= hi + 1e-12):
                raise ParameterError(f"controller voltage of '{a.prefix.rstrip('/')}'", f"{v:.6g} V at t = {self.time:.6g} s",
                                     f"a voltage in the safe range [{lo:g}, {hi:g}] V of {a.twin.actuator.id}")
            vs[k] = v

    # ------------------------------------------------------------------ rollout
    @guarded("rrd", inputs=lambda a: input_files(
        [x.twin for x in a["self"].actuators],
        list(a["voltages"].values()) if isinstance(a["voltages"], dict) else
        (a["voltages"] if isinstance(a["voltages"], (list, tuple)) else [a["voltages"]])))
    def rollout(self, voltages, duration: float, *, initial_curvatures: Union[float, Sequence[float]] = 0.0,
                sample_interval: Optional[float] = None, rrd: Union[str, Path, None] = None,
                on_sample=None, controller=None, engine: str = "auto", estimate_error: bool = False) -> SystemResult:
        """Run for ``duration`` s with one voltage per actuator (waveform text,
        :class:`~mjeap.Waveform`, callable v(t) or None for its rest voltage; a list or a dict
        by prefix). Returns a :class:`SystemResult`; with ``rrd`` a Rerun recording (written
        also when the run fails or is stopped by Ctrl-C or SIGTERM: it then ends with the
        error; a second writer is refused, :func:`mjeap.io.outputs.guarded`). ``on_sample(system)``
        is called at every sample (e.g. to move a mocap body). ``controller(t, system)``
        (``voltages`` then None; a plain function or an object, the one contract of
        :func:`mjeap.rollout`, :func:`mjeap.engines.frame.check_controller`: its ``reset(system,
        None)``, ``interval`` and ``name`` are used when present) is called before every step
        (every ``interval``) and returns the voltages (V) to hold until its next call, one per
        actuator or a dict by prefix (None: unchanged); each is checked against its drive's
        safe range. It may read the system's state; a controller that
        senses an actuator's current steps a :meth:`drive_observer` with them. ``engine``: one
        that runs systems (:func:`mjeap.engines.choose_system`; 'auto': the loop engine).
        ``estimate_error``: each actuator's tip-curvature error from the timestep, against the
        system at half the step (:func:`mjeap.simulation.accuracy.estimate_system_error`; 2 x
        the cost; open loop without ``on_sample``), in ``meta['accuracy']``."""
        from ..engines.frame import check_controller, to_waveform
        from . import pipeline
        duration = check_positive("duration", duration, "s")
        ctrl_name = None if controller is None else check_controller(controller)
        if estimate_error and (controller is not None or on_sample is not None):
            raise ParameterError("estimate_error", estimate_error, "False with a controller or on_sample: the "
                                 "companion run at half the step would call them again (they may keep state or "
                                 "move the model)")
        if estimate_error:
            for p in self.parts:
                p.check_derivable()
        if controller is not None:
            if voltages is not None and any(v is not None for v in self._per_actuator("voltages", voltages)):
                raise ParameterError("voltages", voltages, "None when a controller sets the voltages")
            voltages = None
        waves = [None if w is None else to_waveform(w, duration) for w in self._per_actuator("voltages", voltages)]
        check_work(duration, self.timestep)
        for a, w in zip(self.actuators, waves):
            if a.drive is None and w is not None:
                raise ParameterError("voltages", getattr(w, "text", w), f"None for the passive actuator '{a.prefix}'")
        # a waveform is checked against the drive's safe range (the plan); the rest voltage (None) is in it
        return pipeline.run(pipeline.Job(
            self, tuple(waves), tuple(a.drive for a in self.actuators), duration, initial_curvatures,
            sample_interval=sample_interval, engine=engine, controller=controller, controller_name=ctrl_name,
            on_sample=on_sample, estimate_error=estimate_error, remedy=SYSTEM_TIMESTEP, rrd=rrd))

    def describe_run(self, waves, controller, ctrl_name: Optional[str], duration: float) -> dict:
        """What a run of this system describes in its meta (:func:`mjeap.simulation.pipeline.plan`
        adds the provenance, steps and engine)."""
        return {"actuators": {a.prefix.rstrip("/"): {"actuator": a.twin.actuator.id,
                                                     "drive": None if a.drive is None else a.drive.describe(),
                                                     "voltage": (f"controller: {ctrl_name}" if controller is not None
                                                                 and a.drive is not None else
                                                                 None if w is None else getattr(w, "text", str(w)))}
                              for a, w in zip(self.actuators, waves)},
                "duration_s": duration, "timestep_s": self.timestep, "timestep_reason": self.timestep_reason,
                "units": self.units.describe()}

    def half_step(self) -> "System":
        """This system at half its timestep: a copy of its spec with the same actuators,
        integrator and contact parameters (contact's time constant, in steps, halves with it),
        and the tip loads set on its actuators."""
        for p in self.parts:
            p.check_derivable()
        half = System(self.spec.copy(), self.actuators, self.units, timestep=self.timestep / 2,
                      integrator=self.integrator, contact=self.contact, loaded=self.loaded)
        for p, q in zip(self.parts, half.parts):
            p.carry_loads(q)
        return half
