"""Linearised dynamics of a compiled beam: mass and stiffness matrices, bending modes, and
the exact stability limit of MuJoCo's one-step map for them.

Stiffness comes from finite differences of MuJoCo's own generalised forces around the
reference configuration, split into the elastic part (joint springs and the cable plugin,
``qfrc_passive``) and the gravity part (``-qfrc_bias`` at zero velocity), so payloads
above or below the clamp shift the modes as the physics says.
"""
from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
linalg = lazy_module("scipy.linalg")


@dataclass(frozen=True)
class Linearization:
    """Internal-unit matrices at the reference configuration (nv x nv)."""

    M: np.ndarray          # mass matrix
    K_elastic: np.ndarray  # joint springs + elasticity plugin
    K_gravity: np.ndarray  # geometric stiffness of gravity (negative when inverted)
    K_joint: np.ndarray    # the part of K_elastic from joint springs (implicit under 'discrete')

    @property
    def K(self) -> np.ndarray:
        return self.K_elastic + self.K_gravity


def linearize(model: mujoco.MjModel, eps: float = 1e-6, qpos=None) -> Linearization:
    """Mass and stiffness matrices at ``qpos`` (default qpos0) by central differences of
    MuJoCo's forces (the tangent stiffness there, whether or not it is an equilibrium)."""
    d = mujoco.MjData(model)
    nv = model.nv
    q_ref = model.qpos0.copy() if qpos is None else np.asarray(qpos, dtype=float).copy()
    d.qpos[:] = q_ref
    mujoco.mj_forward(model, d)
    M = np.zeros((nv, nv))
    mujoco.mj_fullM(model, d, M)

    def forces(dq):
        q = q_ref.copy()
        mujoco.mj_integratePos(model, q, dq, 1.0)
        d.qpos[:] = q
        d.qvel[:] = 0
        mujoco.mj_forward(model, d)
        return d.qfrc_passive.copy(), -d.qfrc_bias.copy()

    Ke, Kg = np.zeros((nv, nv)), np.zeros((nv, nv))
    for i in _progress(range(nv), nv, "linearising (finite differences)"):
        dq = np.zeros(nv)
        dq[i] = eps
        pp, gp = forces(dq)
        pm, gm = forces(-dq)
        Ke[:, i] = -(pp - pm) / (2 * eps)
        Kg[:, i] = -(gp - gm) / (2 * eps)
    Ke = 0.5 * (Ke + Ke.T)
    Kg = 0.5 * (Kg + Kg.T)
    Kj = np.zeros((nv, nv))
    for j in range(model.njnt):
        if model.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE:
            a = model.jnt_dofadr[j]
            Kj[a, a] = model.jnt_stiffness[j]
    return Linearization(M, Ke, Kg, Kj)


#: scenes with this many dofs or more show progress while they are analysed (on a terminal):
#: 1000 hinges take minutes (dense eigenvalues of the 2 nv step map in the bisection)
PROGRESS_DOFS = 200


def _progress(it, nv: int, what: str):
    import sys
    if nv < PROGRESS_DOFS or not sys.stderr.isatty():
        return it
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return it
    return tqdm(it, desc=f"{what}, {nv} dofs", leave=False)


def modal_frequencies(lin: Linearization, with_gravity: bool = True) -> np.ndarray:
    """Squared angular frequencies omega^2 (internal 1/time^2), ascending; negative values
    are unstable (buckled) directions."""
    K = lin.K if with_gravity else lin.K_elastic
    return linalg.eigh(K, lin.M, eigvals_only=True)


def _stable_part(K: np.ndarray, M: np.ndarray) -> np.ndarray:
    """K with its negative modes (physical instabilities, e.g. away from equilibrium) removed:
    those grow at any timestep and say nothing about the integrator's limit."""
    lam, phi = linalg.eigh(K, M)
    if lam.min() >= 0:
        return K
    Mphi = M @ phi
    return (Mphi * np.clip(lam, 0.0, None)) @ Mphi.T


def step_map(lin: Linearization, damping: np.ndarray, h: float, integrator: str, gravity: bool = False) -> np.ndarray:
    """MuJoCo's linearised one-step map (x, v) -> (x+, v+) at timestep ``h`` (2 nv x 2 nv).

    Velocity update with implicit damping D and implicit joint stiffness K_i (only under
    ``discrete``), the rest of the stiffness K_e explicit, then x+ = x + h v+:
    (M + h D + h^2 K_i) v+ = M v - h (K_i + K_e) x.
    Gravity stiffness is left out unless ``gravity``: it sets the physics (buckling), not
    the numerics.
    """
    M = lin.M
    K = lin.K if gravity else _stable_part(lin.K_elastic, lin.M)
    Ki = lin.K_joint if integrator == "discrete" else np.zeros_like(K)
    A = M + h * np.diag(damping) + h * h * Ki
    AinvK = np.linalg.solve(A, K)
    AinvM = np.linalg.solve(A, M)
    n = M.shape[0]
    return np.block([[np.eye(n) - h * h * AinvK, h * AinvM], [-h * AinvK, AinvM]])


def spectral_radius(lin: Linearization, damping: np.ndarray, h: float, integrator: str) -> float:
    """Spectral radius of :func:`step_map` (stable where <= 1)."""
    return float(np.max(np.abs(np.linalg.eigvals(step_map(lin, damping, h, integrator)))))


def first_mode_damping(lin: Linearization, damping: np.ndarray, h: float, integrator: str) -> tuple:
    """(frequency in rad per internal time, damping ratio) of the lowest oscillating mode of
    the discrete step map, gravity included: what the simulation really does per step,
    integrator and all, from the eigenvalue lambda = exp(mu h), mu = -zeta w +- i w sqrt(1 - zeta^2)."""
    lam = np.linalg.eigvals(step_map(lin, damping, h, integrator, gravity=True))
    mu = np.log(lam[np.abs(lam.imag) > 1e-12].astype(complex)) / h
    i = np.argmin(np.abs(mu))
    return float(np.abs(mu[i])), float(-mu[i].real / np.abs(mu[i]))


def stability_limit(lin: Linearization, damping: np.ndarray, integrator: str, h_max: float) -> float:
    """Largest timestep (internal units) for which the step map is stable, found by
    bisection; ``inf`` if stable up to ``h_max``."""
    tol = 1e-9

    def stable(h):
        return spectral_radius(lin, damping, h, integrator) <= 1.0 + tol

    if stable(h_max):
        return float("inf")
    w2 = linalg.eigh(lin.K_elastic, lin.M, eigvals_only=True)
    lo = 0.5 / np.sqrt(max(w2.max(), 1e-300))
    while not stable(lo):
        lo *= 0.5
    hi = h_max
    for _ in _progress(range(60), lin.M.shape[0], "stability limit (bisection)"):
        mid = np.sqrt(lo * hi)
        if stable(mid):
            lo = mid
        else:
            hi = mid
        if hi / lo < 1 + 1e-4:
            break
    return lo
