"""Documented calibrations of unknowns the sources leave open.

:func:`calibrate_tip_mass`: Jayaram et al. 2018's bimorphs, built from their physical parameter set
(effective moduli, layer thicknesses, alumina tip blocks; see the catalog), still resonate
above Table 1. One labelled residual per type closes the gap: mass added to the rigid tip
block at fixed block length, fitted (scipy brentq) so that the scene's first mode equals the
measured resonance. A tip mass leaves both static gains (free deflection under the drive's
internal moment, blocked force at the tip) exactly as they were, which a clamp compliance
would not (it softens the blocked force), and it does not shrink with a narrow tip as a
longer alumina block would. The result is an *identified* parameter: it absorbs every other
stiffness or mass error of the model, and :class:`TipMassCalibration` says how plausible it
is against the block it sits on and the actuator's own mass.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..model.catalog import Actuator, get_actuator
from ..errors import ParameterError, check_positive
from ..model.modes import linearize
from ..simulation.scene import Scene
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize, linalg = (lazy_module(f"scipy.{m}") for m in ("optimize", "linalg"))


@dataclass(frozen=True)
class TipMassCalibration:
    """The residual tip-block mass that brings the first mode to ``target_frequency``."""

    actuator: Actuator             # the actuator with the fitted residual
    residual_mass: float           # kg, added to the tip block
    block_mass: float              # kg, the block's own material
    beam_mass: float               # kg, the active length
    first_frequency: float         # Hz, of the calibrated model
    target_frequency: float        # Hz
    uncalibrated_frequency: float  # Hz, physical parameter set, no residual

    @property
    def residual_per_block(self) -> float:
        """Residual / the alumina block's mass (-)."""
        return self.residual_mass / self.block_mass if self.block_mass > 0 else float("inf")

    @property
    def residual_per_beam(self) -> float:
        """Residual / the active beam's mass (-)."""
        return self.residual_mass / self.beam_mass


def with_residual(act: Actuator, mass: float) -> Actuator:
    """``act`` with ``mass`` kg of residual tip-block mass (replacing any it had)."""
    return replace(act, planform=replace(act.planform, residual_tip_mass=float(mass)))


def calibrate_tip_mass(actuator, target_frequency: float, segments: int = 20,
                       max_mass_ratio: float = 2.0) -> TipMassCalibration:
    """Residual tip-block mass (kg, at most ``max_mass_ratio`` x the beam's mass) that brings
    the first bending mode of the scene (horizontal, unloaded, hinge chain) to
    ``target_frequency`` Hz. The actuator needs a tip block (a rigid extension)."""
    act = with_residual(get_actuator(actuator), 0.0)
    check_positive("target_frequency", target_frequency, "Hz")
    if act.planform.extension_length <= 0:
        raise ParameterError("actuator", act.id, "an actuator with a rigid tip block (planform.extension_length > 0)")

    def f1(mass):
        return Scene(with_residual(act, mass), segments=segments).choice.first_frequency

    f0 = f1(0.0)
    mmax = max_mass_ratio * act.total_mass()
    if not (f1(mmax) < target_frequency < f0):
        raise ParameterError("target_frequency", target_frequency,
                             f"a frequency between {f1(mmax):.4g} and {f0:.4g} Hz, reachable with a residual tip "
                             f"mass of 0..{mmax:.3g} kg")
    mass = optimize.brentq(lambda m: f1(m) - target_frequency, 0.0, mmax, xtol=1e-12)
    return TipMassCalibration(with_residual(act, mass), mass, act.planform.extension_mass, act.total_mass(),
                              f1(mass), target_frequency, f0)


def clamp_stiffness_for_frequency(actuator, target_frequency: float, segments: int = 20) -> float:
    """The alternative residual, for comparison: the rotational stiffness (N m/rad) of a clamp
    spring in series with the root hinge that brings the first mode (modal analysis of the
    linearised scene) to ``target_frequency`` Hz."""
    s = Scene(get_actuator(actuator), segments=segments)
    lin = linearize(s.model)
    j0 = int(s.model.jnt_dofadr[0])
    k0 = lin.K_elastic[j0, j0]
    w_target = 2 * np.pi * check_positive("target_frequency", target_frequency, "Hz") * s.units.time

    def excess(log_kc):
        K = lin.K_elastic.copy()
        K[j0, j0] = 1.0 / (1.0 / k0 + np.exp(-log_kc))
        return np.sqrt(linalg.eigh(K, lin.M, eigvals_only=True)[0]) - w_target

    if excess(np.log(1e9 * k0)) < 0 or excess(np.log(1e-9 * k0)) > 0:
        raise ParameterError("target_frequency", target_frequency, "a frequency below the scene's first mode")
    log_kc = optimize.brentq(excess, np.log(1e-9 * k0), np.log(1e9 * k0), xtol=1e-10)
    return float(np.exp(log_kc) * s.units.rotational_stiffness)
