"""The kinematics of a planar chain of hinges for many states at once: where the bodies of a
beam's hinge chain are for every row of joint positions a run returned, without stepping
MuJoCo's kinematics per sample (:func:`chain_kinematics`; the native engine reads a run from
its states with it, :mod:`mjeap.engines.native`)."""
from __future__ import annotations

from typing import Sequence

import mujoco
import numpy as np

from ..caching import BoundedCache

__all__ = ["chain_kinematics"]


def _hinge_rotations(axis: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """(n, 3, 3) rotations by ``angle`` (n,) rad about the unit ``axis`` (Rodrigues)."""
    k = np.array([[0.0, -axis[2], axis[1]], [axis[2], 0.0, -axis[0]], [-axis[1], axis[0], 0.0]])
    s, c = np.sin(angle)[:, None, None], np.cos(angle)[:, None, None]
    return np.eye(3) + s * k + (1.0 - c) * (k @ k)


_EYE = np.eye(3)


#: the structure :func:`chain_kinematics` reads from a model, by (model, bodies, frame_of): a
#: choice's runs and a map's amplitudes step the same native models. Oldest dropped past 128
_CHAINS = BoundedCache("chain structures", max_entries=128, locked=True)


def _chain_structure(model, bodies: tuple, frame_of: int):
    """What :func:`chain_kinematics` needs of ``model`` (None where it does not apply)."""
    nb = max(*bodies, frame_of) + 1
    frames = [(np.eye(3), None)]                # per body: F, axis a (None: not rotating)
    hinges = np.zeros((model.nq, nb))           # body b's angle: qpos @ hinges[:, b]
    offsets = np.zeros((3, nb, 3))              # body b's offset from its parent: cos, sin, 1 terms
    rotating = np.zeros(nb, bool)               # whether body b's parent frame rotates
    above = np.eye(nb)                          # above[k, b]: k is b or one of its ancestors
    for b in range(1, nb):
        p, nj = model.body_parentid[b], model.body_jntnum[b]
        f, a = frames[p]
        v = model.body_pos[b]
        above[:, b] += above[:, p]
        hinges[:, b] = hinges[:, p]
        if a is None:
            offsets[2, b] = f @ v
        else:
            rotating[b] = True
            axv = np.array([a[1] * v[2] - a[2] * v[1], a[2] * v[0] - a[0] * v[2], a[0] * v[1] - a[1] * v[0]])
            fa_av = (f @ a) * (a @ v)
            offsets[0, b], offsets[1, b], offsets[2, b] = f @ v - fa_av, f @ axv, fa_av
        local = np.empty(9)
        mujoco.mju_quat2Mat(local, model.body_quat[b])
        local = local.reshape(3, 3)
        if nj > 1:
            return None
        j = model.body_jntadr[b]
        if nj and (model.jnt_type[j] != mujoco.mjtJoint.mjJNT_HINGE or np.any(model.jnt_pos[j])):
            return None
        if a is not None and (not np.abs(local - _EYE).max() <= 1e-15 or
                              (nj and not np.array_equal(model.jnt_axis[j], a))):
            return None
        if nj:
            hinges[model.jnt_qposadr[j], b] += 1.0
            frames.append((f @ local, model.jnt_axis[j].copy()) if a is None else (f, a))
        else:
            frames.append((f @ local, None) if a is None else (f, a))
    # only the bodies above those asked for (the world first): their angles and offsets
    keep = np.nonzero(above[:, list(bodies) + [frame_of]].any(axis=1))[0]
    where = np.full(nb, -1)
    where[keep] = np.arange(len(keep))
    parent = where[model.body_parentid[keep]]
    return (hinges[:, keep], offsets[:, keep], rotating[keep], np.maximum(parent, 0), above[keep[1:]][:, list(bodies)],
            int(where[frame_of]), frames[frame_of])


def chain_kinematics(model, qpos: np.ndarray, bodies: Sequence[int], frame_of: int):
    """World positions (n, B, 3) of ``bodies`` and orientation (n, 3, 3) of body ``frame_of`` for the joint
    positions ``qpos`` (n, nq), all samples at once, down a planar chain: each body's frame
    is a fixed rotation F times a rotation by the summed angle phi of the hinges above it
    about their one axis, so a point v of a body sits at x + F (v cos phi + (a x v) sin phi
    + a (a . v)(1 - cos phi)). The structure is read once per model (a pass over the bodies,
    kept), then every body's angle (qpos times a 0/1 matrix) and the positions (their
    ancestors' offsets summed, one matrix product) for all samples together. None where a
    body moves otherwise (a joint other than one hinge through its origin, hinges on
    different axes, a rotated body below a hinge)."""
    key = (tuple(int(b) for b in bodies), int(frame_of))
    structure = _CHAINS.get_or_build(key, lambda: (_chain_structure(model, *key),), owner=model)[0]
    if structure is None:
        return None
    hinges, offsets, rotating, parent, picked, frame_at, (f, a) = structure
    n = len(qpos)
    phi = qpos @ hinges                         # (n, nb): each body's summed hinge angle
    c, s = np.cos(phi), np.sin(phi)
    cp = np.where(rotating, c[:, parent], 1.0)
    sp = np.where(rotating, s[:, parent], 0.0)
    step = cp[:, :, None] * offsets[0] + sp[:, :, None] * offsets[1] + offsets[2]      # (n, nb, 3)
    nb = step.shape[1]
    pos = (step[:, 1:].transpose(0, 2, 1).reshape(3 * n, nb - 1) @ picked).reshape(n, 3, -1).transpose(0, 2, 1)
    return pos, np.broadcast_to(f, (n, 3, 3)) if a is None else f @ _hinge_rotations(a, phi[:, frame_at])
