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

from ..errors import ParameterError, check_positive
from ..model import analytical
from ..model.mjcf import BUILDERS
from ..model.views import BeamView, as_slice, into, write_hinge_angles  # noqa: F401  (public here before)


class ActuatorPart:
    """A beam in a compiled model. ``handles`` (:class:`mjeap.model.mjcf.BeamHandles`) name its
    parts as built; ``prefix`` is prepended to every name (``'left/'`` after
    ``attach(prefix='left')``, empty for a :class:`Scene`). ``rotation`` (3 x 3) fixes the
    clamp frame where the clamp cannot move; None reads it from the clamp body."""

    def __init__(self, model: mujoco.MjModel, handles, layout, actuator, units, representation: str,
                 *, payload=None, prefix: str = "", rotation: Optional[np.ndarray] = None):
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
        #: the beam's representation (:class:`mjeap.model.mjcf.BeamBuilder`): how its bending is
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

    def built_hinge_parameters(self):
        """Every hinge's bending stiffness and damping (internal units) as built or set by
        :meth:`set_hinge_parameters`, without a drive's present stiffness scale: what a
        model derived from this one (a native model) starts from."""
        return self._k_bend.copy(), self.view.built_damping()

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

    def direct_bending(self):
        """(angles, moments, scale) for a drive's per-step path, or None: a view of the hinge
        angles (rad, in ``qpos``), a view of the hinges' bending forces (internal units, in
        ``qfrc_applied``) and the internal value of 1 N m, so that writing ``M * scale`` into
        ``moments`` is :meth:`set_internal_moments` (M) without its checks. Only where the
        hinges are evenly spaced joints whose moments do not follow the geometry and whose
        stiffness is the model's own; the views are valid until the part is bound again."""
        v = self.view
        angles, moments = v.direct_arrays()
        if angles is None or moments is None or v.moments_follow_geometry or \
                (self._stiffness_scale != 1.0 and not self._stiffness_in_model):
            return None
        return angles, moments, self._inv_moment

    def forget_moments(self) -> None:
        """The model's applied forces were cleared (mj_resetData): no moments to apply again."""
        self._moments = None

    def after_data_reset(self) -> None:
        """After ``mj_resetData`` (which clears qfrc_applied and xfrc_applied): no internal
        moments to apply again, the tip loads (which persist) applied again. A clamp that
        moves needs its frame first (``mj_kinematics``), the tip moment's axis."""
        self.forget_moments()
        self.apply_loads()

    def reapply_moments(self) -> None:
        """Apply the last internal moments again at the present configuration (a beam whose
        moments follow its geometry, before each step; the drives set them every step)."""
        if self._moments is not None:
            self.set_internal_moments(self._moments)

    @property
    def stiffness_scale(self) -> float:
        """The factor a drive set on every hinge's bending stiffness
        (:meth:`set_bending_stiffness_scale`; 1: the catalog beam's)."""
        return self._stiffness_scale

    @property
    def holds_moments(self) -> bool:
        """Whether internal moments are held to be applied again at each step's configuration
        (a beam whose moments follow its geometry: the rod; :meth:`reapply_moments`)."""
        return self._moments is not None

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
        Mutlu et al. 2013's model; see :mod:`mjeap.analysis.identify`). Hinge chain only. The timestep is not
        re-chosen: a stiffer, less damped chain than the model was built for can diverge
        (the step then raises :class:`DivergenceError`)."""
        if not self.builder.per_hinge_parameters:
            raise ParameterError("representation", self.representation,
                                 "'hinge' (per-joint stiffness and damping are a hinge-chain notion)")
        n = self.layout.segments
        k = b = None
        if stiffness is not None:
            k = np.broadcast_to(np.asarray(stiffness, float), (n,))
            if not np.all(np.isfinite(k) & (k > 0)):
                raise ParameterError("stiffness", stiffness, "positive finite values in N m/rad")
        if damping is not None:
            b = np.broadcast_to(np.asarray(damping, float), (n,))
            if not np.all(np.isfinite(b) & (b >= 0)):
                raise ParameterError("damping", damping, "finite values >= 0 in N m s/rad")
        if k is None and b is None:
            return
        self.revision += 1
        if k is not None:
            self._k_bend = k / self.units.rotational_stiffness
            self.view.set_stiffness(self._k_bend, self._stiffness_scale)
        if b is not None:
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

    def tip_loads(self):
        """The tip loads as set: force (N, clamp frame: axial, transverse, out-of-plane) and
        moment (N m)."""
        return (self.rotation.T @ self._tip_force_world * self.units.force, self._tip_moment * self.units.moment)

    def check_derivable(self) -> None:
        """Refuse to derive models from this one (other segments or another step: a model
        chosen for an accuracy target, an error estimate's companions) when its hinges were
        given their own values (:meth:`set_hinge_parameters`): they belong to these hinges."""
        if self.revision:
            raise ParameterError("scene", "hinge parameters set by set_hinge_parameters",
                                 "a beam whose hinges keep the catalog's stiffness and damping, for a rollout that "
                                 "chooses its model (accuracy=) or estimates its error (estimate_error=)",
                                 "the values belong to this model's hinges; a model of other segments or another "
                                 "step cannot carry them")

    def carry_loads(self, other: "ActuatorPart") -> None:
        """Set this part's tip loads on ``other``, this actuator in a model derived from this
        one (a native model, other segments or another step): the force as it acts in the
        world (a moving clamp may have turned since it was set), the moment about the hinge
        axis; callers deriving a model check :meth:`check_derivable` first."""
        other._tip_force_world = self._tip_force_world * (self.units.force / other.units.force)
        other._tip_moment = self._tip_moment * (self.units.moment / other.units.moment)
        other.apply_loads()

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
    def clamp_moves(self) -> bool:
        """Whether the clamp frame can move (a mount on a free or jointed body); else its
        rotation is fixed (:meth:`fix_rotation`)."""
        return self._fixed_rotation is None

    def fix_rotation(self, rotation) -> None:
        """Declare the clamp frame fixed at the world ``rotation`` (3 x 3; a clamp welded to
        the world)."""
        self._fixed_rotation = np.array(rotation, dtype=float).reshape(3, 3)

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
        """Curvature (1/m) of the arc through clamp and tip, tangent at the clamp (Dadras et al. 2021)."""
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
