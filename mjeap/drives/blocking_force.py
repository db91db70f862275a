"""Blocking-force drive for the PPy trilayer (Mutlu, Alici, Li 2013).

The measured blocking force F_B(t, V) becomes a uniform internal moment
M = (2/3) F_B L at every joint (the moment whose free beam, held at the tip, pushes with
F_B = 3 M / (2 L)). F_B follows a first-order response to the voltage,
F_B / V = F_1 / (tau s + 1), stepped exactly. Joint stiffness (and with it damping) may
depend on the voltage through a table of (volts, factor) pairs, as the paper identifies
stiffness and damping per voltage (its Fig. 3).
"""
from __future__ import annotations

from typing import Dict, Sequence, Tuple

import numpy as np

from ..errors import ParameterError
from ..lazy import lazy_module
from ..model import lti
from .base import Drive, NativeForm, OpenLoop, ExactLTI, register_drive

#: imported at its first use (mjeap.lazy)
signal = lazy_module("scipy.signal")

_EST = "estimate (Mutlu et al. 2013 gives no extractable number; actuator reference: a few tenths of a mN to ~1 mN at 1 V)"


class VoltageTable:
    """Piecewise-linear factor of |V| from (volts, factor) pairs; 1 when empty."""

    def __init__(self, pairs: Sequence[Tuple[float, float]] = (), name: str = "table"):
        pairs = sorted((float(v), float(f)) for v, f in pairs)
        if any(f <= 0 for _, f in pairs):
            raise ParameterError(name, pairs, "positive factors")
        self.v = np.array([p[0] for p in pairs])
        self.f = np.array([p[1] for p in pairs])

    def __call__(self, voltage: float) -> float:
        if self.v.size == 0:
            return 1.0
        return float(np.interp(abs(voltage), self.v, self.f))


@register_drive
class BlockingForceDrive(OpenLoop, NativeForm, Drive):
    name = "blocking-force"
    actuators = ("ppy-trilayer",)
    model_used = "uniform moment (2/3) F_B L from a first-order blocking force"
    #: the ppy-trilayer's values (also in its actuator file), the defaults for any actuator
    GENERIC_PARAMETERS = {
        "blocking_force_per_volt": (0.5e-3, "N/V", _EST),
        "time_constant": (2.0, "s", "estimate (PPy trilayers of this size settle in seconds; not extractable from Mutlu et al. 2013)"),
    }
    RANGES = {"time_constant": (0.0, np.inf)}

    def extra_parameters(self):
        return ("stiffness_table",)

    def __init__(self, scene, **params):
        super().__init__(scene, **params)
        self.stiffness = VoltageTable(self.params.get("stiffness_table", ()), "stiffness_table")
        tau = float(self.params["time_constant"])
        F1 = float(self.params["blocking_force_per_volt"])
        self.force = ExactLTI([[-1 / tau]], [F1 / tau], [[1.0]], [0.0], scene.timestep)
        self.L = scene.layout.length

    def reset(self, initial_curvature: float = 0.0) -> None:
        self.force.x[:] = 0.0
        self.part.set_bending_stiffness_scale(1.0)
        self._moment = 0.0
        self.part.set_internal_moments(0.0)

    def step(self, voltage: float, dt: float) -> None:
        self.part.set_bending_stiffness_scale(self.stiffness(voltage))
        self._moment = 2.0 / 3.0 * float(self.force.x[0, 0]) * self.L
        self.part.set_internal_moments(self._moment)
        self.force.advance(voltage)

    def closed_loop_reason(self):
        return "its stiffness table changes the beam's stiffness with the voltage" if self.stiffness.v.size else None

    # -- native form: a first-order (filterexact) actuator on the bending tendon --------
    def native_reason(self):
        return self.closed_loop_reason()

    def add_native(self, spec, joints, parent):
        """M = (2/3) L F_1 a with the activation a the voltage low-passed over tau."""
        from . import native
        u = self.scene.units
        F1, tau = float(self.params["blocking_force_per_volt"]), float(self.params["time_constant"])
        native.add_bending_tendon(spec, joints, np.ones(len(joints)))
        native.add_drive_actuator(spec, 2.0 / 3.0 * self.L * F1 / u.moment, self.voltage_range(),
                                  time_constant=tau / u.time)
        return native.NativeHandles()

    def _moment_history(self, v):
        """The first-order force by scipy.signal.lfilter of the same exact (ZOH) recursion
        x[k+1] = a x[k] + b v[k] the loop steps; the moment over step k uses x[k]."""
        a, b = float(self.force.Ad[0, 0]), float(self.force.Bd[0])
        self._force_history = signal.lfilter([0.0, b], [1.0, -a], v)     # x[0] .. x[n-1]
        m = 2.0 / 3.0 * self.L * self._force_history
        return np.repeat(m[:, None], self.scene.layout.segments, axis=1)

    def _restore_before(self, k: int) -> None:
        self.force.x[:] = self._force_history[k]

    def signals(self) -> Dict[str, float]:
        return {"blocking_force (N)": float(self.force.x[0, 0]), "drive_moment (N m)": float(self._moment),
                "stiffness_factor (-)": float(self.part.stiffness_scale)}

    def small_signal(self, operating_voltage: float):
        """Linear (without a stiffness table): the blocking force's state F_B' = (F_1 V -
        F_B) / tau, the moment (2/3) L F_B on every hinge. Its model draws no current."""
        from .small_signal import SmallSignal
        v0 = self._operating_voltage(operating_voltage)
        if self.stiffness.v.size:
            raise ParameterError("drive_params", "stiffness_table", "a blocking-force drive without a stiffness table "
                                 "for a small-signal model", "the table makes the beam's stiffness a function of the "
                                 "voltage; run sine sweeps instead (mjeap.analysis.frequency.sine_sweep)")
        tau, F1, n = float(self.params["time_constant"]), float(self.params["blocking_force_per_volt"]), \
            self.scene.layout.segments
        return SmallSignal(v0, "V", np.zeros(n), state_matrix=[[-1.0 / tau]], state_input=[F1 / tau],
                           moment_from_state=np.full((n, 1), 2.0 / 3.0 * self.L), current=False,
                           no_current="the blocking-force drive (Mutlu 2013) models no current: its moment follows "
                                      "a first-order force, with no charge or motional coupling in the model")

    def reference_curvature(self, t, v, initial_curvature=0.0):
        """Quasi-static: uniform curvature (2/3) F_B L / (f(V) EI), F_B the same first-order
        response (:func:`mjeap.model.lti.lsim`; beam inertia and damping neglected)."""
        tau, F1 = self.params["time_constant"], self.params["blocking_force_per_volt"]
        FB = lti.lsim(signal.TransferFunction([F1], [tau, 1.0]), v, t)
        EI = float(self.scene.actuator.flexural_rigidity_at(0.0)[0])
        f = np.array([self.stiffness(x) for x in v])
        return 2.0 / 3.0 * FB * self.L / (f * EI)
