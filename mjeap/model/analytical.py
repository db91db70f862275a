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

from ..errors import ParameterError, check_positive
from ..lazy import lazy_module
from . import lti
from .section import SectionLayer, SectionProperties, multilayer_section  # noqa: F401  (re-export)

#: scipy's parts, imported at their first use (:mod:`mjeap.lazy`)
integrate, optimize, signal = (lazy_module(f"scipy.{m}") for m in ("integrate", "optimize", "signal"))

__all__ = [
    "tip_force_deflection", "tip_moment_deflection", "uniform_load_deflection",
    "deflection_shape_tip_force", "elastica_tip_force", "Elastica", "arc_tip_moment",
    "natural_frequencies", "lateral_stiffness", "buckling_load", "arc_curvature",
    "multilayer_section", "SectionLayer", "SectionProperties", "lateral_stiffness_column",
    "critical_tip_load", "postbuckled_column", "bimorph_stiffness_per_width", "bimorph_geometry_factor",
    "bimorph_free_deflection", "bimorph_blocked_force", "bimorph_motional_current",
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
    couple (N m). In xi = s / L with p = P L^2/EI, a = axial L^2/EI, m = M L/EI:
    theta'' = -(p cos(theta) - a sin(theta)), theta(0) = 0, theta'(1) = m; x' = cos(theta),
    y' = sin(theta). Continuation in the load from the unloaded beam keeps the solver on
    the primary branch.
    """
    check_positive("L", L, "m")
    check_positive("EI", EI, "N m^2")
    xi = np.linspace(0.0, 1.0, n)
    p0, a0, m0 = P * L**2 / EI, axial * L**2 / EI, tip_moment * L / EI

    def solve(frac, guess):
        p, a, m = frac * p0, frac * a0, frac * m0

        def rhs(_s, u):
            th = u[0]
            return np.vstack([u[1], -(p * np.cos(th) - a * np.sin(th)), np.cos(th), np.sin(th)])

        def bc(u0, u1):
            return np.array([u0[0], u1[1] - m, u0[2], u0[3]])

        sol = integrate.solve_bvp(rhs, bc, xi, guess, tol=1e-10, max_nodes=100000)
        if not sol.success:
            raise RuntimeError(f"elastica BVP did not converge at load fraction {frac}: {sol.message}")
        return sol.sol(xi)

    u = np.vstack([np.zeros_like(xi), np.zeros_like(xi), xi, np.zeros_like(xi)])
    for frac in np.linspace(0.1, 1.0, 10):
        u = solve(frac, u)
    return Elastica(s=xi * L, x=u[2] * L, y=u[3] * L, theta=u[0])


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
    This is how Dadras et al. 2021 measures the curvature of the whole actuator."""
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


def _column_rhs(tau_tip: float, kq: float):
    """Linear column equation in xi = x / L for u = [W, dW, d2W, d3W] (derivatives in xi):
    d4W = d(tau dW) with tau(xi) = tau_tip + kq (1 - xi), tau = T L^2 / EI (tension > 0)."""
    def rhs(s, u):
        return np.array([u[1], u[2], u[3], -kq * u[1] + (tau_tip + kq * (1 - s)) * u[2]])
    return rhs


def lateral_stiffness_column(L: float, EI: float, tip_tension: float, weight_per_length: float = 0.0) -> float:
    """Lateral tip stiffness (N/m) of a cantilever column with axial tension
    T(x) = tip_tension + weight_per_length (L - x) (N; negative = compression).

    Linear BVP EI w'''' = (T w')', w(0) = w'(0) = 0, w''(L) = 0 and the tip shear
    -EI w'''(L) + T(L) w'(L) = F, solved with scipy in xi = x / L, W = w EI / (F L^3).
    Unlike :func:`lateral_stiffness` it includes the beam's own weight. Returns F / w(L);
    k passes continuously through 0 at the buckling load and is negative beyond.
    """
    tau_tip = tip_tension * L**2 / EI
    kq = weight_per_length * L**3 / EI
    xi = np.linspace(0.0, 1.0, 101)
    rhs = _column_rhs(tau_tip, kq)

    def bc(u0, u1):
        return np.array([u0[0], u0[1], u1[2], -u1[3] + tau_tip * u1[1] - 1.0])

    guess = np.vstack([xi**2 * (3 - xi) / 6, xi * (2 - xi) / 2, 1 - xi, -np.ones_like(xi)])
    sol = integrate.solve_bvp(rhs, bc, xi, guess, tol=1e-8, max_nodes=100000)
    if not sol.success:
        raise RuntimeError(f"column BVP did not converge: {sol.message}")
    return EI / (L**3 * float(sol.sol(1.0)[0]))


def critical_tip_load(L: float, EI: float, weight_per_length: float = 0.0) -> float:
    """Compressive dead tip load (N) at which a cantilever standing up under its own
    weight buckles; pi^2 EI / (4 L^2) when weightless.

    Shooting on the homogeneous column equation (scipy solve_ivp): the two solutions with
    W(0) = W'(0) = 0 must satisfy W''(1) = 0 and -W'''(1) + tau(1) W'(1) = 0 together,
    i.e. their 2 x 2 determinant vanishes at the critical load.
    """
    Pe = buckling_load(L, EI)
    kq = -weight_per_length * L**3 / EI

    def det(P):
        tau_tip = -P * L**2 / EI
        rhs = _column_rhs(tau_tip, kq)
        cols = []
        for init in ([0, 0, 1, 0], [0, 0, 0, 1]):
            u = integrate.solve_ivp(rhs, (0, 1), init, rtol=1e-11, atol=1e-13).y[:, -1]
            cols.append([u[2], -u[3] + tau_tip * u[1]])
        return cols[0][0] * cols[1][1] - cols[0][1] * cols[1][0]

    return optimize.brentq(det, 0.5 * Pe, 1.5 * Pe, xtol=1e-12 * Pe)


def postbuckled_column(load_ratio: float, L: float) -> Tuple[float, float, float]:
    """Post-buckled equilibrium of a clamped-free column under a dead axial tip load
    P = load_ratio x P_cr (load_ratio >= 1), exact elastica (Timoshenko & Gere 1961, sec. 2.7):
    with p = sin(alpha/2), alpha the tip angle, P / P_cr = (2 K(p^2) / pi)^2;
    lateral tip deflection delta = 2 p L / K, axial tip position x = L (2 E(p^2) / K - 1).
    Returns (x, delta, alpha) in m, m, rad. scipy's ellipk/ellipe take m = p^2."""
    from scipy.special import ellipe, ellipk
    if load_ratio < 1.0:
        raise ParameterError("load_ratio", load_ratio, "a value >= 1 (below it the column stays straight)")
    if load_ratio == 1.0:
        return L, 0.0, 0.0
    target = 0.5 * np.pi * np.sqrt(load_ratio)
    m = optimize.brentq(lambda m: ellipk(m) - target, 0.0, 1.0 - 1e-15)
    K, E = ellipk(m), ellipe(m)
    p = np.sqrt(m)
    return L * (2 * E / K - 1), 2 * p * L / K, 2 * np.arcsin(p)


def critical_load_with_arm(L: float, EI: float, arm: float = 0.0) -> float:
    """Dead vertical load (N) at which a weightless cantilever standing up buckles when the
    load sits on a rigid arm of length ``arm`` (m) beyond the tip (payload centre at L + arm).
    From EI w'' = P (Delta - w), Delta = w(L) + arm w'(L): k arm tan(kL) = 1, k = sqrt(P/EI);
    pi^2 EI / (4 L^2) for arm = 0."""
    L, EI = check_positive("L", L, "m"), check_positive("EI", EI, "N m^2")
    if arm < 0:
        raise ParameterError("arm", arm, "a length >= 0 m")
    if arm == 0:
        return buckling_load(L, EI)
    kL = optimize.brentq(lambda q: q * (arm / L) * np.sin(q) - np.cos(q), 1e-9, 0.5 * np.pi)
    return EI * (kL / L) ** 2


# ---------------------------------------------------------------- Dadras et al. 2021's loaded-actuator model
#: Table I of Dadras et al. 2021: region upper bounds of kappa*l_e (rad), feedback and input coefficients
DADRAS_REGIONS = ((-1.05, 0.24, -0.60), (-0.55, 0.70, -0.14), (0.55, 1.00, 0.0), (1.05, 0.70, 0.14),
                  (np.inf, 0.24, 0.60))


@dataclass(frozen=True)
class DadrasModel:
    """Dadras et al. 2021's lumped model (SI): electrical block (k_tf / g_m) / (s + a) from volts to an
    equivalent moment (N m), mechanical block g_m (s + z) / (s + p) from moment to curvature
    (1/m), with g_m = 1/EI = 4.86e7 1/(N m^2); together eq. (8),
    K/V = 63 (s + 0.52) / ((s + 0.3)(s + 1.8)). A payload closes a positive feedback loop on
    the mechanical block (Table I)."""

    k_tf: float = 63.0
    zero: float = 0.52
    pole: float = 0.3
    electrical_pole: float = 1.8
    mechanical_gain: float = 4.86e7
    gravity: float = 9.81

    def region_coefficients(self, mass: float, l_e: float, region: int) -> Tuple[float, float]:
        """(feedback f in N m^2, constant input M_l in N m) of Table I's region 1-5."""
        _, cf, cl = DADRAS_REGIONS[region - 1]
        W = mass * self.gravity
        return cf * W * 2 * l_e**2 / 3, cl * W * 2 * l_e / 3

    @staticmethod
    def region_of(kappa: float, l_e: float) -> int:
        angle = kappa * l_e
        return next(i + 1 for i, (hi, _, _) in enumerate(DADRAS_REGIONS) if angle < hi)

    def region3_pole(self, mass: float, l_e: float) -> float:
        """Closed-loop mechanical pole (1/s) of Region 3 (small angles):
        s = -(p - g_m f z) / (1 - g_m f); it crosses zero when g_m f z = p."""
        f, _ = self.region_coefficients(mass, l_e, 3)
        gf = self.mechanical_gain * f
        return -(self.pole - gf * self.zero) / (1 - gf)

    def marginal_mass(self, l_e: float) -> float:
        """Payload mass (kg) at which the Region 3 pole reaches the origin."""
        return 3 * self.pole / (2 * self.mechanical_gain * self.zero * self.gravity * l_e**2)

    def free_curvature(self, t: np.ndarray, v: np.ndarray) -> np.ndarray:
        """Curvature (1/m) of the unloaded beam at the uniform sample times ``t`` (s) for the
        voltage samples ``v`` (V, held between samples), from rest: eq. (8) (:func:`lti.lsim`, as scipy's)."""
        tf = signal.TransferFunction([self.k_tf, self.k_tf * self.zero],
                                     np.polymul([1.0, self.pole], [1.0, self.electrical_pole]))
        return lti.lsim(tf, v, t, interp=False)

    def grip_force(self, t: np.ndarray, v: np.ndarray, a: float, gap: float) -> np.ndarray:
        """Contact force (N) of this actuator closing a gap ``gap`` (m) on a rigid stop at
        ``a`` (m) from the clamp, at the uniform sample times ``t`` (s) for the voltage
        samples ``v`` (V, held), quasi-static and small deflection.

        Free, the deflection at a is y(t) = kappa(t) a^2 / 2 (uniform moment). Once it
        reaches the stop (y = gap, then y increasing) the stop takes the excess: with the
        mechanical block's relaxation modulus E(t) = EI [p/z + (1 - p/z) exp(-z t)] (the
        standard linear solid whose compliance is g_m (s + z)/(s + p)), F(t) = (3 / a^3)
        int E(t - tau) d/dtau max(y(tau) - gap, 0) dtau, i.e. the excess filtered by
        (3 EI / a^3)(s + p)/(s + z) (scipy lsim). Limits: without relaxation
        F = 3 M / (2 a) - 3 EI gap / a^3 (instantaneous EI); long after a held voltage
        F = 3 M / (2 a) - 3 (EI p / z) gap / a^3 (relaxed EI), M = the relaxed moment."""
        EI = 1.0 / self.mechanical_gain
        excess = np.clip(self.free_curvature(t, v) * a**2 / 2 - gap, 0.0, None)
        tf = signal.TransferFunction([3 * EI / a**3, 3 * EI / a**3 * self.pole], [1.0, self.zero])
        return lti.lsim(tf, excess, t, interp=True)

    def response(self, t: np.ndarray, v: np.ndarray, mass: float = 0.0, l_e: float = 6e-3,
                 kappa0: float = 0.0) -> Tuple[np.ndarray, np.ndarray]:
        """Curvature (1/m) and region number at the sample times ``t`` (s, uniform) for the
        voltage samples ``v`` (V, held between samples), as the paper describes it: in each
        region the closed-loop system with that region's feedback and constant mechanical
        input; on entering a region the curvature carries over (the mechanical state is
        re-initialised so that kappa is continuous), the electrical state carries over.
        The initial curvature kappa(0-) sits on the mechanical state (as in eq. (7)).
        Exact zero-order-hold discretisation per region (scipy.signal.cont2discrete)."""
        from scipy import signal
        t, v = np.asarray(t, float), np.asarray(v, float)
        h = float(t[1] - t[0])
        gm, z, p, a = self.mechanical_gain, self.zero, self.pole, self.electrical_pole
        b = self.k_tf / gm
        cache = {}

        def discrete(region):
            if region not in cache:
                f, Ml = self.region_coefficients(mass, l_e, region)
                c = gm / (1 - gm * f)               # kappa = c (x + u_e + M_l)
                # states (u_e, x); x' = -p x + (z - p)(u_e + M_l + f kappa); inputs (V, M_l)
                A = np.array([[-a, 0.0], [(z - p) * (1 + f * c), -p + (z - p) * f * c]])
                B = np.array([[b, 0.0], [0.0, (z - p) * (1 + f * c)]])
                Ad, Bd, *_ = signal.cont2discrete((A, B, np.eye(2), np.zeros((2, 2))), h, method="zoh")
                cache[region] = (Ad, Bd, c, Ml)
            return cache[region]

        region = self.region_of(kappa0, l_e)
        Ad, Bd, c, Ml = discrete(region)
        s = np.array([0.0, kappa0 / c - Ml])
        kap, reg = np.empty(len(t)), np.empty(len(t), dtype=int)
        for i in range(len(t)):
            k = c * (s[0] + s[1] + Ml)
            new = self.region_of(k, l_e)
            if new != region:
                region = new
                Ad, Bd, c, Ml = discrete(region)
                s[1] = k / c - s[0] - Ml
            kap[i], reg[i] = k, region
            s = Ad @ s + Bd @ np.array([v[i], Ml])
        return kap, reg


def first_frequency_variable(L: float, EI, mass_per_length, guess: float, tip_mass: float = 0.0,
                             tip_offset: float = 0.0, tip_inertia: float = 0.0) -> float:
    """First bending frequency (Hz) of a clamped-free Euler-Bernoulli beam with EI(x) (N m^2)
    and m(x) (kg/m) given as callables, e.g. a tapered plate: (EI y'')'' = omega^2 m y solved
    as a boundary-value eigenproblem (scipy solve_bvp, omega^2 an unknown parameter, the
    tip deflection normalised to 1). ``guess`` (Hz) selects the mode.

    A rigid body may sit on the tip (a tip block): ``tip_mass`` (kg) with its centre
    ``tip_offset`` (m) past x = L along the tip's tangent and ``tip_inertia`` (kg m^2) about
    its centre. Its inertia enters the free end's conditions (from the stationarity of
    U - T): M(L) = omega^2 [m e (y + e y') + J y'] and V(L) = -omega^2 m (y + e y')."""
    L = check_positive("L", L, "m")

    EI0, m0 = float(EI(0.0)), float(mass_per_length(0.0))
    check_positive("EI(0)", EI0, "N m^2")
    check_positive("mass_per_length(0)", m0, "kg/m")
    mu_t, e_t, j_t = tip_mass / (m0 * L), tip_offset / L, tip_inertia / (m0 * L**3)

    # nondimensional: x = L xi, EI = EI0 e(xi), m = m0 mu(xi), lam = omega^2 m0 L^4 / EI0
    def rhs(xi, u, p):
        y, th, M, V = u
        return np.vstack([th, M / (EI(xi * L) / EI0), V, p[0] * (mass_per_length(xi * L) / m0) * y])

    def bc(u0, u1, p):
        y, th, M, V = u1
        lam = p[0]
        return np.array([u0[0], u0[1], M - lam * (mu_t * e_t * (y + e_t * th) + j_t * th),
                         V + lam * mu_t * (y + e_t * th), y - 1.0])

    xi = np.linspace(0, 1, 100)
    lam = (2 * np.pi * guess) ** 2 * m0 * L**4 / EI0
    u0 = np.vstack([xi**2 * (3 - xi) / 2, 3 * xi * (2 - xi) / 2, 3 * (1 - xi), -3 * np.ones_like(xi)])
    sol = integrate.solve_bvp(rhs, bc, xi, u0, p=[lam], tol=1e-8, max_nodes=20000)
    if not sol.success:
        raise RuntimeError(f"eigenvalue BVP did not converge: {sol.message}")
    return float(np.sqrt(sol.p[0] * EI0 / (m0 * L**4)) / (2 * np.pi))


# ------------------------------------------- PZT bimorph closed forms (Jayaram et al. 2018's actuators)
# Transcribed, with the published variables, from Jafferis et al. 2015 (Smart Mater. Struct. 24
# 065023) as Harvard's own HAMR actuator model implements them (HarvardAgileRoboticsLab/drake,
# examples/HAMR-URDF/dev/Actuator/PZTBender2.m: ``df``, ``GF``, ``Ft``/``Fb``), and Jayaram et al. 2018's
# eq. (13). Independent of mjeap's drive and section code: they are the checks of those.
#
# V is the closed form's voltage, the difference of the two plates' voltages: PZTBender2 sets
# the field eps = (V_b - V_g) / t_p at full drive, and its force is Ft - Fb with the plates at
# V_b - V_sig and V_sig - V_g. Under unipolar simultaneous drive (V_g = 0) that is
# V = |2 V_sig - V_bias|, i.e. V_bias at full drive.

def bimorph_stiffness_per_width(E_p: float, t_p: float, E_cf: float, t_cf: float) -> float:
    """Bending stiffness per width of a symmetric PZT / carbon-fibre / PZT bimorph (N m):
    D = (1/3) E_p t_p (1.5 t_cf^2 + 3 t_cf t_p + 2 t_p^2) + E_cf t_cf^3 / 12 (Jafferis 2015;
    PZTBender2's ``df_den``)."""
    return (E_p * t_p * (1.5 * t_cf**2 + 3 * t_cf * t_p + 2 * t_p**2) / 3 + E_cf * t_cf**3 / 12)


def bimorph_geometry_factor(width_ratio: float, length_ratio: float) -> float:
    """Blocked-force geometry factor G_F of the trapezoidal bimorph with a rigid extension
    (Jafferis 2015; PZTBender2's ``GF``): width_ratio w_r = base width / nominal width (the
    nominal width w_n is the mean of base and tip, so the tip is (2 - w_r) w_n), length_ratio
    l_r = extension length / active length. G_F = 1 for a rectangle without extension."""
    wr, lr = float(width_ratio), float(length_ratio)
    if not 0.0 < wr < 2.0:
        raise ParameterError("width_ratio", wr, "0 < w_r < 2 (base width / mean width)")
    if abs(wr - 1.0) < 1e-3:
        # near a rectangle the closed form cancels (0/0): its limit, within 0.05 % here
        return (1 + 2 * lr) / ((1 + lr) ** 3 - lr**3)
    num = 8 * (1 - wr) ** 3 * (1 + 2 * lr)
    den = (-6 * (wr - 1) * (-3 + 4 * lr * (wr - 1) + 2 * wr)
           + 3 * (-2 + 2 * lr * (wr - 1) + wr) ** 2 * np.log((2 - wr) / wr))
    return num / den


def bimorph_free_deflection(f31: float, V: float, t_p: float, t_cf: float, L: float, length_ratio: float,
                            D: float) -> float:
    """Free deflection (m) at the end of the rigid extension: (1/4)(1 + 2 l_r) f31 V
    (t_p + t_cf) L^2 / D (Jafferis 2015; PZTBender2's ``df``), f31 the effective stress per
    field (Pa m/V), V the difference of the plates' voltages (V_bias at full drive)."""
    return 0.25 * (1 + 2 * length_ratio) * f31 * V * (t_p + t_cf) * L**2 / D


def bimorph_blocked_force(f31: float, V: float, t_p: float, t_cf: float, L: float, nominal_width: float,
                          width_ratio: float, length_ratio: float) -> float:
    """Blocked force (N) at the end of the rigid extension: (3/4)(w_n / L) f31 (t_p + t_cf) V
    G_F (Jafferis 2015; PZTBender2's ``Ft - Fb``), w_n the nominal (mean) width."""
    return 0.75 * nominal_width / L * f31 * (t_p + t_cf) * V * bimorph_geometry_factor(width_ratio, length_ratio)


def bimorph_motional_current(f31: float, area: float, strain_rate):
    """Jayaram et al. 2018 eq. (13): the motional current of a free bimorph, I = 2 A f31 d(eps_1)/dt (A),
    A the electrode area of one plate (m^2), eps_1 the bending strain of one plate (its
    mean over the plate; the two plates' strains are opposite and their currents add)."""
    return 2.0 * area * f31 * np.asarray(strain_rate)
