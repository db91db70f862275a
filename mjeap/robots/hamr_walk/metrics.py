"""The HAMR-VI walk's read-outs (:mod:`mjeap.robots.hamr_walk`): a walk's metrics over its
measuring window (:func:`walk_metrics`), its contact forces against momentum
(:func:`force_balance`) and whether it stayed upright (:func:`upright`).

Read-outs (SI): forward speed (the body's displacement along the ground's x over the
measuring window, divided by its duration); roll and pitch relative to the ground; stance: a
foot within STANCE_GAP = 10 um of the ground; foot slip: the share of stance samples whose
tangential foot speed exceeds SLIDE_FRACTION = 10 % of the mean stance speed relative to the
body; the no-slip kinematic estimate (the stance feet's backward speed relative to the
body); the duty factor and touch-downs per foot and cycle, read from the clearance and from
the ground's normal force (at the sample's instant, and over each sample interval from every
step's contact sensors); penetration and the chassis's and legs' lowest points.
"""
from __future__ import annotations

import numpy as np

from .model import CONTACT_WIDTH_FRACTION, FOOT_RADIUS, roll_pitch

__all__ = ["STANCE_GAP", "UPRIGHT_DEG", "SLIDE_FRACTION", "force_balance", "walk_metrics", "upright"]

STANCE_GAP = 10e-6              # m, a foot this close to the ground is in stance (2 % of its radius)
UPRIGHT_DEG = 30.0              # deg: a body within this roll and pitch is upright
SLIDE_FRACTION = 0.1            # a contact foot slides above this fraction of its stance speed


def force_balance(run: dict) -> dict:
    """Momentum along the ground's normal over a :func:`walk`'s measuring window: the mean of
    the ground's contact force on the robot (N, from the impulses of every step,
    ``ground_force_mean``) against what Newton's second law requires of it, the weight's
    normal share plus the change of the robot's normal momentum over the window divided by
    its duration; their ratio - 1. Beside it the mean of the forces at the samples alone
    (``sampled_force_balance_error``: a landing's force lasts a few steps, so the samples
    miss or catch it)."""
    t, up = run["time"], run["ground"][:, 2]
    k0 = int(np.argmax(t >= run["t0"] - 1e-12))
    T = t[-1] - t[k0]
    steps = np.asarray(run["interval_steps"][k0 + 1:], dtype=float)
    mean = float((run["ground_force_mean"][k0 + 1:] @ up) @ steps / steps.sum())
    fz = run["ground_force"][k0:] @ up
    sampled = float(np.sum(0.5 * (fz[1:] + fz[:-1]) * np.diff(t[k0:])) / T)
    p = run["momentum"][k0:] @ up
    need = float(run["weight_n"] * up[2] + (p[-1] - p[0]) / T)
    return {"mean_normal_force_n": mean, "momentum_normal_force_n": need, "weight_n": run["weight_n"],
            "force_balance_error": mean / need - 1.0, "sampled_force_balance_error": sampled / need - 1.0}


def walk_metrics(run: dict) -> dict:
    """The read-outs of a :func:`walk` over its measuring window (see the module text), with
    ``upright`` (:func:`upright`)."""
    t, f, G = run["time"], run["frequency"], run["ground"]
    k = t >= run["t0"] - 1e-12
    tw = t[k]
    fwd, up = G[:, 0], G[:, 2]
    p = run["body"][k]
    duration = tw[-1] - tw[0]
    speed = float((p[-1] - p[0]) @ fwd / duration)
    lateral = float((p[-1] - p[0]) @ G[:, 1] / duration)
    rp = np.degrees(np.array([roll_pitch(R, G) for R in run["R"][k]]))
    # the feet in the body frame: their fore-aft speed relative to the body
    rel = np.einsum("nji,nkj->nki", run["R"], run["feet"] - run["body"][:, None, :])     # R^T (foot - body)
    v_rel = np.gradient(rel[..., 0], t, axis=0)[k]                                        # (n, 4) m/s
    gap = run["feet"] @ up - FOOT_RADIUS                  # the feet's clearance (the plane passes the origin)
    c = (gap < STANCE_GAP)[k]                             # in stance (MuJoCo's contact flickers at zero depth)
    any_c = c.any(axis=1)
    stance_back = np.where(c, -v_rel, 0.0)
    v_est = np.where(any_c, stance_back.sum(axis=1) / np.maximum(c.sum(axis=1), 1), np.nan)
    dt = np.gradient(tw)
    stroke = float((stance_back * dt[:, None]).sum() / 4 / (duration * f))      # per foot per cycle
    duty = float(c.mean())
    stance_speed = float(np.abs(v_rel[c]).mean()) if c.any() else 0.0
    vf = run["feet_velocity"][k]
    v_t = np.linalg.norm(vf - (vf @ up)[..., None] * up, axis=-1)
    threshold = max(SLIDE_FRACTION * stance_speed, 1e-4)
    slides = (v_t > threshold) & c
    # contact: the ground's normal force on a foot, at the sample (instantaneous) and over
    # every step of the interval before it (its impulse; the steps with a positive force)
    touch_now = (run["foot_force"] @ up)[k] > 0.0                       # (n, 4)
    ki = np.flatnonzero(k)[1:]                                           # the intervals inside the window
    touch = (run["foot_force_mean"] @ up)[ki] > 0.0
    loaded = np.asarray(run["loaded_steps"])[ki]
    steps = np.asarray(run["interval_steps"])[ki]
    near = (gap < STANCE_GAP)[ki]
    out = {
        "frequency_hz": f, "amplitude_v": run["amplitude"], "lift_amplitude_v": run.get("lift_amplitude"),
        "speed_m_s": speed, "lateral_drift_m_s": lateral,
        "kinematic_speed_m_s": float(np.nanmean(v_est)) if any_c.any() else None,    # None: no foot ever down
        "stance_stroke_m": stroke, "duty_factor": duty,
        "stroke_f_over_duty_m_s": stroke * f / duty if duty > 0 else None,
        "time_with_a_foot_down": float(any_c.mean()),
        "slip_fraction": float(slides.sum() / max(c.sum(), 1)), "slide_threshold_m_s": threshold,
        "max_abs_roll_deg": float(np.abs(rp[:, 0]).max()), "max_abs_pitch_deg": float(np.abs(rp[:, 1]).max()),
        "mean_roll_deg": float(rp[:, 0].mean()), "mean_pitch_deg": float(rp[:, 1].mean()),
        "body_height_range_m": [float((p @ up).min()), float((p @ up).max())],
        "max_penetration_m": float(run["penetration"].max()),
        "contact_tolerance_m": CONTACT_WIDTH_FRACTION * FOOT_RADIUS,
        # the fastest a foot moved (m/s): a critically damped contact of time constant tau
        # stops a body landing at v within v tau / e (contact_sizing)
        "max_foot_speed_m_s": float(np.linalg.norm(run["feet_velocity"], axis=-1).max()),
        # stance onsets per foot per cycle: ~1 a trot, several a foot bouncing, < 1 a body in flight
        "touchdowns_per_cycle": float(((~c[:-1]) & c[1:]).sum() / 4 / (duration * f)),
        # the same read from the normal force: the share of the sample intervals in which a foot
        # carried load (a positive normal impulse; and of every step, and at the samples alone),
        # the onsets of those intervals per foot and cycle, and of the samples with a foot within
        # STANCE_GAP of the ground the share whose interval it carried load in (1: a stance
        # foot is in contact; and at the sample's instant alone)
        "contact_duty_factor": float(touch.mean()),                              # intervals with a load
        "loaded_step_fraction": float(loaded.sum() / (4 * steps.sum())),        # every step with a load
        "contact_duty_factor_sampled": float(touch_now.mean()),                  # at the samples alone
        "contact_touchdowns_per_cycle": float(((~touch[:-1]) & touch[1:]).sum() / 4 / (duration * f)),
        # the issue's: the onsets of a positive normal force at the samples' instants, per foot and cycle
        "contact_touchdowns_per_cycle_sampled": float(((~touch_now[:-1]) & touch_now[1:]).sum() / 4 / (duration * f)),
        "contact_when_near": float(touch[near].mean()) if near.any() else None,
        "contact_when_near_sampled": float(touch_now[1:][near].mean()) if near.any() else None,
        # the load's onsets at the step's resolution (a flickering contact: many per cycle)
        "step_touchdowns_per_cycle": float(np.asarray(run["onsets"])[ki].sum() / 4 / (duration * f)),
        # momentum: the mean of the feet's vertical (ground-normal) forces over the window against
        # the weight plus the change of the robot's momentum along the normal (force_balance)
        **force_balance(run),
        # over the whole run (a roll-over may come before the window): below 0, through the ground
        "min_chassis_clearance_m": float(np.min(run["chassis_clearance"])),
        "min_leg_clearance_m": float(np.min(run["leg_clearance"])),
        "measured_s": float(duration), "simulated_s": float(t[-1]),
        "wall_time_s": float(run["result"].meta["wall_time_s"]),
        "wall_s_per_simulated_s": float(run["result"].meta["wall_time_s"] / t[-1]),
    }
    out["upright"] = upright(out)
    return out


def upright(metrics: dict) -> bool:
    """|roll| and |pitch| stayed below UPRIGHT_DEG over the measuring window."""
    return bool(metrics["max_abs_roll_deg"] < UPRIGHT_DEG and metrics["max_abs_pitch_deg"] < UPRIGHT_DEG)
