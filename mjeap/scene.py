"""A compiled, ready-to-step beam scene: model building, damping and timestep choice,
loads, stepping with divergence checks, and SI read-outs.

Damping and timestep are derived from the compiled model, never tuned by hand:

1. Linearise (``mjeap.modes``) and find the first bending mode omega_1 of the scene
   (payload and gravity included) and the highest discrete mode.
2. Joint damping is stiffness-proportional (Rayleigh), b_j = beta k_j with
   beta = 2 zeta_1 / omega_1, so the first mode has the catalog's damping ratio zeta_1 and
   mode n has zeta_n = beta omega_n / 2: the stiff discrete modes are overdamped, as
   material damping does to short wavelengths.
3. Under ``implicitfast`` joint damping is implicit but stiffness (joint springs and the
   cable plugin) is explicit, so the step must satisfy the stability limit h_stab of the
   linearised step map (about beta + sqrt(beta^2 + 4/omega_max^2), i.e. ~2 beta for a fine
   chain). Under ``discrete`` joint stiffness is implicit too (hinge chain: no limit; the
   cable plugin stays explicit), at the price of numerical damping ~ omega h / 2.
4. The default timestep is min(T_1 / 50, h_stab / 2): 50 steps per period of the first
   mode keeps its period error below 0.1 %, the factor 2 keeps away from the limit, which
   moves slightly with the large-deflection geometry. A user timestep above h_stab is
   refused with the limit in the message.
"""
from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Optional, Sequence, Union

import mujoco
import numpy as np

from . import analytical
from .catalog import Actuator, get_actuator
from .discretize import BeamLayout, Payload, check_payload, clamp_rotation, discretize
from .errors import DivergenceError, ParameterError, check_positive, check_range
from .mjcf import build_spec, get_builder
from .modes import linearize, modal_frequencies, stability_limit
from .units import DEFAULT_UNITS, UnitSystem

STEPS_PER_PERIOD = 50
STABILITY_SAFETY = 0.5
SETTLING_DAMPING_RATIO = 0.3
INTEGRATORS = {"implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE}
DEFAULT_SEGMENTS = 20
#: tip angle (rad) of the uniform arc at which the cable's stability limit is checked
#: besides the straight beam; seed 000's actuator bends to about 1.8 rad
DEFAULT_MAX_BEND = 2.0
DOF_DAMPING_FIELD = "mjeap_dof_damping"


def _as_slice(idx: np.ndarray):
    """A slice equal to an evenly spaced index array (else the array itself)."""
    idx = np.asarray(idx)
    if len(idx) > 1 and np.all(np.diff(idx) == idx[1] - idx[0]) and idx[1] > idx[0]:
        return slice(int(idx[0]), int(idx[-1]) + 1, int(idx[1] - idx[0]))
    return idx


def _write_hinge_angles(qpos: np.ndarray, qposadr: np.ndarray, angles, hinge: bool) -> None:
    """Write bending angles (rad) about the local z axis into ``qpos``: hinge joints take
    the angle, ball joints (cable) the quaternion of that rotation."""
    if hinge:
        qpos[qposadr] = angles
    else:
        half = 0.5 * np.asarray(angles, dtype=float)
        qpos[qposadr] = np.cos(half)
        qpos[qposadr + 1] = 0.0
        qpos[qposadr + 2] = 0.0
        qpos[qposadr + 3] = np.sin(half)


def _floor_sig(x: float, digits: int) -> float:
    e = np.floor(np.log10(x)) - (digits - 1)
    return float(np.floor(x / 10**e * (1 + 1e-12)) * 10**e)


def apply_dof_damping(model: mujoco.MjModel) -> mujoco.MjModel:
    """Apply the per-dof Rayleigh damping stored in a generated model (cable), in place."""
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, DOF_DAMPING_FIELD)
    if i >= 0:
        a, n = model.numeric_adr[i], model.numeric_size[i]
        if n != model.nv:
            raise ParameterError(DOF_DAMPING_FIELD, n, f"{model.nv} values (one per dof)")
        model.dof_damping[:] = model.numeric_data[a:a + n]
    return model


def load_mjcf(path: str) -> mujoco.MjModel:
    """Load a model written by mjeap (``assets/mjcf``) with its per-dof damping applied."""
    return apply_dof_damping(mujoco.MjModel.from_xml_path(str(path)))


@dataclass(frozen=True)
class TimestepChoice:
    """How the timestep and damping were chosen (SI)."""

    timestep: float               # s
    stability_limit: float        # s (inf: none)
    accuracy_limit: float         # s, T_1 / STEPS_PER_PERIOD
    first_frequency: float        # Hz, scene's first bending mode (gravity included)
    highest_frequency: float      # Hz, highest discrete mode (elastic)
    damping_ratio: float          # zeta_1
    rayleigh_beta: float          # s
    integrator: str
    buckled: bool                 # reference configuration unstable under gravity
    reason: str

    def as_dict(self) -> dict:
        return dict(self.__dict__)


class Scene:
    """A catalog actuator as a MuJoCo scene. Inputs and outputs in SI.

    Parameters: ``actuator`` (catalog id or :class:`Actuator`), ``representation``
    ('hinge' | 'cable'), ``segments`` (>= 2), ``orientation`` ('horizontal' | 'up' |
    'down'), ``payload`` (:class:`Payload` or 'MASS@POSITION'), ``units`` (internal
    :class:`UnitSystem`), ``timestep`` (s, default from the model), ``integrator``
    ('implicitfast' | 'discrete'), ``damping_ratio`` (first-mode, default from the
    catalog), ``gravity`` (bool), ``max_bend`` (rad: tip angle up to which the cable's
    timestep is checked for stability; the hinge chain needs none).
    """

    def __init__(self, actuator: Union[str, Actuator], representation: str = "hinge",
                 segments: int = DEFAULT_SEGMENTS, orientation: str = "horizontal",
                 payload: Union[Payload, str, None] = None, units: Optional[UnitSystem] = None,
                 timestep: Optional[float] = None, integrator: str = "implicitfast",
                 damping_ratio: Optional[float] = None, gravity: bool = True,
                 max_bend: float = DEFAULT_MAX_BEND):
        self.actuator = get_actuator(actuator)
        get_builder(representation)
        clamp_rotation(orientation)
        if integrator not in INTEGRATORS:
            raise ParameterError("integrator", integrator, f"one of {', '.join(INTEGRATORS)}")
        if isinstance(payload, str):
            payload = Payload.parse(payload)
        self.units = units or DEFAULT_UNITS
        self.representation, self.orientation, self.payload = representation, orientation, payload
        self.integrator = integrator
        self.max_bend = check_range("max_bend", max_bend, 0.0, 2 * np.pi, "rad")
        self.layout: BeamLayout = discretize(self.actuator, segments)
        check_payload(payload, self.layout)
        zeta = self.actuator.damping_ratio.value if damping_ratio is None else \
            check_range("damping_ratio", damping_ratio, 0.0, 10.0)
        self.rotation = clamp_rotation(orientation)

        self.spec, self.handles = build_spec(self.layout, representation, orientation, payload,
                                             self.units, gravity)
        self.spec.option.integrator = INTEGRATORS[integrator]
        self.spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
        self.choice = self._choose_timestep_and_damping(zeta, timestep)
        self.model = apply_dof_damping(self.spec.compile())
        self._data = mujoco.MjData(self.model)
        self._ids()
        self._bind_views()
        self._tip_force_world = np.zeros(3)
        self._tip_moment = 0.0
        self.reset()

    # ------------------------------------------------------------------ construction
    def _choose_timestep_and_damping(self, zeta: float, timestep: Optional[float]) -> TimestepChoice:
        u = self.units
        try:
            model = self.spec.compile()
        except ValueError as e:
            if "mjMINVAL" not in str(e):
                raise
            raise ParameterError(
                "units", u, "units in which segment masses and inertias exceed MuJoCo's 1e-15 floor",
                f"{self.actuator.id}: smallest segment mass {self.layout.link_mass.min() / u.mass:.3g} and "
                f"inertia {self.layout.link_inertia.min() / u.inertia:.3g} in these units; use e.g. the default "
                f"(mm, mg, ms). MuJoCo said: {str(e).splitlines()[0]}") from None
        self.linearization = lin = linearize(model)
        w2_tot = modal_frequencies(lin, with_gravity=True)
        w2_el = modal_frequencies(lin, with_gravity=False)
        buckled = bool(w2_tot[0] <= 0)
        w1 = np.sqrt(w2_tot[0] if not buckled else w2_el[0])
        wmax = np.sqrt(w2_el[-1])
        beta = 2 * zeta / w1
        # Rayleigh damping D = beta K per degree of freedom. A ball joint takes one scalar
        # damping in MJCF, so the cable's per-dof values (bending, in-plane, twist) travel in
        # a custom numeric field that load_mjcf() and the scene apply after compiling.
        dof_damping = beta * np.clip(np.diag(lin.K_elastic), 0.0, None)
        kj = self.layout.hinge_stiffness / u.rotational_stiffness
        for j, name in enumerate(self.handles.joints):
            self.spec.joint(name).damping = [beta * kj[j], 0, 0]
        if self.representation != "hinge":
            self.spec.add_numeric(name=DOF_DAMPING_FIELD, data=list(dof_damping))
        T1 = 2 * np.pi / w1
        h_stab = stability_limit(lin, dof_damping, self.integrator, h_max=T1)
        if self.representation != "hinge":
            # the cable's tangent stiffness stops being diagonal in the joint coordinates
            # once bent (the stiff in-plane direction couples into twist), so diagonal
            # damping no longer damps it: check the design bend too
            bent = self._uniform_arc_qpos(model, self.max_bend)
            h_stab = min(h_stab, stability_limit(linearize(model, qpos=bent), dof_damping,
                                                 self.integrator, h_max=T1))
        h_acc = T1 / STEPS_PER_PERIOD
        if timestep is None:
            # rounded down to 3 significant figures in SI: a clean number that does not
            # depend on the internal units (the limit itself is known to ~1e-4)
            h_si = min(h_acc, STABILITY_SAFETY * h_stab) * u.time
            h = _floor_sig(h_si, 3) / u.time
            reason = (f"min(T1/{STEPS_PER_PERIOD} = {h_acc * u.time:.3g} s, "
                      f"{STABILITY_SAFETY} x stability limit {h_stab * u.time:.3g} s)")
        else:
            h = check_positive("timestep", timestep, "s") / u.time
            if h > h_stab:
                raise ParameterError(
                    "timestep", timestep,
                    f"a timestep <= {h_stab * u.time:.4g} s",
                    f"stability limit of {self.actuator.id} ({self.representation}, {self.layout.segments} "
                    f"segments) under {self.integrator}: highest bending mode {wmax / u.time / 2 / np.pi:.4g} Hz "
                    f"with explicit stiffness, Rayleigh damping beta = {beta * u.time:.3g} s")
            reason = "given by the user"
        self.spec.option.timestep = h
        return TimestepChoice(
            timestep=h * u.time, stability_limit=h_stab * u.time, accuracy_limit=h_acc * u.time,
            first_frequency=w1 / u.time / (2 * np.pi), highest_frequency=wmax / u.time / (2 * np.pi),
            damping_ratio=zeta, rayleigh_beta=beta * u.time, integrator=self.integrator,
            buckled=buckled, reason=reason)

    def _uniform_arc_qpos(self, model: mujoco.MjModel, tip_angle: float) -> np.ndarray:
        q = model.qpos0.copy()
        adr = np.array([model.jnt_qposadr[mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_JOINT, j)]
                        for j in self.handles.joints])
        _write_hinge_angles(q, adr, np.full(len(adr), tip_angle / self.layout.segments),
                            self.representation == "hinge")
        return q

    def _ids(self):
        m, h = self.model, self.handles
        body = lambda n: mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        self.clamp_id = body(h.clamp_body)
        self.link_ids = np.array([body(n) for n in h.link_bodies])
        self.tip_body_id = body(h.tip_body)
        self.tip_site_id = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, h.tip_site)
        self.payload_id = body(h.payload_body) if h.payload_body else -1
        self.joint_ids = np.array([mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_JOINT, n) for n in h.joints])
        self.joint_qpos = m.jnt_qposadr[self.joint_ids]
        self.joint_dof = m.jnt_dofadr[self.joint_ids]
        # the bending dof of each hinge: the hinge itself, or a ball joint's rotation about
        # the local z (hinge) axis
        self.bend_dof = self.joint_dof + (0 if self.representation == "hinge" else 2)
        # the same as slices (views, no copies) when evenly spaced, for the per-step paths
        self._bend_sl = _as_slice(self.bend_dof)
        self._qpos_sl = _as_slice(self.joint_qpos) if self.representation == "hinge" else None
        # a ball joint's bending angle is 2 atan2(q_z, q_w) of its quaternion
        self._quat_sl = None if self.representation == "hinge" else \
            (_as_slice(self.joint_qpos), _as_slice(self.joint_qpos + 3))
        self._inv_moment = 1.0 / self.units.moment
        self._k_bend = self.layout.hinge_stiffness / self.units.rotational_stiffness  # internal units
        self._d0 = m.dof_damping.copy()
        # model views of the bending stiffness and damping, for per-step changes (drives
        # whose stiffness follows the field) without allocation; None if not strided
        jsl = _as_slice(self.joint_ids)
        self._jnt_stiffness_bend = m.jnt_stiffness[jsl] \
            if isinstance(jsl, slice) and self.representation == "hinge" else None
        self._dof_damping_bend = m.dof_damping[self._bend_sl] if isinstance(self._bend_sl, slice) else None
        self._d0_bend = self._d0[self._bend_sl]
        self._stiffness_scale = 1.0
        self.tip_load_id = body(h.tip_load_body)

    @property
    def data(self) -> mujoco.MjData:
        """The scene's MjData (internal units)."""
        return self._data

    @data.setter
    def data(self, data: mujoco.MjData) -> None:
        # a dm_control Physics hands its own MjData to the scene; the views follow it
        self._data = data
        self._bind_views()
        self._apply_loads()

    def _bind_views(self) -> None:
        """Views (no copies) of the bending dofs in qpos, qvel and qfrc_applied, made once,
        so the per-step paths of the drives allocate nothing; None where the dofs are not
        evenly spaced (the indexed fallback then copies)."""
        d, sl = self._data, self._bend_sl
        strided = isinstance(sl, slice)
        self._qfrc_bend = d.qfrc_applied[sl] if strided else None
        self._qvel_bend = d.qvel[sl] if strided else None
        self._qpos_bend = d.qpos[self._qpos_sl] if isinstance(self._qpos_sl, slice) else None
        self._quat_wz = tuple(d.qpos[q] for q in self._quat_sl) \
            if self._quat_sl is not None and all(isinstance(q, slice) for q in self._quat_sl) else None

    # ------------------------------------------------------------------ state
    @property
    def timestep(self) -> float:
        """Timestep (s)."""
        return self.choice.timestep

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self.data.time * self.units.time

    def reset(self, curvature: float = 0.0) -> None:
        """Reset to rest; ``curvature`` (1/m) starts the beam as a uniform arc of that
        curvature (seed 000 starts each experiment from a measured curvature)."""
        mujoco.mj_resetData(self.model, self.data)
        self._apply_loads()                  # mj_resetData clears xfrc_applied; tip loads persist
        self.set_bending_stiffness_scale(1.0)
        if curvature:
            self.set_hinge_angles(np.full(self.layout.segments, curvature * self.layout.ds))
        mujoco.mj_forward(self.model, self.data)
        self._step_count = 0

    def set_hinge_angles(self, angles: Sequence[float]) -> None:
        """Set the bending angle (rad) of every hinge about the hinge axis, velocities zero."""
        a = np.asarray(angles, dtype=float)
        if a.shape != (self.layout.segments,):
            raise ParameterError("angles", a.shape, f"an array of {self.layout.segments} angles")
        _write_hinge_angles(self.data.qpos, self.joint_qpos, a, self.representation == "hinge")
        self.data.qvel[:] = 0
        mujoco.mj_forward(self.model, self.data)

    def hinge_angles(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending angle (rad) of every hinge about the hinge axis; written into ``out``
        (shape (segments,)) when given, which then allocates nothing."""
        if self._qpos_bend is not None:            # hinge chain
            if out is None:
                return self._qpos_bend.copy()
            np.copyto(out, self._qpos_bend)
            return out
        if self._quat_wz is not None:              # cable: 2 atan2(q_z, q_w)
            a = np.arctan2(self._quat_wz[1], self._quat_wz[0], out=out)
            a *= 2.0
            return a
        q = self.data.qpos                         # indexed fallback (copies)
        a = q[self.joint_qpos] if self.representation == "hinge" else \
            2 * np.arctan2(q[self.joint_qpos + 3], q[self.joint_qpos])
        if out is None:
            return a
        np.copyto(out, a)
        return out

    # ------------------------------------------------------------------ loads
    def set_tip_force(self, force: Union[float, Sequence[float]]) -> None:
        """Dead load at the tip point, N. A scalar is transverse (along the deflection
        axis y of the clamp frame); a 3-vector is (axial, transverse, out-of-plane) in the
        clamp frame."""
        f = np.array([0.0, float(force), 0.0]) if np.isscalar(force) else np.asarray(force, dtype=float)
        if f.shape != (3,) or not np.all(np.isfinite(f)):
            raise ParameterError("force", force, "a finite scalar or 3-vector in N")
        self._tip_force_world = self.rotation @ f / self.units.force
        self._apply_loads()

    def set_tip_moment(self, moment: float) -> None:
        """Couple at the tip about the hinge axis, N m (positive bends toward +y)."""
        m = float(moment)
        if not np.isfinite(m):
            raise ParameterError("moment", moment, "a finite number in N m")
        self._tip_moment = m / self.units.moment
        self._apply_loads()

    def _apply_loads(self) -> None:
        """Tip loads act on the massless tip-load body, whose centre of mass is the tip
        point: constant in the world frame, they stay dead loads there as the beam moves."""
        d, b = self.data, self.tip_load_id
        d.xfrc_applied[b, :3] = self._tip_force_world
        d.xfrc_applied[b, 3:] = self.rotation[:, 2] * self._tip_moment

    # ------------------------------------------------------------------ drives
    def set_internal_moments(self, moments) -> None:
        """Internal bending moment (N m) at every hinge (scalar: the same everywhere), applied
        as equal and opposite couples on the two links it joins, i.e. a generalised force
        on the hinge's bending dof. Replaces the previous call's moments."""
        if self._stiffness_scale != 1.0 and self.representation != "hinge":
            # the cable plugin's stiffness is fixed at init: add the change as a moment
            M = np.multiply(moments, self._inv_moment)
            M = M - (self._stiffness_scale - 1.0) * self._k_bend * self.hinge_angles()
            self.data.qfrc_applied[self._bend_sl] = M
        elif self._qfrc_bend is not None:   # the per-step path: no allocation
            if isinstance(moments, np.ndarray) and moments.ndim:
                np.multiply(moments, self._inv_moment, out=self._qfrc_bend)
            else:
                self._qfrc_bend.fill(float(moments) * self._inv_moment)
        else:
            self.data.qfrc_applied[self._bend_sl] = np.multiply(moments, self._inv_moment)

    def set_bending_stiffness_scale(self, factor: float) -> None:
        """Scale every hinge's bending stiffness (and its Rayleigh damping, which keeps the
        stability limit) by ``factor`` relative to the catalog beam, e.g. for
        field-stiffened polymers."""
        if factor == self._stiffness_scale:   # the per-step call of a drive: nothing to do
            return
        f = check_positive("stiffness factor", factor)
        self._stiffness_scale = f
        if self._jnt_stiffness_bend is not None:
            np.multiply(self._k_bend, f, out=self._jnt_stiffness_bend)
        elif self.representation == "hinge":
            self.model.jnt_stiffness[self.joint_ids] = self._k_bend * f
        if self._dof_damping_bend is not None:
            np.multiply(self._d0_bend, f, out=self._dof_damping_bend)
        else:
            self.model.dof_damping[self.bend_dof] = self._d0[self.bend_dof] * f

    def set_hinge_parameters(self, stiffness=None, damping=None) -> None:
        """Set every hinge's bending stiffness (N m / rad) and/or viscous damping (N m s / rad),
        scalars or one value per hinge, replacing the catalog beam's (the joint-level view of
        seed 001's model; see :mod:`mjeap.identify`). Hinge chain only. The timestep is not
        re-chosen: a stiffer, less damped chain than the scene was built for can diverge
        (the step then raises :class:`DivergenceError`)."""
        if self.representation != "hinge":
            raise ParameterError("representation", self.representation,
                                 "'hinge' (per-joint stiffness and damping are a hinge-chain notion)")
        n = self.layout.segments
        if stiffness is not None:
            k = np.broadcast_to(np.asarray(stiffness, float), (n,))
            if not np.all(np.isfinite(k) & (k > 0)):
                raise ParameterError("stiffness", stiffness, "positive finite values in N m/rad")
            self._k_bend = k / self.units.rotational_stiffness
            self.model.jnt_stiffness[self.joint_ids] = self._k_bend * self._stiffness_scale
        if damping is not None:
            b = np.broadcast_to(np.asarray(damping, float), (n,))
            if not np.all(np.isfinite(b) & (b >= 0)):
                raise ParameterError("damping", damping, "finite values >= 0 in N m s/rad")
            self._d0[self.bend_dof] = b / self.units.rotational_damping
            self.model.dof_damping[self.bend_dof] = self._d0[self.bend_dof] * self._stiffness_scale

    def hinge_damping(self) -> np.ndarray:
        """Current viscous damping of every hinge's bending dof (N m s / rad)."""
        return self.model.dof_damping[self.bend_dof] * self.units.rotational_damping

    def hinge_rates(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending angular velocity of every hinge (rad/s); written into ``out`` when given."""
        v = self._qvel_bend if self._qvel_bend is not None else self.data.qvel[self._bend_sl]
        return np.multiply(v, 1.0 / self.units.time, out=out)

    def hinge_stiffness(self) -> np.ndarray:
        """Current bending stiffness of every hinge (N m / rad)."""
        return self._k_bend * self.units.rotational_stiffness * self._stiffness_scale

    def gravity_moments(self) -> np.ndarray:
        """Moment (N m) that gravity exerts on every hinge's bending dof at the current
        configuration (at rest)."""
        d = self.data
        saved = d.qvel.copy()
        d.qvel[:] = 0
        mujoco.mj_forward(self.model, d)
        out = -d.qfrc_bias[self.bend_dof] * self.units.moment
        d.qvel[:] = saved
        mujoco.mj_forward(self.model, d)
        return out

    # ------------------------------------------------------------------ stepping
    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps; raises :class:`DivergenceError` if the state blows up."""
        mujoco.mj_step(self.model, self.data, nstep=n)
        self._step_count += n
        self.check_finite()
        self.update_kinematics()

    def update_kinematics(self) -> None:
        """Recompute positions and orientations from the present joint state. mj_step leaves
        them at the state before its integration, one step behind qpos (a phase lag of
        omega dt, 6.5 degrees at 2 kHz with dt = 9 us); the read-outs below use them."""
        mujoco.mj_kinematics(self.model, self.data)

    def run(self, duration: float) -> None:
        """Advance by ``duration`` seconds (rounded to whole steps)."""
        n = int(round(check_positive("duration", duration, "s") / self.timestep))
        self.step(max(n, 1))

    def check_finite(self) -> None:
        d = self.data
        # a sum is finite only if every entry is (and no entry is near overflow)
        bad = d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0 or \
            not math.isfinite(float(d.qpos.sum()) + float(d.qvel.sum()))
        if bad:
            raise self.divergence_error()

    def divergence_error(self) -> DivergenceError:
        """The error for a run that blew up by the present step: which scene, when, the
        timestep against its stability limit and the mode that sets it."""
        c = self.choice
        return DivergenceError(
            f"{self.actuator.id} ({self.representation}) diverged by step {self._step_count} "
            f"(t = {self.time:.6g} s): timestep {c.timestep:.4g} s, stability limit "
            f"{c.stability_limit:.4g} s set by the highest bending mode ({c.highest_frequency:.4g} Hz) "
            f"under {c.integrator}" + ("; the reference configuration is buckled under gravity"
                                      if c.buckled else "") + ". Reduce the timestep or the load.")

    def settle(self, tol: float = 1e-7, max_periods: int = 400) -> int:
        """Run to static equilibrium under the current loads with extra damping (first-mode
        damping ratio 0.3), returning the number of steps; the tip must move by less than
        ``tol`` x L over one first-mode period. Restores the scene's damping afterwards."""
        m = self.model
        saved = m.dof_damping.copy()
        m.dof_damping[:] = saved * (SETTLING_DAMPING_RATIO / max(self.choice.damping_ratio, 1e-9))
        period = max(1, int(round(1.0 / self.choice.first_frequency / self.timestep)))
        steps, last = 0, self.tip_position()
        try:
            for _ in range(max_periods):
                self.step(period)
                steps += period
                now = self.tip_position()
                if np.linalg.norm(now - last) < tol * self.layout.length:
                    return steps
                last = now
        finally:
            m.dof_damping[:] = saved
        raise DivergenceError(f"{self.actuator.id}: did not settle within {max_periods} periods "
                              f"(tip still moving by {np.linalg.norm(now - last):.3g} m per period)")

    # ------------------------------------------------------------------ read-outs (SI)
    def clamp_frame(self, p_rel: np.ndarray) -> np.ndarray:
        """World-axis offsets from the clamp (internal units, any leading shape) to the
        clamp frame in m."""
        out = p_rel @ self.rotation
        out *= self.units.length
        return out

    def in_plane_angle(self, xmat: np.ndarray) -> np.ndarray:
        """Rotation (rad) about the hinge axis, relative to the clamp, of body frames given
        as flattened world rotation matrices (..., 9)."""
        rel = self.rotation.T @ np.reshape(xmat, (-1, 3, 3))
        return np.arctan2(rel[:, 1, 0], rel[:, 0, 0]).reshape(np.shape(xmat)[:-1])

    def _to_clamp(self, p_world: np.ndarray) -> np.ndarray:
        return self.clamp_frame(p_world - self.data.xpos[self.clamp_id])

    def tip_position(self) -> np.ndarray:
        """Tip point in the clamp frame (axial x, deflection y, out-of-plane z), m."""
        return self._to_clamp(self.data.site_xpos[self.tip_site_id])

    def tip_angle(self) -> float:
        """Rotation of the tip about the hinge axis relative to the clamp, rad."""
        return float(self.in_plane_angle(self.data.xmat[self.tip_body_id]))

    def tip_curvature(self) -> float:
        """Curvature (1/m) of the arc through clamp and tip, tangent at the clamp (seed 000)."""
        p = self.tip_position()
        return analytical.arc_curvature(p[0], p[1])

    def centreline(self) -> np.ndarray:
        """Clamp, hinges and tip in the clamp frame, (N + 2, 3), m."""
        pts = np.vstack([self.data.xpos[self.clamp_id], self.data.xpos[self.link_ids],
                         self.data.site_xpos[self.tip_site_id]])
        return self._to_clamp(pts)

    def payload_position(self) -> Optional[np.ndarray]:
        """Payload centre in the clamp frame (m), or None."""
        return None if self.payload_id < 0 else self._to_clamp(self.data.xpos[self.payload_id])

    # ------------------------------------------------------------------ output
    def to_xml(self) -> str:
        """The scene as MJCF text (internal units, as compiled)."""
        return self.spec.to_xml()

    def summary(self) -> dict:
        c = self.choice
        return {"actuator": self.actuator.id, "representation": self.representation,
                "segments": self.layout.segments, "orientation": self.orientation,
                "payload_kg": None if self.payload is None else self.payload.mass,
                "units": self.units.describe(), **c.as_dict()}
