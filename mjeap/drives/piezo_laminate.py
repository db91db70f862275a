"""``drive = "piezo"``: any laminate with one or more piezo layers (a unimorph, an
asymmetric bimorph, a multilayer) from datasheet constants (:mod:`mjeap.model.laminate`).

Each ``role = "piezo"`` layer takes d31 (or e31 = d31 Y), a relative permittivity
eps33^T / eps0, an ``electrode`` (``"signal"``: V; ``"complement"``: ``bias`` - V) and a
``poling`` (``"up"`` or ``"down"``). At hinge j (position x_j, width w(x_j)) the moment is
the section's free-strain moment about its neutral axis, M_j = Gamma_j V + M0_j
(:meth:`mjeap.model.laminate.Laminate.moment`), so the drive is linear in V like
``piezo-bimorph`` and shares its stepping, its current and its native form
(:class:`mjeap.drives.piezo.LinearPiezo`):

    I = sum_j V_j / R_j + C dV/dt + sum_j Gamma_j dtheta_j/dt,

C the clamped (dielectric) capacitance sum_j (eps33^T - d31 e_j) A_j / t_j, or the
``capacitance`` parameter where given (a measured dielectric term overrides the derived
one); the motional term's coefficient is dM_j/dV (reciprocity), which carries the direct
effect. ``resistance`` (optional) is the leakage seen from the signal terminal, shared by the
piezo layers in proportion to A_j / t_j (a uniform resistivity).

A file refused before any work names the key: no piezo layer, a piezo layer without d31 or
permittivity (and no material to supply them), a complement layer without a bias, a
coupling d31^2 Y >= eps33^T. A layer driven past its material's recommended field over the
file's voltage range (or against its poling past the coercive field) is warned about, naming
the layer and the field (:class:`~mjeap.model.laminate.FieldWarning`, as ``piezo-bimorph``).
"""
from __future__ import annotations

from typing import Dict, Optional

import numpy as np

from ..errors import ParameterError
from ..model.laminate import FieldWarning, Laminate, laminate_reason, piezo_layers
from .base import register_drive
from .piezo import LinearPiezo

__all__ = ["PiezoLaminateDrive", "FieldWarning"]


_DERIVED = "derived: the clamped capacitance of the piezo layers (mjeap.model.laminate)"


@register_drive
class PiezoLaminateDrive(LinearPiezo):
    name = "piezo"
    actuators = ()
    model_used = "piezo laminate from datasheet constants (free-strain moments about the neutral axis)"
    #: at least one piezo layer; any other layer may take any role (:meth:`stack_reason`)
    ROLES = {"piezo": 1}
    GENERIC_PARAMETERS = {
        "bias": (None, "V", "none: a file with a 'complement' layer sets it"),
        "capacitance": (None, "F", _DERIVED),
        "resistance": (None, "ohm", "none: no leakage current"),
    }

    def __init__(self, scene, **params):
        super().__init__(scene, **params)
        for k, positive in (("bias", False), ("capacitance", True), ("resistance", True)):
            v = self.params.get(k)
            if v is None:
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or not np.isfinite(v) \
                    or (positive and not v > 0):
                raise ParameterError(f"{self.name} parameter {k}", v,
                                     f"a finite number{' > 0' if positive else ''} in {self.parameter_units()[k]}")
        act = scene.actuator
        why = laminate_reason(act, self.params["bias"])
        if why is not None:
            raise ParameterError("drive", self.name, "a laminate the piezo drive can run", why)
        self.lam = Laminate(act, piezo_layers(act), self.params["bias"])
        lay = scene.layout
        coeffs = np.array([self.lam.moment(x) for x in lay.hinge_x])
        gamma, m0 = coeffs[:, 0], coeffs[:, 1]
        uniform, v0 = self._rest(gamma, m0)
        c = self.params["capacitance"]
        self._couple(gamma, v0, None if uniform else m0,
                     capacitance=self.lam.clamped_capacitance() if c is None else float(c))
        # the leakage: R_j = R sum(A/t) / (A_j / t_j), the signal terminal's current sum_j s_j V_j / R_j
        r = self.params["resistance"]
        if r is None:
            self._leak = None
        else:
            g = self.lam.electrode_areas() / np.array([act.layers[p.index].thickness for p in self.lam.piezo])
            self._leak = np.array([p.sign for p in self.lam.piezo]) * g / (float(r) * g.sum())
        self.warn_fields()

    def _rest(self, gamma, m0):
        """(whether the rest voltage -M0_j / Gamma_j is the same at every hinge, that voltage
        at the clamp's hinge (V); the range's low end where no voltage relieves it)."""
        lo, hi = self.voltage_range()
        if gamma[0] == 0:
            return bool(np.all(m0 == 0) and np.all(gamma == 0)), float(lo)
        v0 = -m0[0] / gamma[0]
        uniform = bool(np.allclose(m0, -v0 * gamma, rtol=1e-12, atol=1e-300))
        return uniform, float(v0)

    @classmethod
    def stack_reason(cls, actuator) -> Optional[str]:
        """At least one piezo layer, each with its constants (:func:`laminate_reason`)."""
        own = actuator.drive == cls.name          # a file of this drive: its bias is all there is
        bias = actuator.drive_parameters.get("bias", (None,))[0] if own else None
        return laminate_reason(actuator, bias, need_bias=own)

    def resistive_current(self, v: float) -> float:
        """sum_j s_j V_j / R_j (A): the signal terminal's share of each layer's leakage."""
        if self._leak is None:
            return 0.0
        return float(self._leak @ self.lam.layer_voltages(v)[:, 0])

    def laminate(self) -> Laminate:
        return self.lam

    def capacitances(self) -> Dict[str, object]:
        """Free: sum_j eps0 eps_r A_j / t_j; blocked: the dielectric term of the current (the
        clamped capacitance, or the ``capacitance`` parameter)."""
        given = self.params["capacitance"] is not None
        return {"free": (self.lam.free_capacitance(), "eps0 eps33^T A / t of the piezo layers (the datasheet's, free)"),
                "blocked": (self._capacitance, "the capacitance parameter (the dielectric term of the current)" if given
                            else "(eps33^T - d31 e31) A / t: the clamped permittivity, the dielectric term of the current")}

    def free_deflection(self, v: float) -> float:
        """Quasi-static tip deflection (m) at the tip block's end at drive voltage ``v`` (V),
        from the straight beam (:meth:`mjeap.model.laminate.Laminate.free_deflection`)."""
        return self.lam.free_deflection(v)

    def blocked_force(self, v: float) -> float:
        """Blocked force (N) at the tip block's end at ``v`` (V)."""
        return self.lam.blocked_force(v)

    def reference_curvature(self, t, v, initial_curvature=0.0):
        """Quasi-static curvature at the clamp, M(0, V) / EI(0) (uniform where every layer
        follows the planform)."""
        g, m0 = self.lam.moment(0.0)
        return (g * np.asarray(v, float) + m0) / float(self.scene.actuator.flexural_rigidity_at(0.0)[0])
