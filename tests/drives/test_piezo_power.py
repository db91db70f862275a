"""Electrical power and motional-current phase of the piezo bimorphs across 0.1 .. 2 f_1 at
the default step (trust issue, section 1), against two independent references:

- converged runs of the same model at the default step / 32 (tests/golden/piezo_power.json,
  made by scripts/piezo_power_reference.py; its / 16 companion shows it converged);
- the energy balance per cycle: the electrical work into the motional branch, V_eff I_mech,
  against what the hinges' dampers dissipate, read from MuJoCo's own state.

On eaac59e (I_mech from the rates after the step) the default step's power was 0.61 x the
converged at f_1 / 2 and 1.33-1.54 x at 1.5 f_1; the lag at f_1 / 2 2.32 deg for 3.75.
"""
import json
from pathlib import Path

import mujoco
import numpy as np
import pytest

from mjeap import Scene, rollout
from mjeap.analysis.frequency import driven_power
from mjeap.drives import make_drive

GOLDEN = json.loads((Path(__file__).resolve().parents[1] / "golden" / "piezo_power.json").read_text())
CASES = GOLDEN["cases"]
#: the issue's bounds off resonance (r <= 0.5, r >= 1.5): power 2 %, lag 0.1 deg or 2 % of it
POWER_TOL, LAG_TOL_DEG, LAG_TOL_REL = 0.02, 0.1, 0.02
#: the README's bound in the resonance band (r = 0.9 .. 1.1): the implicit damping's half-step
#: delay adds an inertia h C / 2, which moves f_1 by zeta_1 omega_1 h / 2 (0.25 % at h = beta)
NEAR_POWER_TOL, NEAR_LAG_TOL_DEG = 0.05, 3.0


def _id(c):
    return f"{c['actuator']}-{c['ratio']}f1"


@pytest.fixture(scope="module")
def scenes():
    return {a: Scene(a) for a in {c["actuator"] for c in CASES}}


def test_the_references_are_converged():
    """The reference at step / 32 against step / 16: power within 0.2 %, lag within 0.01 deg
    (first order in the step: the / 32 reference is within half of that again)."""
    for c in CASES:
        assert c["power_w_at_step_over_16"] / c["power_w"] == pytest.approx(1.0, abs=2e-3), _id(c)
        assert c["lag_deg_at_step_over_16"] == pytest.approx(c["lag_deg"], abs=0.01 + 0.002 * abs(c["lag_deg"])), _id(c)


@pytest.mark.parametrize("case", CASES, ids=_id)
def test_power_and_phase_at_the_default_step(scenes, case):
    s = scenes[case["actuator"]]
    assert s.timestep == pytest.approx(case["default_timestep_s"], rel=1e-12)
    got = driven_power(s, case["frequency_hz"], GOLDEN["amplitude_v"], GOLDEN["offset_v"])
    near = 0.8 < case["ratio"] < 1.2
    ptol = NEAR_POWER_TOL if near else POWER_TOL
    ltol = NEAR_LAG_TOL_DEG if near else max(LAG_TOL_DEG, LAG_TOL_REL * abs(case["lag_deg"]))
    assert got["power_w"] / case["power_w"] == pytest.approx(1.0, abs=ptol)
    assert got["lag_deg"] == pytest.approx(case["lag_deg"], abs=ltol)


@pytest.mark.parametrize("actuator", ["pzt-hamr-large", "pzt-hamr-small", "pzt-robobee"])
@pytest.mark.parametrize("ratio", [0.3, 0.5, 1.5, 2.0])
def test_electrical_work_per_cycle_is_what_the_dampers_dissipate(actuator, ratio):
    """Lockstep at the default step, a 20 V sine about 100 V at r f_1 (whole steps per
    period), after 12 / (zeta_1 omega_1): over one period the mean of V_eff I_mech, I_mech as
    the drive reports it, against the mean of sum_j c_j (dtheta_j/dt)^2, MuJoCo's hinge
    dampers acting on its end-of-step rates (implicit damping). 2 %; measured within 1 %
    (the step's own (omega h)^2 / 4 between the two pairings)."""
    s = Scene(actuator)
    drv = make_drive(None, s)
    h = s.timestep
    n = round(1.0 / (ratio * s.choice.first_frequency * h))
    f = 1.0 / (n * h)
    n_settle = n * int(np.ceil(12.0 / (s.choice.damping_ratio * 2 * np.pi * s.choice.first_frequency) * f))
    s.reset()
    drv.reset()
    c = s.part.hinge_damping()                            # N m s / rad
    w_el = diss = 0.0
    for k in range(n_settle + n):
        v = 100.0 + 20.0 * np.sin(2 * np.pi * f * k * h)
        drv.step(v, h)
        mujoco.mj_step(s.model, s.data)
        if k >= n_settle:
            w_el += (v - 100.0) * drv.currents()[2]
            diss += float(c @ s.part.hinge_rates() ** 2)
    assert w_el > 0
    assert w_el / diss == pytest.approx(1.0, abs=0.02)


@pytest.mark.parametrize("engine", ["loop", "threaded", "native"])
def test_capacitive_current_at_the_voltage_instant_and_the_charge_of_a_step(engine):
    """The capacitive current of a sample belongs to its voltage's instant t_k, as I_mech
    does (mjeap.drives.piezo): on a parabolic voltage it is exactly C dV/dt(t_k) (the
    backward difference was the slope at t_k - h/2, 2 b h / 2 less); a 20 V step delivers
    C x 20 V, 3/2 of it in the step's sample and -1/2 in the next, on every engine (the
    threaded and native ones replay the drive)."""
    s = Scene("pzt-robobee")
    h, c = s.timestep, make_drive("piezo-bimorph", s).params["capacitance"]
    r = rollout(s, f"step:20V,delay={10 * h!r}s,offset=100V", 30 * h, sample_interval=h, engine=engine,
                progress=False)
    q = r.signals["current_capacitive (A)"] * h / (c * 20.0)
    assert np.sum(q) == pytest.approx(1.0, rel=1e-12)
    k = int(np.argmax(q))
    np.testing.assert_allclose(q[k - 1:k + 3], [0.0, 1.5, -0.5, 0.0], atol=1e-12)
    b = 2e8                                                   # V/s^2
    r = rollout(s, lambda t: 100.0 + b * t**2, 30 * h, sample_interval=h, engine=engine, progress=False)
    t_k = r.time[3:] - h                                      # the voltage's instant: the step's start
    np.testing.assert_allclose(r.signals["current_capacitive (A)"][3:], c * 2 * b * t_k, rtol=1e-9)


def test_the_capacitive_current_does_no_work_over_a_cycle():
    """A capacitor stores and returns: over a period the mean of V_eff I_C is zero. At the
    voltage's instant (the second-order difference) it is (omega h)^4 / 4 of the reactive
    power, 3e-4 of the motional power at f_1 / 2 on pzt-hamr-small (bound 1e-3); the backward
    difference, half a step early, had a real part omega^2 h / 2 and did 24 % of it (the
    total electrical power 1.24 x the motional and resistive)."""
    s = Scene("pzt-hamr-small")
    n = round(2.0 / (s.choice.first_frequency * s.timestep))
    f = 1.0 / (n * s.timestep)
    p = {c: driven_power(s, f, 20.0, 100.0, current=f"current_{c} (A)")["power_w"] for c in ("capacitive", "motional")}
    assert p["motional"] > 0
    assert abs(p["capacitive"]) < 1e-3 * p["motional"]
