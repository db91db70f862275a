"""The curvature-tracking task without dm_control: what the dm_env environment
(:mod:`mjeap.envs.environment`, MuJoCo 3.x) and the Gymnasium one (:mod:`mjeap.envs.gymnasium_env`,
MuJoCo 3.17 and 4.x) share, so that both pose the same task.

* the episode: payload mass (kg) and initial curvature (1/m) drawn uniformly from a seeded
  generator (:func:`draw_episode`; the payload is changed in place, see
  :mod:`mjeap.envs.environment` on what that keeps);
* the action: one voltage (V), clipped to the drive's safe range with a count and one
  warning per episode (:class:`VoltageLimiter`);
* the step: the drive, then ``mj_step``, once per MuJoCo step, the voltage held
  (:func:`step_lockstep`);
* the observations (SI, :func:`observe`) and the Gaussian tracking reward
  (:func:`tracking_reward`, dm_control's ``rewards.tolerance`` without dm_control).
"""
from __future__ import annotations

import collections
import math
import warnings
from typing import Callable, Dict, List, Optional, Tuple

import mujoco
import numpy as np

from ..model.discretize import Payload
from ..errors import ParameterError
from ..engines.frame import check_initial_curvature, one_voltage
from ..engines import stepper

__all__ = ["default_reference", "check_curvature_range", "check_mass_range", "warn_heavy_range", "draw_episode",
           "VoltageLimiter", "step_lockstep", "observe", "reference_value", "tracking_reward"]

#: the reward at an error of one margin (dm_control's ``rewards.tolerance`` default)
VALUE_AT_MARGIN = 0.1


def default_reference(t):
    """Dadras et al. 2021's closed-loop reference: a 0.05 Hz sine of 50 1/m at ``t`` s."""
    return 50.0 * np.sin(2 * np.pi * 0.05 * t)


def check_curvature_range(bounds, length: Optional[float]) -> Tuple[float, float]:
    """``(low, high)`` initial curvatures (1/m) with low <= high, each within rollout's
    bounds for a beam of ``length`` m (finite, at most a full circle; None: order only)."""
    try:
        lo, hi = (float(x) for x in bounds)
    except (TypeError, ValueError):
        raise ParameterError("initial_curvature_range", bounds, "(low, high) 1/m") from None
    for k in (lo, hi) if length is not None else ():
        check_initial_curvature(k, length, "initial_curvature_range")
    if lo > hi:
        raise ParameterError("initial_curvature_range", bounds, "(low, high) 1/m with low <= high")
    return lo, hi


def check_mass_range(bounds) -> Optional[Tuple[float, float]]:
    """``(low, high)`` payload masses (kg) with 0 < low <= high, or None (no randomisation)."""
    if bounds is None:
        return None
    try:
        lo, hi = (float(x) for x in bounds)
    except (TypeError, ValueError):
        lo = hi = math.nan
    if not (0 < lo <= hi < math.inf):
        raise ParameterError("payload_mass_range", bounds, "(low, high) kg with 0 < low <= high")
    return lo, hi


def warn_heavy_range(payload_mass_range: Optional[Tuple[float, float]], scene, stacklevel: int = 4) -> None:
    """The Scene's unit check of a payload (:func:`mjeap.simulation.scene.warn_heavy_payload`)
    on the heaviest mass an episode may draw, once, when the environment is made."""
    from ..simulation.scene import warn_heavy_payload
    if payload_mass_range is not None:
        warn_heavy_payload(payload_mass_range[1], float(scene.layout.link_mass.sum()),
                           "payload_mass_range's upper mass", stacklevel)


def draw_episode(scene, random, payload_mass_range: Optional[Tuple[float, float]],
                 initial_curvature_range: Tuple[float, float]) -> Dict[str, float]:
    """Draw an episode from ``random`` (a numpy Generator or RandomState): the payload mass
    uniformly in ``payload_mass_range`` (kg; None: the scene's own, nothing drawn), written
    into ``scene.model`` with its inertia (same sphere, or the same given inertia) and
    ``mj_setConst``, and into ``scene.payload`` (same position and size: the model simulates
    the drawn mass, the scene says so); then the initial curvature (1/m) uniformly in
    ``initial_curvature_range``. Returns ``{"payload_mass_kg"?, "initial_curvature_per_m"}``;
    the caller resets the beam and the drive to that curvature."""
    episode = {}
    if payload_mass_range is not None:
        if scene.payload_id < 0:
            raise ParameterError("payload_mass_range", payload_mass_range,
                                 "None for a scene without a payload (give the scene a nominal payload)")
        mass = float(random.uniform(*payload_mass_range))
        m, u, p = scene.model, scene.units, scene.payload
        drawn = Payload(mass, p.position, rotary_inertia=p.rotary_inertia) if p.rotary_inertia is not None else \
            Payload(mass, p.position, p.sphere_radius)          # the sphere drawn keeps its size
        m.body_mass[scene.payload_id] = mass / u.mass
        m.body_inertia[scene.payload_id] = drawn.inertia / u.inertia
        mujoco.mj_setConst(m, scene.data)
        scene.payload = drawn
        episode["payload_mass_kg"] = mass
    episode["initial_curvature_per_m"] = float(random.uniform(*initial_curvature_range))
    return episode


class VoltageLimiter:
    """An action as the drive's input: one finite voltage (V; a number or an array of shape
    (1,), more values are refused, not cut, naming ``space``), clipped to the drive's safe
    range. Clipped actions are counted in ``saturated_steps`` and warned about once per
    episode (:meth:`reset` starts one)."""

    def __init__(self, space: str = "the action space"):
        self.space = space
        self.reset()

    def reset(self) -> None:
        self.saturated_steps, self._warned = 0, False

    def __call__(self, action, drive, stacklevel: int = 3) -> float:
        actuator = drive.scene.actuator.id
        u = one_voltage(action, "action", f"{self.space}: shape (1,), the voltage of {actuator}")
        lo, hi = drive.voltage_range()
        v = min(max(u, lo), hi)
        if v != u:
            self.saturated_steps += 1
            if not self._warned:
                warnings.warn(f"action {u:.4g} V clipped to the safe range [{lo:g}, {hi:g}] V of {actuator}",
                              stacklevel=stacklevel)
                self._warned = True
        return v


def step_lockstep(scene, drive, voltage: float, nstep: int) -> None:
    """Advance ``nstep`` MuJoCo steps with ``voltage`` (V) held: the drive, then ``mj_step``,
    once per step (the environments' engine, :func:`mjeap.engines.stepper`). No divergence check and no kinematics
    update: the caller does both."""
    stepper().advance(scene, drive, voltage, nstep)
    scene.step_count += nstep


def observe(scene, drive, reference: Callable[[float], float], signal_names: List[str]):
    """The observations, SI: ``tip_curvature`` (1/m, the arc through clamp and tip),
    ``reference`` (1/m, at the present time), ``tip_position`` (m, clamp frame),
    ``drive_state`` (the drive's ``signals()`` in the order ``signal_names``, each in the
    unit its name gives) and, for a drive that reports one, ``current`` (A)."""
    sig = drive.signals()
    obs = collections.OrderedDict()
    obs["tip_curvature"] = np.array([scene.tip_curvature()])
    obs["reference"] = np.array([reference_value(reference, scene.time)])
    obs["tip_position"] = scene.tip_position()
    obs["drive_state"] = np.array([sig[k] for k in signal_names], dtype=float)
    if "current (A)" in sig:
        obs["current"] = np.array([sig["current (A)"]])
    return obs


def reference_value(reference: Callable[[float], float], t: float) -> float:
    """``reference(t)`` (1/m) as one finite number (a one-element array too); anything else
    (more values, text, None, NaN) is refused naming the reference and the time."""
    value = reference(t)
    try:
        a = None if isinstance(value, (str, bytes, bool, type(None))) else np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        a = None
    if a is None or a.size != 1 or not np.isfinite(a.reshape(-1)[0]):
        shown = value if a is None or a.ndim == 0 else f"{type(value).__name__} of shape {a.shape}"
        raise ParameterError("reference", shown, "a callable reference(t) returning one finite number, the "
                             "reference curvature in 1/m at t s (a number or an array of shape (1,))",
                             f"its value at t = {t:.6g} s")
    return float(a.reshape(-1)[0])


def tracking_reward(kappa: float, reference: float, margin: float) -> float:
    """A Gaussian of the tracking error (1/m): 1 on target, VALUE_AT_MARGIN (0.1) at an error
    of ``margin`` 1/m; dm_control's ``rewards.tolerance(kappa - reference, bounds=(0, 0),
    margin=margin, sigmoid='gaussian')``, the same arithmetic."""
    d = abs(kappa - reference) / margin
    scale = np.sqrt(-2 * np.log(VALUE_AT_MARGIN))
    return float(np.exp(-0.5 * (d * scale) ** 2))
