"""The piezo bimorph's moment per volt against its sources, and energy balances over a cycle.

References, none of them the drive's own formula:
- Jayaram et al. 2018 eq. (13), I_mech = 2 A f31 d(eps_1)/dt, with the plate's bending strain taken from
  the simulated tip (the arc through clamp and tip, as the paper's vibrometer sees the tip);
- Harvard's HAMR actuator model (PZTBender2.m, Jafferis et al. 2015) with its own variables:
  the plates' voltage difference V = V_bias at full drive, D from its layer formula;
- energy: the electrical work into the motional branch against what MuJoCo's own state says
  was dissipated by its dampers and stored in its springs and bodies (mjENBL_ENERGY).
"""
import mujoco
import numpy as np
import pytest

from mjeap import Scene, analytical as an, rollout
from mjeap.drives import make_drive

from harvard import F31, stack as _stack

PZT = ["pzt-hamr-large", "pzt-hamr-small", "pzt-robobee"]


def test_motional_current_follows_seed_003_eq_13():
    """A free pzt-hamr-small driven at 100 Hz (far below its 1750 Hz mode, so the curvature is
    uniform): the drive's motional current against eq. (13), 2 A f31 d(eps_1)/dt, with A the
    trapezoid's electrode area and eps_1 = kappa (t_p + t_cf)/2 at a plate's mid-plane, kappa
    the simulated tip's arc curvature. 2 % (the issue's bound; 0.3 % is the dynamic
    amplification (f/f_1)^2). The moment of 8290cc9 gave 0.505."""
    s = Scene("pzt-hamr-small")
    drv = make_drive(None, s)
    r = rollout(s, "sine:50V@100Hz,offset=100V", 0.03, drive=drv, progress=False, sample_interval=s.timestep)
    p = s.actuator.planform
    t_p, t_cf, _, _ = _stack(s.actuator)
    area = 0.5 * (p.base_width + p.tip_width) * p.length
    strain_rate = np.gradient(r.tip_curvature, r.time) * (t_p + t_cf) / 2
    i13 = an.bimorph_motional_current(F31, area, strain_rate)
    late = r.time > 0.01
    ratio = np.ptp(r.signals["current_motional (A)"][late]) / np.ptp(i13[late])
    assert ratio == pytest.approx(1.0, abs=0.02)


@pytest.mark.parametrize("actuator", PZT)
def test_full_drive_free_deflection_and_blocked_force_match_harvards_model(actuator):
    """V_sig = V_bias = 200 V (full drive, the closed form's V = 200 V): free deflection at the
    tip block's end against (1/4)(1 + 2 l_r) f31 V (t_p + t_cf) L^2 / D with D from the layer
    formula, and the blocked force (superposition: the tip force that cancels the free
    deflection) against (3/4)(w_n/L) f31 (t_p + t_cf) V G_F with the published G_F, w_n the
    mean width. 2 %; measured within 0.03 % (8290cc9: -50 %)."""
    s = Scene(actuator)
    act, p = s.actuator, s.actuator.planform
    t_p, t_cf, E_p, E_cf = _stack(act)
    D = an.bimorph_stiffness_per_width(E_p, t_p, E_cf, t_cf)
    wn, lr = 0.5 * (p.base_width + p.tip_width), p.extension_length / p.length
    rollout(s, "step:200V", 20 / s.choice.first_frequency, drive_params={"bias": 200.0}, progress=False)
    s.settle(tol=1e-10)
    free = float(s.tip_position()[1])
    assert free == pytest.approx(an.bimorph_free_deflection(F31, 200.0, t_p, t_cf, p.length, lr, D), rel=0.02)
    s2 = Scene(actuator)
    s2.set_tip_force(1e-3)
    s2.settle(tol=1e-10)
    blocked = 1e-3 * free / float(s2.tip_position()[1])
    assert blocked == pytest.approx(an.bimorph_blocked_force(F31, 200.0, t_p, t_cf, p.length, wn, p.base_width / wn, lr),
                                    rel=0.02)


def test_geometry_factor_closed_form_against_the_tip_compliance_integral():
    """The published G_F (a closed form in w_r, l_r) against its definition by a different
    method: the ratio of the free deflection of a uniform moment to the tip compliance of the
    trapezoid with a rigid extension, int (L (1 + l_r) - x)^2 / w(x) dx by quadrature."""
    from scipy.integrate import quad
    L, wn = 1.0, 1.0
    for wr in (0.6, 1.0, 1.5, 1.7):
        for lr in (0.0, 0.1, 0.25):
            w = lambda x: wn * (wr + (2 - 2 * wr) * x / L)          # base wr wn, tip (2 - wr) wn
            compliance = quad(lambda x: (L * (1 + lr) - x) ** 2 / w(x), 0, L)[0]    # x 12/(E t^3)
            # F_b = delta_f / compliance with delta_f = kappa L^2 (1 + 2 l_r) / 2 and M = kappa EI w
            # per width: the factor of (3/4)(w_n/L) f31 (t_p + t_cf) V in units of M/(w kappa)
            gf = (L**2 * (1 + 2 * lr) / 2) / compliance / (1.5 * wn / L)
            assert an.bimorph_geometry_factor(wr, lr) == pytest.approx(gf, rel=5e-4 if wr == 1.0 else 1e-9)


def _cycle_energy(model, data, set_input, electrical_power, settle_steps, cycle_steps):
    """Over ``cycle_steps`` steps after ``settle_steps``: (electrical work in, dissipated by
    MuJoCo's dampers, change of MuJoCo's kinetic + potential energy), internal units. The
    damping force under implicitfast acts with the end-of-step velocity, so dissipation is
    h v+ D v+; electrical power is sampled at the step's start (the sensors' time)."""
    model.opt.enableflags |= mujoco.mjtEnableBit.mjENBL_ENERGY
    h = model.opt.timestep
    w_el = diss = 0.0
    e0 = None
    for k in range(settle_steps + cycle_steps):
        set_input(k)
        mujoco.mj_forward(model, data)
        if k == settle_steps:
            e0 = float(data.energy.sum())
        if k >= settle_steps:
            w_el += h * electrical_power(k)
        mujoco.mj_step(model, data)
        if k >= settle_steps:
            diss += h * float(np.sum(model.dof_damping * data.qvel**2))
    mujoco.mj_forward(model, data)
    return w_el, diss, float(data.energy.sum()) - e0


@pytest.mark.parametrize("f_ratio, steps_per_period", [(1.0, None), pytest.param(0.5, 10000, marks=pytest.mark.slow)])
def test_piezo_energy_balance_over_a_cycle(f_ratio, steps_per_period):
    """Native pzt-hamr-small (the default engine), sine drive: the electrical work into the
    motional branch over one period, (V_sig - V_bias/2) I_mech summed over both sources (each
    plate's V_plate I_plate), with I_mech the drive's current from the tendon-rate sensor,
    equals the energy MuJoCo's hinge dampers dissipate plus the change of its kinetic and
    spring energy: 1 %. What this checks is the energy bookkeeping between the electrical
    port and MuJoCo's mechanics (a current coefficient other than the moment per volt MuJoCo
    applies would break the balance by their ratio); the size of that coefficient is checked
    against the sources by the eq. (13) and Harvard tests above, not here.

    The step map's own energy error (explicit springs, implicit dampers) is about
    (h omega_1 / 4 zeta_1)(1 - (f/f_1)^2) of the dissipation: nothing at resonance, so f_1 runs
    at the scene's timestep (measured 0.25 %); at f_1/2 it is 19 % at 200 steps a period and
    2.4 % at 2000 (measured), so that case runs 10000 steps a period (0.5 % expected)."""
    f1 = Scene("pzt-hamr-small").choice.first_frequency
    f = f_ratio * f1
    s = Scene("pzt-hamr-small", timestep=None if steps_per_period is None else float(f"{1 / (steps_per_period * f):.3g}"))
    drv = make_drive(None, s)
    nat = s.native_model(drv)
    nat.reset()
    u = s.units
    m, d = nat.model, nat.data
    h = m.opt.timestep * u.time
    n_per = int(round(1 / (f * h)))
    bias = drv.params["bias"]
    v = lambda k: bias / 2 + 50.0 * np.sin(2 * np.pi * f * k * h)
    sensor = m.sensor_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SENSOR, "bend_rate")]
    g0 = float(m.numeric_data[m.numeric_adr[mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, "mjeap_coupling")]])

    def set_input(k):
        d.ctrl[nat.actuator_id] = v(k)

    def power(k):                                    # W -> internal energy / internal time
        i_mech = g0 * d.sensordata[sensor] / u.time
        return (v(k) - bias / 2) * i_mech * u.time / u.moment

    w_el, diss, de = _cycle_energy(m, d, set_input, power, (40 if f_ratio == 1.0 else 10) * n_per, n_per)
    assert w_el > 0
    assert (diss + de) / w_el == pytest.approx(1.0, abs=0.01)


@pytest.mark.slow
def test_seed_000_energy_balances_over_a_cycle():
    """Dadras et al. 2021's model is one-way (eq. 8: the double layer does not see the beam's motion), so
    its energy closes on each side. Native pedot-micro, 1.5 V sine at 0.5 Hz, one period after
    two. Electrical: the work V I = the resistor's R I^2 plus the change of the double layer's
    (1/2) C v_c^2, with R = 1/(C p_elec). Mechanical: the drive actuator's work = what the hinge
    and Maxwell-arm dampers dissipate plus the change of kinetic, spring (hinges, Maxwell
    tendons) and gravity energy, all from MuJoCo's state. 1 % each."""
    s = Scene("pedot-micro")
    drv = make_drive(None, s)
    nat = s.native_model(drv)
    nat.reset()
    u = s.units
    m, d = nat.model, nat.data
    h = m.opt.timestep * u.time
    f = 0.5
    n_per = int(round(1 / (f * h)))
    v = lambda k: 1.5 * np.sin(2 * np.pi * f * k * h)
    a = nat.actuator_id
    C, pe = drv.params["capacitance"], drv.params["pole_electrical"]
    el = {"vi": 0.0, "ri2": 0.0, "vc0": None}

    def set_input(k):
        d.ctrl[a] = v(k)

    def power(k):                                    # the actuator's mechanical power, internal
        vc = float(d.act[m.actuator_actadr[a]])
        i = C * pe * (v(k) - vc)                      # the RC branch's current, A
        if el["vc0"] is None:
            el["vc0"] = vc
        el["vi"] += h * v(k) * i
        el["ri2"] += h * i * i / (C * pe)
        return float(d.actuator_force[a] * d.actuator_velocity[a])

    w_mech, diss, de = _cycle_energy(m, d, set_input, power, 2 * n_per, n_per)
    vc1 = float(d.act[m.actuator_actadr[a]])
    assert (diss + de) / w_mech == pytest.approx(1.0, abs=0.01)
    stored = 0.5 * C * (vc1**2 - el["vc0"] ** 2)
    assert (el["ri2"] + stored) / el["vi"] == pytest.approx(1.0, abs=0.01)
