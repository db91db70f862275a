"""HAMR-VI's eight foot phase loops as one system controller (Jayaram et al. 2018, section
6.2: the single leg's phase loop, :mod:`mjeap.controllers.hamr_leg`, on every actuator of the
walker, :mod:`mjeap.robots.hamr_walk`).

Each loop drives V_bias/2 + a sin(omega t + phi) on its actuator and, after the open-loop
cycles, moves phi once per cycle by a PI on its foot's phase error as its own drive current
senses it (eqs. 7-9, calibrated once on the free actuator): the loops read nothing else of
the simulator. The desired phases are the trot's (the walker passes them: its legs' table).
"""
from __future__ import annotations

import copy
from typing import Mapping

from ..errors import check_integer, check_range
from .hamr_leg import LIFT, SWING, LegPhaseController, PhaseControllers, free_actuator, phase_loop_gains
from .self_sensing import calibrate_on_free_actuator

__all__ = ["TRANSMISSIONS", "ESTIMATOR_FREQUENCIES", "walker_estimator", "trot_loop_gains", "TrotPhaseControllers"]

#: each leg's two transmissions (ratio, resonance): swing 13 / 100 Hz, lift 12 / 80 Hz
TRANSMISSIONS = {"swing": SWING, "lift": LIFT}
#: Hz, the free actuator's calibration sweep (as the single leg's free_estimator)
ESTIMATOR_FREQUENCIES = (100.0, 1000.0, 1500.0, 1750.0, 2000.0)


def walker_estimator(system, frequencies=ESTIMATOR_FREQUENCIES):
    """Eqs. 7-9 calibrated once on the free pzt-hamr-small (no leg, no robot) at the
    ``system``'s bias and segments, over ``frequencies`` (Hz); not changed for the legs or
    the ground."""
    a = system.actuators[0]
    return calibrate_on_free_actuator(free_actuator(), a.drive.params["bias"], frequencies, gravity=False,
                                      segments=system.parts[0].layout.segments)


def trot_loop_gains(frequency: float, damping_ratio: float) -> dict:
    """Per degree of freedom the phase loop's (kp, ki, kd) per cycle at the trot
    ``frequency`` (Hz): controllers.hamr_leg.phase_loop_gains on each transmission's
    second-order model (its resonance, ``damping_ratio``)."""
    return {dof: phase_loop_gains(damping_ratio, tr.resonance, frequency) for dof, tr in TRANSMISSIONS.items()}


class TrotPhaseControllers(PhaseControllers):
    """The eight phase loops as one system controller: per actuator prefix of ``phases``
    (prefix -> desired foot phase, rad, against sin(omega t)) a
    :class:`~mjeap.controllers.hamr_leg.LegPhaseController` driving V_bias/2 + ``amplitude``
    sin(omega t + phi) (V), phi starting at the desired phase, the amplitude ramped over
    ``ramp`` s; after ``open_loop_cycles`` phi moves once per cycle by the PI (``gains``:
    'swing' / 'lift' -> (kp, ki, kd)) on the sensed foot phase error. Each loop reads only
    its own actuator's drive current through its own copy of ``estimator``
    (:func:`walker_estimator` if None)."""

    name = "eight foot phase PIs on the self-sensed currents"

    def __init__(self, system, frequency: float, phases: Mapping[str, float], gains: Mapping[str, tuple], *,
                 amplitude: float, open_loop_cycles: int, ramp: float, estimator=None,
                 frequency_range: tuple = (1.0, 100.0)):
        bias = system.actuators[0].drive.params["bias"]
        frequency = check_range("frequency", frequency, *frequency_range, "Hz")
        amplitude = check_range("amplitude", amplitude, 0.0, 0.5 * bias, "V", lo_open=True)
        open_loop_cycles = check_integer("open_loop_cycles", open_loop_cycles, 1, 10_000)
        est = walker_estimator(system) if estimator is None else estimator
        self.frequency, self.open_loop_cycles, self.dt = frequency, open_loop_cycles, system.timestep
        self.ctrls, self.obs = {}, {}
        for prefix, phase in phases.items():
            c = LegPhaseController(copy.deepcopy(est), frequency, amplitude, phase, gains[prefix.split("_")[1]],
                                   open_loop_cycles, initial_phase=phase, ramp=ramp)
            self.obs[prefix] = system.drive_observer(prefix)
            c.reset(system, self.obs[prefix])
            self.ctrls[prefix] = c


