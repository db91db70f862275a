"""One actuator inside a compiled MuJoCo model: its named parts, its bending dofs and its SI
read-outs.

An :class:`ActuatorPart` finds a beam's bodies, joints and sites by name (with the prefix it
was attached under), keeps views of its bending dofs in an ``MjData`` and reads the beam
out in SI in its own clamp frame (x along the undeformed beam, y the deflection, z the
hinge axis). The one-actuator :class:`mjeap.Scene` holds one part; a
:class:`mjeap.System` holds one per attached actuator, all sharing one model and data.
The clamp frame follows the clamp body: a clamp welded to the world has a constant
rotation, one mounted on a moving body is read from ``data.xmat`` every time.
"""
from __future__ import annotations

from typing import Optional, Sequence, Union

import mujoco
import numpy as np

from . import analytical
from .errors import ParameterError, check_positive


def as_slice(idx: np.ndarray):
    """A slice equal to an evenly spaced index array (else the array itself)."""
    idx = np.asarray(idx)
    if len(idx) > 1 and np.all(np.diff(idx) == idx[1] - idx[0]) and idx[1] > idx[0]:
        return slice(int(idx[0]), int(idx[-1]) + 1, int(idx[1] - idx[0]))
    return idx


def into(a: np.ndarray, out: Optional[np.ndarray]) -> np.ndarray:
    """``a``, or ``a`` copied into ``out`` when given (the read-outs' ``out=`` convention)."""
    if out is None:
        return a
    np.copyto(out, a)
    return out


def write_hinge_angles(qpos: np.ndarray, qposadr: np.ndarray, angles, hinge: bool) -> None:
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


class BeamView:
    """How one beam representation reads and drives its bending in a compiled model
    (internal units): made by its builder (:meth:`mjeap.mjcf.BeamBuilder.view`) for an
    :class:`ActuatorPart`, which holds the SI side. ``bend_dof``: the generalised dof that
    carries each hinge's bending (None where no dof does, e.g. the rod's vertices)."""

    bend_dof: Optional[np.ndarray] = None
    #: the generalised force of a hinge moment depends on the configuration (the rod's
    #: vertex forces follow its edges): moments must be applied again before every step
    moments_follow_geometry: bool = False

    def bind(self, data: mujoco.MjData) -> None:
        """Views of ``data`` for the per-step paths (made once per MjData)."""
        self.data = data

    def angles(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending angle (rad) of every hinge about the hinge axis."""
        raise NotImplementedError

    def rates(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending rate of every hinge (rad per internal time unit)."""
        raise NotImplementedError

    def write_angles(self, qpos: np.ndarray, angles: np.ndarray) -> None:
        """Write a configuration bent by ``angles`` (rad per hinge) into ``qpos``."""
        raise NotImplementedError

    def zero_rates(self, qvel: np.ndarray) -> None:
        """Set the beam's velocities in ``qvel`` to zero."""
        raise NotImplementedError

    def moments_of(self, qfrc: np.ndarray) -> np.ndarray:
        """The moment (internal) about every hinge of a generalised force ``qfrc`` (nv,): its
        virtual work per unit bending of that hinge, all others held."""
        raise NotImplementedError

    def apply_moments(self, moments, scale: float, stiffness_change: Optional[np.ndarray]) -> None:
        """Apply the moments ``moments`` x ``scale`` (internal units; scalar or one per
        hinge) as equal and opposite couples on the two parts each hinge joins, replacing
        the previous call's. ``stiffness_change``: per-hinge stiffness (internal) to add to
        the beam's own where the model cannot change it (None: nothing to add)."""
        raise NotImplementedError

    def set_stiffness(self, k: np.ndarray, factor: float) -> bool:
        """Set every hinge's bending stiffness to ``k`` x ``factor`` (internal) in the model;
        False where the model's stiffness is fixed (the change then goes in as a moment)."""
        return False

    def damping(self) -> np.ndarray:
        """Present viscous damping of every hinge's bending (internal)."""
        raise NotImplementedError

    def scale_damping(self, factor: float) -> None:
        """Scale the beam's damping to ``factor`` x its value as built."""
        raise NotImplementedError

    def set_damping(self, b: np.ndarray) -> None:
        """Set every hinge's viscous damping (internal), replacing the built value."""
        raise NotImplementedError

    def save_damping(self):
        """The model's present damping, for :meth:`scale_saved_damping` and
        :meth:`restore_damping` (a scene settling with extra damping)."""
        return self.model.dof_damping.copy()

    def scale_saved_damping(self, saved, factor: float) -> None:
        self.model.dof_damping[:] = saved * factor

    def restore_damping(self, saved) -> None:
        self.model.dof_damping[:] = saved


class JointView(BeamView):
    """A beam whose hinges are joints: one generalised dof per hinge carries its bending
    (a hinge joint, or a ball joint's rotation about its local z axis, ``offset`` 2), its
    damping is that dof's ``dof_damping``."""

    offset = 0

    def __init__(self, model: mujoco.MjModel, joint_ids: np.ndarray):
        m = self.model = model
        self.joint_ids = joint_ids
        self.joint_qpos = m.jnt_qposadr[joint_ids]
        self.joint_dof = m.jnt_dofadr[joint_ids]
        self.bend_dof = self.joint_dof + self.offset
        # the same as slices (views, no copies) when evenly spaced, for the per-step paths
        self._bend_sl = as_slice(self.bend_dof)
        self._d0 = m.dof_damping.copy()
        self._dof_damping_bend = m.dof_damping[self._bend_sl] if isinstance(self._bend_sl, slice) else None
        self._d0_bend = self._d0[self._bend_sl]
        self._qfrc_bend = self._qvel_bend = None

    def bind(self, data):
        """Views (no copies) of the bending dofs in qvel and qfrc_applied, made once, so
        the per-step paths of the drives allocate nothing; None where the dofs are not
        evenly spaced (the indexed fallback then copies)."""
        self.data = d = data
        sl = self._bend_sl
        strided = isinstance(sl, slice)
        self._qfrc_bend = d.qfrc_applied[sl] if strided else None
        self._qvel_bend = d.qvel[sl] if strided else None

    def rates(self, out=None):
        return self._qvel_bend if self._qvel_bend is not None else self.data.qvel[self._bend_sl]

    def moments_of(self, qfrc):
        return qfrc[self.bend_dof]

    def apply_moments(self, moments, scale, stiffness_change):
        if stiffness_change is not None:
            M = np.multiply(moments, scale)
            M = M - stiffness_change * self.angles()
            self.data.qfrc_applied[self._bend_sl] = M
        elif self._qfrc_bend is not None:   # the per-step path: no allocation
            if isinstance(moments, np.ndarray) and moments.ndim:
                np.multiply(moments, scale, out=self._qfrc_bend)
            else:
                self._qfrc_bend.fill(float(moments) * scale)
        else:
            self.data.qfrc_applied[self._bend_sl] = np.multiply(moments, scale)

    def damping(self):
        return self.model.dof_damping[self.bend_dof]

    def scale_damping(self, factor):
        if self._dof_damping_bend is not None:
            np.multiply(self._d0_bend, factor, out=self._dof_damping_bend)
        else:
            self.model.dof_damping[self.bend_dof] = self._d0[self.bend_dof] * factor

    def set_damping(self, b):
        self._d0[self.bend_dof] = b


class HingeView(JointView):
    """The hinge chain: hinge joints, angle = qpos; stiffness is the joints' own."""

    def __init__(self, model, joint_ids):
        super().__init__(model, joint_ids)
        self._qpos_sl = as_slice(self.joint_qpos)
        jsl = as_slice(joint_ids)
        self._jnt_stiffness_bend = model.jnt_stiffness[jsl] if isinstance(jsl, slice) else None
        self._qpos_bend = None

    def bind(self, data):
        super().bind(data)
        self._qpos_bend = data.qpos[self._qpos_sl] if isinstance(self._qpos_sl, slice) else None

    def angles(self, out=None):
        if self._qpos_bend is not None:
            return self._qpos_bend.copy() if out is None else into(self._qpos_bend, out)
        return into(self.data.qpos[self.joint_qpos], out)      # indexed fallback (copies)

    def write_angles(self, qpos, angles):
        write_hinge_angles(qpos, self.joint_qpos, angles, True)

    def zero_rates(self, qvel):
        qvel[self.joint_dof] = 0

    def set_stiffness(self, k, factor):
        if self._jnt_stiffness_bend is not None:
            np.multiply(k, factor, out=self._jnt_stiffness_bend)
        else:
            self.model.jnt_stiffness[self.joint_ids] = k * factor
        return True


class CableView(JointView):
    """The cable: ball joints, the bending angle 2 atan2(q_z, q_w) of each quaternion and
    its rotation dof about the local z axis; the plugin's stiffness is fixed at init."""

    offset = 2

    def __init__(self, model, joint_ids):
        super().__init__(model, joint_ids)
        self._quat_sl = (as_slice(self.joint_qpos), as_slice(self.joint_qpos + 3))
        self._quat_wz = None

    def bind(self, data):
        super().bind(data)
        self._quat_wz = tuple(data.qpos[q] for q in self._quat_sl) \
            if all(isinstance(q, slice) for q in self._quat_sl) else None

    def angles(self, out=None):
        if self._quat_wz is not None:              # 2 atan2(q_z, q_w)
            a = np.arctan2(self._quat_wz[1], self._quat_wz[0], out=out)
            a *= 2.0
            return a
        q = self.data.qpos                         # indexed fallback (copies)
        return into(2 * np.arctan2(q[self.joint_qpos + 3], q[self.joint_qpos]), out)

    def write_angles(self, qpos, angles):
        write_hinge_angles(qpos, self.joint_qpos, angles, False)

    def zero_rates(self, qvel):
        qvel[self.joint_dof] = 0
        qvel[self.joint_dof + 1] = 0
        qvel[self.joint_dof + 2] = 0


class ActuatorPart:
    """A beam in a compiled model. ``handles`` (:class:`mjeap.mjcf.BeamHandles`) name its
    parts as built; ``prefix`` is prepended to every name (``'left/'`` after
    ``attach(prefix='left')``, empty for a :class:`Scene`). ``rotation`` (3 x 3) fixes the
    clamp frame where the clamp cannot move; None reads it from the clamp body."""

    def __init__(self, model: mujoco.MjModel, handles, layout, actuator, units, representation: str,
                 payload=None, prefix: str = "", rotation: Optional[np.ndarray] = None):
        self.model, self.handles, self.layout, self.actuator = model, handles, layout, actuator
        self.units, self.representation, self.payload, self.prefix = units, representation, payload, prefix
        m = model

        def find(kind, name):
            i = mujoco.mj_name2id(m, kind, prefix + name)
            if i < 0:
                raise ParameterError("model", prefix + name, f"a model holding the {kind.name[6:].lower()} "
                                     f"'{prefix + name}' of actuator {actuator.id}")
            return i

        body = lambda n: find(mujoco.mjtObj.mjOBJ_BODY, n)  # noqa: E731
        h = handles
        from .mjcf import BUILDERS
        #: the beam's representation (:class:`mjeap.mjcf.BeamBuilder`): how its bending is
        #: read, set and driven in this model (its :class:`BeamView`)
        self.builder = BUILDERS[representation]
        self.clamp_id = body(h.clamp_body)
        self.link_ids = np.array([body(n) for n in h.link_bodies])
        self.tip_body_id = body(h.tip_body)
        self.tip_site_id = find(mujoco.mjtObj.mjOBJ_SITE, h.tip_site)
        self.payload_id = body(h.payload_body) if h.payload_body else -1
        self.tip_load_id = body(h.tip_load_body)
        self.joint_ids = np.array([find(mujoco.mjtObj.mjOBJ_JOINT, n) for n in h.joints], dtype=int)
        self.view = self.builder.view(m, h, layout, units, prefix, find)
        #: the generalised dof carrying each hinge's bending (None where none does: the rod)
        self.bend_dof = self.view.bend_dof
        self._inv_moment = 1.0 / units.moment
        self._k_bend = layout.hinge_stiffness / units.rotational_stiffness  # internal units
        self._stiffness_scale = 1.0
        self._fixed_rotation = None if rotation is None else np.asarray(rotation, dtype=float)
        self._tip_force_world = np.zeros(3)
        self._tip_moment = 0.0
        self._data = None
        #: counts changes of the hinge parameters (models derived from this one follow it)
        self.revision = 0

    # ------------------------------------------------------------------ data
    @property
    def data(self) -> mujoco.MjData:
        return self._data

    def bind(self, data: mujoco.MjData) -> None:
        """Bind the part (and its beam view, whose per-step paths then allocate nothing)
        to ``data``."""
        self._data = data
        self.view.bind(data)
        self.apply_loads()

    @property
    def timestep(self) -> float:
        """Timestep (s) of the model the part is in."""
        return self.model.opt.timestep * self.units.time

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self._data.time * self.units.time

    # ------------------------------------------------------------------ hinges
    def set_hinge_angles(self, angles: Sequence[float], forward: bool = True) -> None:
        """Set the bending angle (rad) of every hinge about the hinge axis, its velocities zero."""
        a = np.asarray(angles, dtype=float)
        if a.shape != (self.layout.segments,):
            raise ParameterError("angles", a.shape, f"an array of {self.layout.segments} angles")
        self.view.write_angles(self._data.qpos, a)
        self.view.zero_rates(self._data.qvel)
        if forward:
            mujoco.mj_forward(self.model, self._data)

    def hinge_angles(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending angle (rad) of every hinge about the hinge axis; written into ``out``
        (shape (segments,)) when given, which then allocates nothing."""
        return self.view.angles(out)

    def hinge_rates(self, out: Optional[np.ndarray] = None) -> np.ndarray:
        """Bending angular velocity of every hinge (rad/s); written into ``out`` when given."""
        return np.multiply(self.view.rates(), 1.0 / self.units.time, out=out)

    def hinge_stiffness(self) -> np.ndarray:
        """Current (instantaneous) bending stiffness of every hinge (N m / rad)."""
        return self._k_bend * self.units.rotational_stiffness * self._stiffness_scale

    def hinge_damping(self) -> np.ndarray:
        """Current viscous damping of every hinge's bending (N m s / rad)."""
        return self.view.damping() * self.units.rotational_damping

    def gravity_moments(self) -> np.ndarray:
        """Moment (N m) that gravity exerts on every hinge's bending at the current
        configuration (at rest)."""
        d = self._data
        saved = d.qvel.copy()
        d.qvel[:] = 0
        mujoco.mj_forward(self.model, d)
        out = -self.view.moments_of(d.qfrc_bias) * self.units.moment
        d.qvel[:] = saved
        mujoco.mj_forward(self.model, d)
        return out

    # ------------------------------------------------------------------ forces
    def set_internal_moments(self, moments) -> None:
        """Internal bending moment (N m) at every hinge (scalar: the same everywhere), applied
        as equal and opposite couples on the two parts it joins (a generalised force on the
        hinge's bending). Replaces the previous call's moments."""
        change = None
        if self._stiffness_scale != 1.0 and not self._stiffness_in_model:
            # a model whose stiffness is fixed at init (the cable plugin): add the change as a moment
            change = (self._stiffness_scale - 1.0) * self._k_bend
        self.view.apply_moments(moments, self._inv_moment, change)
        if self.view.moments_follow_geometry:
            self._moments = np.array(moments, dtype=float)

    #: the last internal moments (N m) where they must follow the geometry, else None
    _moments = None

    def forget_moments(self) -> None:
        """The model's applied forces were cleared (mj_resetData): no moments to apply again."""
        self._moments = None

    def reapply_moments(self) -> None:
        """Apply the last internal moments again at the present configuration (a beam whose
        moments follow its geometry, before each step; the drives set them every step)."""
        if self._moments is not None:
            self.set_internal_moments(self._moments)

    #: whether the model's own stiffness follows set_bending_stiffness_scale (else the
    #: change is applied as a moment with the drives' moments)
    _stiffness_in_model = True

    def set_bending_stiffness_scale(self, factor: float) -> None:
        """Scale every hinge's bending stiffness (and its Rayleigh damping, which keeps the
        stability limit) by ``factor`` relative to the catalog beam, e.g. for
        field-stiffened polymers."""
        if factor == self._stiffness_scale:   # the per-step call of a drive: nothing to do
            return
        f = check_positive("stiffness factor", factor)
        self._stiffness_scale = f
        self._stiffness_in_model = self.view.set_stiffness(self._k_bend, f)
        self.view.scale_damping(f)

    def set_hinge_parameters(self, stiffness=None, damping=None) -> None:
        """Set every hinge's bending stiffness (N m / rad) and/or viscous damping (N m s / rad),
        scalars or one value per hinge, replacing the catalog beam's (the joint-level view of
        seed 001's model; see :mod:`mjeap.identify`). Hinge chain only. The timestep is not
        re-chosen: a stiffer, less damped chain than the model was built for can diverge
        (the step then raises :class:`DivergenceError`)."""
        if not self.builder.per_hinge_parameters:
            raise ParameterError("representation", self.representation,
                                 "'hinge' (per-joint stiffness and damping are a hinge-chain notion)")
        n = self.layout.segments
        self.revision += 1
        if stiffness is not None:
            k = np.broadcast_to(np.asarray(stiffness, float), (n,))
            if not np.all(np.isfinite(k) & (k > 0)):
                raise ParameterError("stiffness", stiffness, "positive finite values in N m/rad")
            self._k_bend = k / self.units.rotational_stiffness
            self.view.set_stiffness(self._k_bend, self._stiffness_scale)
        if damping is not None:
            b = np.broadcast_to(np.asarray(damping, float), (n,))
            if not np.all(np.isfinite(b) & (b >= 0)):
                raise ParameterError("damping", damping, "finite values >= 0 in N m s/rad")
            self.view.set_damping(b / self.units.rotational_damping)
            self.view.scale_damping(self._stiffness_scale)

    # ------------------------------------------------------------------ tip loads
    def set_tip_force(self, force: Union[float, Sequence[float]]) -> None:
        """Dead load at the tip point, N. A scalar is transverse (along the deflection
        axis y of the clamp frame); a 3-vector is (axial, transverse, out-of-plane) in the
        clamp frame (as it is when the load is set)."""
        f = np.array([0.0, float(force), 0.0]) if np.isscalar(force) else np.asarray(force, dtype=float)
        if f.shape != (3,) or not np.all(np.isfinite(f)):
            raise ParameterError("force", force, "a finite scalar or 3-vector in N")
        self._tip_force_world = self.rotation @ f / self.units.force
        self.apply_loads()

    def set_tip_moment(self, moment: float) -> None:
        """Couple at the tip about the hinge axis, N m (positive bends toward +y)."""
        m = float(moment)
        if not np.isfinite(m):
            raise ParameterError("moment", moment, "a finite number in N m")
        self._tip_moment = m / self.units.moment
        self.apply_loads()

    def has_tip_load(self) -> bool:
        return bool(self._tip_force_world.any() or self._tip_moment)

    def apply_loads(self) -> None:
        """Tip loads act on the massless tip-load body, whose centre of mass is the tip
        point: constant in the world frame, they stay dead loads there as the beam moves."""
        d, b = self._data, self.tip_load_id
        if d is None:
            return
        d.xfrc_applied[b, :3] = self._tip_force_world
        d.xfrc_applied[b, 3:] = self.rotation[:, 2] * self._tip_moment

    # ------------------------------------------------------------------ read-outs (SI)
    @property
    def rotation(self) -> np.ndarray:
        """World rotation of the clamp frame (columns: beam axis, deflection, hinge axis)."""
        if self._fixed_rotation is not None:
            return self._fixed_rotation
        return self._data.xmat[self.clamp_id].reshape(3, 3)

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
        return self.clamp_frame(p_world - self._data.xpos[self.clamp_id])

    def tip_position(self) -> np.ndarray:
        """Tip point in the clamp frame (axial x, deflection y, out-of-plane z), m."""
        return self._to_clamp(self._data.site_xpos[self.tip_site_id])

    def tip_angle(self) -> float:
        """Rotation of the tip about the hinge axis relative to the clamp, rad."""
        return float(self.in_plane_angle(self._data.xmat[self.tip_body_id]))

    def tip_curvature(self) -> float:
        """Curvature (1/m) of the arc through clamp and tip, tangent at the clamp (seed 000)."""
        p = self.tip_position()
        return analytical.arc_curvature(p[0], p[1])

    def centreline(self) -> np.ndarray:
        """Clamp, hinges and tip in the clamp frame, (N + 2, 3), m."""
        d = self._data
        pts = np.vstack([d.xpos[self.clamp_id], d.xpos[self.link_ids], d.site_xpos[self.tip_site_id]])
        return self._to_clamp(pts)

    def payload_position(self) -> Optional[np.ndarray]:
        """Payload centre in the clamp frame (m), or None."""
        return None if self.payload_id < 0 else self._to_clamp(self._data.xpos[self.payload_id])
