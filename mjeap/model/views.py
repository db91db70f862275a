"""How each beam representation reads and drives its bending in a compiled model (internal
units): a :class:`BeamView` per representation, made by its builder
(:meth:`mjeap.model.mjcf.BeamBuilder.view`) for an :class:`mjeap.simulation.part.ActuatorPart`,
which holds the SI side."""
from __future__ import annotations

from typing import Optional

import mujoco
import numpy as np



__all__ = ["BeamView", "JointView", "HingeView", "CableView", "as_slice", "into", "write_hinge_angles"]


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
    (internal units): made by its builder (:meth:`mjeap.model.mjcf.BeamBuilder.view`) for an
    :class:`ActuatorPart`, which holds the SI side. ``bend_dof``: the generalised dof that
    carries each hinge's bending (None where no dof does, e.g. the rod's vertices)."""

    bend_dof: Optional[np.ndarray] = None
    #: the generalised force of a hinge moment depends on the configuration (the rod's
    #: vertex forces follow its edges): moments must be applied again before every step
    moments_follow_geometry: bool = False

    def bind(self, data: mujoco.MjData) -> None:
        """Views of ``data`` for the per-step paths (made once per MjData)."""
        self.data = data

    def direct_arrays(self) -> tuple:
        """(angles, moments): views (no copies) of the hinges' angles in ``qpos`` and their
        bending forces in ``qfrc_applied`` of the bound data, each None where the hinges are
        not evenly spaced joints (:meth:`bind`)."""
        return getattr(self, "_qpos_bend", None), getattr(self, "_qfrc_bend", None)

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

    def built_damping(self) -> np.ndarray:
        """Every hinge's bending damping as built (or set), unscaled (internal)."""
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

    def built_damping(self):
        return self._d0[self.bend_dof].copy()

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
