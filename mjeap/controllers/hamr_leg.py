"""HAMR leg phase control from the actuator's own current (Jayaram et al. 2018,
section 6.2), written against mjeap's public API only.

Scene: the HAMR small bimorph (catalog residual tip mass fitted to its measured 1750 Hz) drives one
leg degree of freedom through a transmission of ratio T (swing 13, lift 12): the foot moves
T times the actuator tip. Linearised, a lever with a foot mass m_f reflects T^2 m_f onto the
actuator tip, so the leg is a point mass there, sized so that the loaded first mode sits at
the transmission resonance the paper reports (swing ~100 Hz). Gravity is off: the swing
moves in the horizontal plane. Only the swing is controlled here: the lift (ratio 12,
~80 Hz) driven at 100 Hz sits above its resonance, where the phase response after a
change beats at 20 Hz and the gains below (derived for a drive at resonance) do not apply.

Controller: the drive is V = V_bias/2 + a sin(omega t + phi). Every step the self-sensing
estimator (eqs. 7 and 9) turns the drive current into a tip velocity; a lock-in over each
drive cycle gives its phase, the foot position's is 90 degrees behind. Once per cycle a PID
in velocity form moves phi by the phase error to the desired foot phase. The gains follow
from the plant: after a phase step the response's phasor relaxes with the resonance's
envelope, a = exp(-zeta omega_n / f) per cycle, and the phase is measured one cycle late, so
the loop is g / (z (z - 1)) once the PI zero cancels a; g = 1/4 puts both closed-loop poles
at 1/2 (error roughly halves per cycle, no overshoot).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Dict, List, Optional

import numpy as np

from mjeap.simulation.rollout import rollout
from mjeap.simulation.scene import Scene
from mjeap.model.catalog import get_actuator
from mjeap.model.discretize import Payload
from mjeap.errors import ParameterError, check_positive
from mjeap.analysis.frequency import phasor

from mjeap.controllers.self_sensing import SelfSensingEstimator, calibrate_on_free_actuator
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")

ACTUATOR = "pzt-hamr-small"
MEASURED_RESONANCE = 1750.0     # Hz, Table 1, Type II


@dataclass(frozen=True)
class Transmission:
    """A leg degree of freedom: foot motion = ``ratio`` x actuator tip motion; the loaded
    actuator resonates at ``resonance`` (Hz); the desired foot motion is
    sin(omega t + ``desired_phase``) (rad)."""

    name: str
    ratio: float
    resonance: float
    desired_phase: float


SWING = Transmission("swing", 13.0, 100.0, 0.0)
#: the lift, 90 degrees ahead of the swing: the foot traces the ellipse of Jayaram et al. 2018 (ref. [50])
LIFT = Transmission("lift", 12.0, 80.0, np.pi / 2)


def free_actuator():
    """The HAMR small bimorph of the catalog: its residual tip mass is fitted to the measured
    resonance (MEASURED_RESONANCE, mjeap.analysis.calibration.calibrate_tip_mass)."""
    return get_actuator(ACTUATOR)


def leg_scene(transmission: Transmission, actuator=None, **scene_kw) -> Scene:
    """The actuator carrying the leg's reflected mass at its tip, sized (scipy brentq on the
    scene's own first mode) so that the loaded actuator resonates at the transmission's
    resonance. ``scene_kw`` go to the scenes; a ``timestep`` only to the loaded one (the
    modes, hence the mass, do not depend on it; the free actuator's and the lighter trial
    scenes' stability limits are lower than the loaded scene's)."""
    act = actuator or free_actuator()
    tip = act.length + act.planform.extension_length
    search_kw = {k: v for k, v in scene_kw.items() if k != "timestep"}
    f_free = Scene(act, gravity=False, **search_kw).choice.first_frequency
    if transmission.resonance >= f_free:
        raise ParameterError("transmission.resonance", transmission.resonance,
                             f"a frequency below the free actuator's {f_free:.4g} Hz")

    def scene(mass, kw=search_kw):
        return Scene(act, gravity=False, payload=Payload(mass, tip, radius=1e-5), **kw)

    # one-mode guess, f^2 ~ k / (m + m_eff), with an effective beam mass of 1 mg; the
    # bracket spans four decades around it
    guess = 1e-6 * (f_free / transmission.resonance) ** 2
    mass = optimize.brentq(lambda m: scene(m).choice.first_frequency - transmission.resonance,
                           guess * 1e-2, guess * 1e4, xtol=1e-12, rtol=1e-6)
    return scene(mass, scene_kw)


def pid_gains(damping_ratio: float, resonance: float, frequency: float, pole: float = 0.5):
    """(kp, ki, kd) per cycle of the phase loop, from the plant (see the module text)."""
    a = np.exp(-damping_ratio * 2 * np.pi * resonance / frequency)
    g = pole**2                       # z^2 - z + g = (z - pole)^2 with pole = 1/2
    k = g / (1 - a)
    return a * k, (1 - a) * k, 0.0


def phase_loop_characteristic(kp: float, ki: float, damping_ratio: float, resonance: float,
                              frequency: float) -> np.ndarray:
    """Closed-loop characteristic polynomial (in z, per drive cycle) of the phase loop on a
    second-order transmission driven at ``frequency`` off its ``resonance``: after a drive
    phase step Delta the response phasor relaxes as c^k, c = exp((-zeta w_n + i (w_n - w)) / f),
    so the foot phase follows 1 - Re(c^k) (small Delta): G(z) = 1 - (z - 1)(z - Re c) /
    ((z - c)(z - c*)); measured one cycle late, under the velocity-form PI
    C(z) = ((kp + ki) z - kp) / (z - 1). At resonance c is real and G = (1 - a) / (z - a)."""
    c = np.exp((-damping_ratio * 2 * np.pi * resonance + 1j * 2 * np.pi * (resonance - frequency)) / frequency)
    den = np.real(np.poly([c, np.conj(c)]))
    num = np.polysub(den, np.polymul([1.0, -1.0], [1.0, -c.real]))
    return np.polyadd(np.polymul([1.0, -1.0, 0.0], den), np.polymul([kp + ki, -kp], num))


def phase_loop_gains(damping_ratio: float, resonance: float, frequency: float):
    """(kp, ki, kd) that minimise the closed loop's spectral radius
    (:func:`phase_loop_characteristic`, scipy Nelder-Mead from :func:`pid_gains`); the
    latter where it is already optimal (at resonance, where its zero cancels the plant's
    pole and the others sit at 1/2). Off resonance the transient beats at |f_n - f| and the
    at-resonance gains can be unstable (the lift at 80 Hz driven at 100 Hz)."""
    def radius(g):
        return float(np.max(np.abs(np.roots(phase_loop_characteristic(g[0], g[1], damping_ratio, resonance,
                                                                      frequency)))))

    g0 = pid_gains(damping_ratio, resonance, frequency)
    res = optimize.minimize(radius, g0[:2], method="Nelder-Mead", options={"xatol": 1e-6, "fatol": 1e-9})
    if radius(g0[:2]) <= res.fun + 1e-6:
        return g0
    return float(res.x[0]), float(res.x[1]), 0.0


class PhaseControllers:
    """Several :class:`LegPhaseController` as one system controller (``ctrls``: actuator
    prefix -> controller, ``obs``: prefix -> its drive observer, ``dt``: the system's step,
    set by a subclass): each reads only its actuator's drive current (the observer stepped
    with the voltage it holds) and its own commands, nothing else of the system."""

    ctrls: dict
    obs: dict
    dt: float

    def __call__(self, t: float, system) -> dict:
        out = {}
        for nm, c in self.ctrls.items():
            out[nm] = c(t, None)               # reads the current after the last step, nothing of the system
            self.obs[nm].step(out[nm], self.dt)
        return out


class LegPhaseController:
    """Drives V = V_bias/2 + ``amplitude`` sin(2 pi ``frequency`` t + phi) (V) and, after
    ``open_loop_cycles`` cycles, moves phi once per cycle by a PID on the self-sensed phase
    error. Reads only the drive's current (``drive.signals()``) and its own commands.
    ``initial_phase``: phi before the loop closes (rad); ``ramp``: the amplitude grows
    linearly from zero over this many s (0: none), as the walker's soft start."""

    name = "leg phase PID (self-sensed)"

    def __init__(self, estimator: SelfSensingEstimator, frequency: float, amplitude: float,
                 desired_phase: float = 0.0, gains=(0.7, 0.25, 0.0), open_loop_cycles: int = 10,
                 initial_phase: float = 0.0, ramp: float = 0.0):
        self.est = estimator
        self.frequency = check_positive("frequency", frequency, "Hz")
        self.amplitude = check_positive("amplitude", amplitude, "V")
        self.desired_phase, self.gains, self.open_loop_cycles = desired_phase, gains, int(open_loop_cycles)
        self.initial_phase = float(initial_phase)
        self.ramp = 0.0 if ramp == 0 else check_positive("ramp", ramp, "s")

    def reset(self, scene, drive) -> None:
        self.drive, self.dt = drive, scene.timestep
        self.interval = scene.timestep            # the drive is a sine: updated every step
        self.est.reset()
        self.est.bias = drive.params["bias"]
        self.phi = self.initial_phase
        self._u: Optional[float] = None
        self._cycle, self._sum, self._n = 0, 0j, 0
        self._e = [0.0, 0.0]                      # the last two phase errors (rad)
        self.errors: List[float] = []             # sensed foot phase error per cycle (rad)
        self.commands: List[float] = []           # phi per cycle (rad)

    def _end_of_cycle(self) -> None:
        v = 2 * self._sum / max(self._n, 1)                    # velocity phasor (lock-in)
        x_phase = np.angle(v) - np.pi / 2                      # position: 90 deg behind
        e = float(np.angle(np.exp(1j * (self.desired_phase - np.pi / 2 - x_phase))))
        self.errors.append(e)
        if self._cycle >= self.open_loop_cycles:
            kp, ki, kd = self.gains
            e1, e2 = self._e
            self.phi += kp * (e - e1) + ki * e + kd * (e - 2 * e1 + e2)
        self._e = [e, self._e[0]]
        self.commands.append(self.phi)
        self._sum, self._n = 0j, 0
        self._cycle += 1

    def __call__(self, t: float, scene) -> float:
        w = 2 * np.pi * self.frequency
        if self._u is not None:
            # the current read after the last step, with the voltage held over it: both belong
            # to that voltage's instant, the step's start t - dt (mjeap.drives.piezo), not to
            # t (at the leg's 159 us step, omega dt = 5.7 deg at 100 Hz)
            v_sen = self.est.update(self._u, self.drive.signals()["current (A)"], self.dt)
            self._sum += v_sen * np.exp(-1j * w * (t - self.dt))
            self._n += 1
        if t >= (self._cycle + 1) / self.frequency - 0.5 * self.dt:
            self._end_of_cycle()
        a = self.amplitude if t >= self.ramp else self.amplitude * t / self.ramp
        self._u = self.est.bias / 2 + a * np.sin(w * t + self.phi)
        return self._u

    def signals(self) -> Dict[str, float]:
        return {"drive_phase (deg)": float(np.degrees(self.phi)),
                "sensed_phase_error (deg)": float(np.degrees(self.errors[-1])) if self.errors else 0.0}


@dataclass
class LegRun:
    """One leg degree of freedom under the phase controller: the rollout, and per cycle the
    sensed and the true foot phase error (degrees; true: from the simulated tip)."""

    transmission: Transmission
    result: object
    sensed_error_deg: np.ndarray
    true_error_deg: np.ndarray
    open_loop_cycles: int
    meta: dict = field(default_factory=dict)

    @property
    def foot(self) -> np.ndarray:
        """Foot position (m): ratio x the actuator tip deflection."""
        return self.transmission.ratio * self.result.tip_position[:, 1]

    def cycles_to_within(self, tol_deg: float = 5.0, which: str = "true") -> Optional[int]:
        """Closed-loop cycles until the phase error stays within ``tol_deg``."""
        return cycles_to_within(self.true_error_deg if which == "true" else self.sensed_error_deg,
                                self.open_loop_cycles, tol_deg)


def free_estimator(bias: float) -> SelfSensingEstimator:
    """Eqs. 7-9 calibrated on the free HAMR actuator (:func:`calibrate_on_free_actuator`)
    around its 1750 Hz resonance; the leg does not change it."""
    return calibrate_on_free_actuator(free_actuator(), bias, (100.0, 1000.0, 1500.0, 1750.0, 2000.0), gravity=False)


def cycles_to_within(errors_deg, open_loop_cycles: int, tol_deg: float = 5.0) -> Optional[int]:
    """Closed-loop cycles (after ``open_loop_cycles``) until the per-cycle phase error
    ``errors_deg`` stays within ``tol_deg``; None if it never does."""
    e = np.abs(np.asarray(errors_deg))[open_loop_cycles:]
    bad = np.nonzero(e > tol_deg)[0]
    n = 0 if bad.size == 0 else int(bad[-1]) + 1
    return None if n >= e.size else n


def phase_errors_per_cycle(time, position, frequency: float, desired_phase: float, cycles: int) -> np.ndarray:
    """Per drive cycle, the position's phase error (deg) to the desired sin(omega t +
    ``desired_phase``): a lock-in (:func:`mjeap.analysis.frequency.phasor`) over each cycle's samples."""
    time, position = np.asarray(time), np.asarray(position)
    out = []
    for n in range(cycles):
        sel = (time >= n / frequency) & (time < (n + 1) / frequency)
        z = phasor(time[sel], position[sel], frequency)
        out.append(np.angle(np.exp(1j * (desired_phase - np.pi / 2 - np.angle(z)))))
    return np.degrees(out)


def run_leg(transmission: Transmission = SWING, *, cycles: int = 40, open_loop_cycles: int = 10,
            bias: float = 100.0, amplitude: float = 20.0, frequency: float = 100.0,
            estimator: Optional[SelfSensingEstimator] = None, gains=None, rrd=None,
            timestep: Optional[float] = None) -> LegRun:
    """Run one leg DOF at ``frequency`` (Hz): ``open_loop_cycles`` open loop, then closed.
    The estimator is calibrated on the free actuator unless given (as in the paper, it is
    not changed for the load); the gains follow from the scene unless given. ``timestep``
    (s): the leg scene's (default its own, :class:`mjeap.Scene`)."""
    act = free_actuator()
    estimator = estimator or free_estimator(bias)
    sc = leg_scene(transmission, act, **({} if timestep is None else {"timestep": timestep}))
    if gains is None:
        gains = pid_gains(sc.choice.damping_ratio, sc.choice.first_frequency, frequency)
    ctrl = LegPhaseController(estimator, frequency, amplitude, transmission.desired_phase, gains, open_loop_cycles)
    r = rollout(sc, None, cycles / frequency, drive_params={"bias": bias}, controller=ctrl,
                sample_interval=sc.timestep, progress=False)
    # true foot phase per cycle, from the simulated tip deflection (lock-in of each cycle)
    true = phase_errors_per_cycle(r.time, r.tip_position[:, 1], frequency, transmission.desired_phase,
                                  len(ctrl.errors))
    run = LegRun(transmission, r, np.degrees(ctrl.errors), true, open_loop_cycles,
                 {"gains_kp_ki_kd": list(gains), "leg_mass_reflected_kg": sc.payload.mass,
                   "foot_mass_kg": sc.payload.mass / transmission.ratio**2,
                   "resonance_hz": sc.choice.first_frequency, "estimator": estimator.fit,
                   "bias_V": bias, "amplitude_V": amplitude, "frequency_hz": frequency})
    if rrd is not None:
        write_leg_recording(rrd, run, sc)
    return run


def write_leg_recording(path, run: LegRun, scene) -> None:
    """The rollout's recording plus the leg: foot position (simulated and desired), the
    per-cycle phase error (sensed and true), and the foot path over one cycle before the
    loop closes and at the end, drawn as (desired, simulated) foot position in mm: a
    circle-like loop for a 90 degree lag, the diagonal when in phase."""
    import rerun as rr
    import rerun.blueprint as rrb
    from mjeap.io.recording import write_recording

    r, f = run.result, run.meta["frequency_hz"]
    tr = run.transmission
    desired = np.abs(run.foot).max() * np.sin(2 * np.pi * f * r.time + tr.desired_phase)
    t_cycle = (np.arange(len(run.true_error_deg)) + 1) / f

    def extra(rec):
        for ent, y, label in ((f"leg/foot/{tr.name}/simulated", run.foot, "simulated foot (m)"),
                              (f"leg/foot/{tr.name}/desired", desired, "desired foot (m)")):
            rec.log(ent, rr.SeriesLines(names=label), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=r.time)],
                             columns=rr.Scalars.columns(scalars=y))
        for ent, y in (("leg/phase_error/true", run.true_error_deg), ("leg/phase_error/sensed", run.sensed_error_deg)):
            rec.log(ent, rr.SeriesPoints(names=ent.rsplit("/", 1)[1] + " (deg)"), static=True)
            rec.send_columns(ent, indexes=[rr.TimeColumn("time", duration=t_cycle)],
                             columns=rr.Scalars.columns(scalars=y))
        for name, n, colour in (("open_loop", run.open_loop_cycles - 1, [150, 150, 150]),
                                ("closed_loop", len(t_cycle) - 1, [40, 170, 60])):
            sel = (r.time >= n / f) & (r.time <= (n + 1) / f)
            path2d = np.column_stack([desired[sel], run.foot[sel]]) * 1e3
            rec.log(f"leg/foot_path/{name}", rr.LineStrips2D([path2d], colors=[colour], labels=[name]), static=True)

    views = (rrb.TimeSeriesView(origin="/leg/phase_error", name="foot phase error per cycle (deg)"),
             rrb.TimeSeriesView(origin="/leg/foot", name="foot position (m)"),
             rrb.Spatial2DView(origin="/leg/foot_path", name="foot path: desired (x) vs simulated (y), mm"))
    write_recording(path, r, scene, extra=extra, views=views)
