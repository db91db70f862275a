"""Analytical references for cantilevers, independent of the simulator (SI throughout).

Assumptions unless stated: a prismatic, inextensible, unshearable Euler-Bernoulli beam of
length L and flexural rigidity EI, clamped at x = 0, free at x = L. Loads are dead loads
(constant direction). References: Timoshenko & Gere, *Theory of Elastic Stability* (1961)
for buckling and beam-columns; Bisshopp & Drucker, Q. Appl. Math. 3 (1945) for the
elastica; Erturk & Inman, *Piezoelectric Energy Harvesting* (2011), eq. (3.16) for the
cantilever with tip mass and rotary inertia.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Tuple

import numpy as np
from scipy import integrate, optimize

from .errors import ParameterError, check_positive
from .section import SectionLayer, SectionProperties, multilayer_section  # noqa: F401  (re-export)

__all__ = [
    "tip_force_deflection", "tip_moment_deflection", "uniform_load_deflection",
    "deflection_shape_tip_force", "elastica_tip_force", "Elastica", "arc_tip_moment",
    "natural_frequencies", "lateral_stiffness", "buckling_load", "arc_curvature",
    "multilayer_section", "SectionLayer", "SectionProperties",
]


# ---------------------------------------------------------------- small deflection (EB)
def tip_force_deflection(P: float, L: float, EI: float) -> Tuple[float, float]:
    """Tip deflection (m) and slope (rad) under a transverse tip force P (N): PL^3/3EI, PL^2/2EI."""
    return P * L**3 / (3 * EI), P * L**2 / (2 * EI)


def deflection_shape_tip_force(x, P: float, L: float, EI: float):
    """Deflection w(x) (m) under a tip force: P x^2 (3L - x) / (6 EI)."""
    x = np.asarray(x, dtype=float)
    return P * x**2 * (3 * L - x) / (6 * EI)


def tip_moment_deflection(M: float, L: float, EI: float) -> Tuple[float, float]:
    """Tip deflection (m) and slope (rad) under a tip moment M (N m): ML^2/2EI, ML/EI."""
    return M * L**2 / (2 * EI), M * L / EI


def uniform_load_deflection(q: float, L: float, EI: float) -> Tuple[float, float]:
    """Tip deflection (m) and slope (rad) under a uniform load q (N/m): qL^4/8EI, qL^3/6EI."""
    return q * L**4 / (8 * EI), q * L**3 / (6 * EI)


# ---------------------------------------------------------------- large deflection
@dataclass(frozen=True)
class Elastica:
    """Solution of the planar elastica: arc length s, centreline x(s), y(s), angle theta(s)."""

    s: np.ndarray
    x: np.ndarray
    y: np.ndarray
    theta: np.ndarray

    @property
    def tip(self) -> Tuple[float, float]:
        return float(self.x[-1]), float(self.y[-1])

    @property
    def tip_angle(self) -> float:
        return float(self.theta[-1])


def elastica_tip_force(P: float, L: float, EI: float, axial: float = 0.0,
                       tip_moment: float = 0.0, n: int = 401) -> Elastica:
    """Large-deflection cantilever under a dead tip load, solved as a BVP with scipy.

    ``P`` is the force component perpendicular to the undeformed axis (N), ``axial`` the
    component along it (N, > 0 pulls the tip away from the clamp), ``tip_moment`` a tip
    couple (N m). Equations in arc length s: x' = cos(theta), y' = sin(theta),
    EI theta'' = -(P cos(theta) - axial sin(theta)); theta(0) = 0, EI theta'(L) = tip_moment.
    Continuation in the load from the small-deflection solution keeps the solver on the
    primary branch.
    """
    check_positive("L", L, "m")
    check_positive("EI", EI, "N m^2")
    s = np.linspace(0.0, L, n)

    def solve(frac, guess):
        p, a, m = frac * P, frac * axial, frac * tip_moment

        def rhs(_s, u):
            th, k = u[0], u[1]
            return np.vstack([k, -(p * np.cos(th) - a * np.sin(th)) / EI, np.cos(th), np.sin(th)])

        def bc(u0, uL):
            return np.array([u0[0], uL[1] - m / EI, u0[2], u0[3]])

        sol = integrate.solve_bvp(rhs, bc, s, guess, tol=1e-9, max_nodes=200000)
        if not sol.success:
            raise RuntimeError(f"elastica BVP did not converge at load fraction {frac}: {sol.message}")
        return sol.sol(s)

    # initial guess: small-deflection shape
    th0 = (P * (L * s - s**2 / 2) + tip_moment * s) / EI * 1e-3
    guess = np.vstack([th0, np.gradient(th0, s), s, np.zeros_like(s)])
    u = guess
    for frac in np.linspace(0.1, 1.0, 10):
        u = solve(frac, u)
    return Elastica(s=s, x=u[2], y=u[3], theta=u[0])


def arc_tip_moment(M: float, L: float, EI: float) -> Tuple[float, float, float]:
    """Exact tip position (x, y) (m) and angle (rad) of a beam bent by a tip couple M:
    uniform curvature kappa = M/EI, x = sin(kappa L)/kappa, y = (1 - cos(kappa L))/kappa."""
    k = M / EI
    if abs(k * L) < 1e-12:
        return L, 0.0, 0.0
    return np.sin(k * L) / k, (1 - np.cos(k * L)) / k, k * L


def arc_curvature(x: float, y: float) -> float:
    """Curvature (1/m) of the circular arc tangent to the beam axis at the clamp (origin,
    axis along x) that passes through the tip (x, y): kappa = 2 y / (x^2 + y^2).
    This is how seed 000 measures the curvature of the whole actuator."""
    return 2.0 * y / (x * x + y * y)


# ---------------------------------------------------------------- vibration
def natural_frequencies(L: float, EI: float, mass_per_length: float, tip_mass: float = 0.0,
                        tip_inertia: float = 0.0, n: int = 3) -> np.ndarray:
    """First ``n`` bending natural frequencies (Hz) of a uniform cantilever carrying a tip
    mass (kg) with rotary inertia about its centre (kg m^2), the mass centred at the tip.

    Characteristic equation (Erturk & Inman 2011, eq. 3.16) in lambda = beta L:
    1 + cos l cosh l + l Mr (cos l sinh l - sin l cosh l)
      - l^3 Jr (cosh l sin l + sinh l cos l) + l^4 Mr Jr (1 - cos l cosh l) = 0,
    Mr = M_t/(m L), Jr = I_t/(m L^3); omega = l^2 sqrt(EI / (m L^4)).
    """
    check_positive("mass_per_length", mass_per_length, "kg/m")
    Mr = tip_mass / (mass_per_length * L)
    Jr = tip_inertia / (mass_per_length * L**3)

    def f(l):
        c, ch, sn, sh = np.cos(l), np.cosh(l), np.sin(l), np.sinh(l)
        # divided by cosh(l) to keep the numbers finite for the higher roots
        return (1 / ch + c + l * Mr * (c * sh / ch - sn) - l**3 * Jr * (sn + sh / ch * c)
                + l**4 * Mr * Jr * (1 / ch - c))

    roots, grid = [], np.linspace(1e-3, 4 * (n + 1) * np.pi, 20000)
    vals = f(grid)
    for a, b, fa, fb in zip(grid[:-1], grid[1:], vals[:-1], vals[1:]):
        if fa == 0 or fa * fb < 0:
            roots.append(optimize.brentq(f, a, b, xtol=1e-14))
            if len(roots) == n:
                break
    lam = np.array(roots)
    return lam**2 * np.sqrt(EI / (mass_per_length * L**4)) / (2 * np.pi)


# ---------------------------------------------------------------- axial load
def buckling_load(L: float, EI: float) -> float:
    """Euler load (N) of a clamped-free column under a dead axial tip load: pi^2 EI / (4 L^2)."""
    return np.pi**2 * EI / (4 * L**2)


def lateral_stiffness(L: float, EI: float, axial: float = 0.0) -> float:
    """Small-deflection lateral tip stiffness (N/m) of a cantilever under a dead axial tip
    load ``axial`` (N): > 0 tension (payload hanging below the clamp), < 0 compression
    (payload above the clamp). With a = sqrt(|axial| / EI):
      tension:      k = T a / (a L - tanh(a L))
      compression:  k = P a / (tan(a L) - a L)     (-> 0 at the Euler load, < 0 beyond)
      none:         k = 3 EI / L^3.
    """
    if abs(axial) < 1e-12 * EI / L**2:
        return 3 * EI / L**3
    a = np.sqrt(abs(axial) / EI)
    if axial > 0:
        return axial * a / (a * L - np.tanh(a * L))
    if a * L >= np.pi / 2:
        raise ParameterError("axial", axial, f"a compression below the Euler load {buckling_load(L, EI):.6g} N")
    return -axial * a / (np.tan(a * L) - a * L)
