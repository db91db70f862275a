"""Contact at micro scale (:class:`ContactParameters`): MuJoCo's contact set for beams of
tens of micrometres and the bodies they touch, applied to a host model by
:class:`mjeap.System`."""
from __future__ import annotations

from dataclasses import dataclass

import mujoco
import numpy as np

from ..errors import ParameterError

__all__ = ["ContactParameters"]


_CONES = {"elliptic": mujoco.mjtCone.mjCONE_ELLIPTIC, "pyramidal": mujoco.mjtCone.mjCONE_PYRAMIDAL}


@dataclass(frozen=True)
class ContactParameters:
    """Contact for micro-scale systems, applied to every contact of the system (MuJoCo's
    ``override`` flag), internal units derived from the timestep h.

    * ``solref`` = (``timeconst_steps`` x h, ``dampratio``): the stiffest contact MuJoCo
      integrates stably is a time constant of 2 h (it raises smaller ones to 2 h);
      critically damped, so a beam closing on a body does not bounce.
    * ``solimp`` = (0.99, 0.999, ``width_fraction`` x the thinnest beam, 0.5, 2): impedance
      near 1 makes the contact nearly rigid. At rest the penetration is
      F (1 - d) (timeconst)^2 / m_eff for a force F on an effective mass m_eff; for the
      actuators here that is far below their thickness (tested: a beam pressing on a block).
    * ``margin`` 0, ``friction`` = (sliding coefficient, torsional m, rolling m) =
      (0.5, 5 um, 0.1 um), an elliptic cone (``cone``). The torsional and rolling
      coefficients are lengths (the moment they resist per newton of normal force) and act
      only where a geom asks for them (condim 4 or 6; the beams' geoms are condim 3).
    * ``impratio``: the friction rows' regularisation is the normal row's divided by it.
      MuJoCo's friction is soft: under a steady tangential load f a sticking contact creeps
      at about f R / b (R its regulariser, b = 1 / h its damping); impratio > 1 cuts the
      creep by that factor (elliptic cones only).

    Sizing a contact from its physics (the defaults suit a beam closing on a part, the
    gripper's and the rod's tests; a system whose contacts carry a body may need others:
    mjeap.robots.hamr_walk sizes the walker's feet this way). With dampratio 1 a contact's
    penetration r obeys r'' + (2 / tau) r' + r / tau^2 = 0 (MuJoCo's reference
    acceleration; b = 2 / (dmax tau), k = 1 / (dmax tau dampratio)^2), for any mass:

    * tau well above the step: at 2 h (MuJoCo's floor) the normal and friction rows are
      deadbeat from one step to the next and a contact that carries a body through other
      stiff constraints can chatter; ~10 steps resolve the response.
    * tau well below the contact's physical time scales: the critically damped response
      settles in about 5 tau, which should be a small share of the shortest contact event
      (a stance); a body landing at speed v penetrates at most v tau / e (critical damping),
      to be kept within the solimp width (the penetration the model tolerates).
    * At rest a contact carrying a force F on an effective mass m (1 / its diagonal of
      J M^-1 J^T) penetrates about (1 - d) / d^2 x tau^2 F / m (d = dmin at a shallow depth):
      the impedance d sets how rigid it is beside tau; and a sticking contact under a
      tangential force f creeps at about (1 - d) / d x (f / m) x dmax tau / (2 impratio):
      longer time constants creep more, impratio cuts it.
    * Under 'implicitfast' MuJoCo sizes contact impulses for M alone while the step
      integrates M + hD: a contact coupled to a damped beam (through a transmission, say)
      is then mis-sized and can chatter however the contact is set; 'discrete' solves it in
      the step's own metric (:func:`attach`'s ``integrator``).
    """

    timeconst_steps: float = 2.0
    dampratio: float = 1.0
    impedance: tuple = (0.99, 0.999)
    width_fraction: float = 0.1
    friction: tuple = (0.5, 5e-6, 1e-7)
    margin: float = 0.0
    cone: str = "elliptic"
    impratio: float = 1.0

    def __post_init__(self):
        if len(self.friction) != 3 or not all(np.isfinite(f) and f >= 0 for f in self.friction):
            raise ParameterError("friction", self.friction, "(sliding >= 0, torsional >= 0 m, rolling >= 0 m)")
        if self.cone not in _CONES:
            raise ParameterError("cone", self.cone, " or ".join(f"'{c}'" for c in _CONES))
        if not (np.isfinite(self.impratio) and self.impratio >= 1.0):
            raise ParameterError("impratio", self.impratio, "a ratio >= 1")

    def apply(self, spec: mujoco.MjSpec, h: float, thickness: float, length: float) -> None:
        """Set the host's contact override: ``h`` and ``thickness`` internal, ``length`` the
        SI size (m) of one internal length unit."""
        o = spec.option
        o.disableflags &= ~int(mujoco.mjtDisableBit.mjDSBL_CONTACT)
        o.enableflags |= int(mujoco.mjtEnableBit.mjENBL_OVERRIDE)
        o.o_solref = [self.timeconst_steps * h, self.dampratio]
        o.o_solimp = [self.impedance[0], self.impedance[1], self.width_fraction * thickness, 0.5, 2.0]
        o.o_margin = self.margin
        mu, torsion, rolling = self.friction[0], self.friction[1] / length, self.friction[2] / length
        o.o_friction = [mu, mu, torsion, rolling, rolling]
        o.cone = _CONES[self.cone]
        o.impratio = self.impratio
