"""The RoboBee wing of mjeap.robots.robobee_wing, shortened (the 30-270 Hz sweeps are the
script's): the transmission against closed forms, the stroke's rise to the transmission
resonance and fall after, and the self-sensing estimate within the paper's 10 %."""
import numpy as np
import pytest

import harvard
from mjeap import Scene
from mjeap.model.discretize import Payload
from mjeap.robots import robobee_wing as robobee


def test_quasi_static_stroke_is_t_eff_times_the_free_deflection():
    """100 V on the 100 V bias (full drive: V_sig = V_bias), reached by a smooth ramp over
    10 periods of the loaded mode and held, in vacuum: the stroke angle is T_eff x the
    Harvard model's free deflection (1/4)(1 + 2 l_r) f31 V (t_p + t_cf) L^2 / D with its own
    V = V_bias = 100 V (tests/harvard.py, not the drive's code) within 1 % (the tendon is the
    linearised tip deflection; the wing adds no stiffness; the ramp leaves a ringing below
    1 %)."""
    system = robobee.build(100.0, air=False)
    q = system.model.joint("stroke").qposadr[0]

    def ramp(t, duration=0.1):
        s = np.minimum(np.asarray(t) / duration, 1.0)
        return 50.0 + 50.0 * (3 * s**2 - 2 * s**3)

    system.rollout([ramp], 0.2)
    assert abs(system.data.qpos[q]) == pytest.approx(robobee.T_EFF * harvard.free_deflection("pzt-robobee", 100.0),
                                                     rel=0.01)


def test_transmission_reflects_the_wing_inertia_onto_the_tip():
    """In vacuum, released from a bent shape: the system rings at the first mode of the
    actuator carrying a point mass I_wing T_eff^2 at its tip (the modal analysis of the
    chain, not the tendon equality), within 1 %."""
    system = robobee.build(200.0, air=False)
    q = system.model.joint("stroke").qposadr[0]
    angle = []
    r = system.rollout([None], 0.08, initial_curvatures=2.0, sample_interval=2e-5,
                       on_sample=lambda s: angle.append(s.data.qpos[q]))
    a = np.array(angle) - np.mean(angle[len(angle) // 2:])
    t = r.time[:len(a)]
    up = np.nonzero((a[:-1] < 0) & (a[1:] >= 0))[0]
    tc = t[up] - a[up] * (t[up + 1] - t[up]) / (a[up + 1] - a[up])      # interpolated upward crossings
    f_sim = (len(tc) - 1) / (tc[-1] - tc[0])
    tip_x = system.actuators[0].twin.layout.tip_x
    reflected = Payload.point(robobee.wing_inertia() * robobee.T_EFF**2, tip_x)
    f_ref = Scene("pzt-robobee", gravity=False, payload=reflected).choice.first_frequency
    assert f_sim == pytest.approx(f_ref, rel=0.01)


@pytest.mark.slow
def test_stroke_peaks_between_30_and_270_hz_and_is_self_sensed():
    """The stroke rises to the transmission resonance and falls after it; self-sensed within
    Jayaram et al. 2018's 10 % at 30 and 90 Hz. At 270 Hz the wing's inertia nearly blocks the
    actuator: the motional current is a small part of the total, so the estimate's error
    is the calibrated blocking factor's own error times the dielectric-to-motional current
    ratio there (eq. 7: I_sen = I_mech + (1 - beta) C dV/dt), which the bound adds to the
    paper's 10 %. Measured: -0.15 / +0.79 / +8.4 % at the default step, -0.15 / +0.81 / +8.8 %
    at a quarter of it (beta from the free actuator's sweep, 1.0217 and 1.0217; the ratio
    5.0). With the capacitive current and the estimator's dV/dt half a step (sample) before
    the voltage's instant they were +13 % and +22 % (beta 1.033 and 1.049, and the estimator
    differencing over its 37 us samples against the drive's step): see mjeap.drives.piezo."""
    from mjeap.analysis.frequency import phasor
    system = robobee.build(100.0)
    est = robobee.estimator(100.0)
    rows = {f: robobee.flap(system, 100.0, f, est, trace=f == 270.0) for f in (30.0, 90.0, 270.0)}
    assert rows[90.0]["stroke_deg"] > rows[30.0]["stroke_deg"] > rows[270.0]["stroke_deg"]
    for f, r in rows.items():
        assert r["steady"] < 0.01
        bound = 0.10
        if f == 270.0:
            a = r["trace"][0].actuators["act"]
            late = a.time > a.time[-1] - 4 / f
            ratio = abs(phasor(a.time[late], a.signals["current_capacitive (A)"][late], f)
                        / phasor(a.time[late], a.signals["current_motional (A)"][late], f))
            bound += abs(est.beta - 1) * ratio
            assert ratio > 3          # the ill-conditioned case the bound is for
        assert abs(r["estimated_deg"] / r["stroke_deg"] - 1) < bound, (f, bound)
