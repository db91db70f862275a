"""Fitting an actuator file's own numbers to a measurement, in the file's own form, so that the
identified file is the model that was fitted (``mjeap identify hinges``, ``identify piezo``).

* The stiffness is a scale s on the file's EI(x): every layer's modulus times s (EI(x) stays
  proportional to the layered one, taper and stack included), or its flexural_rigidity
  override times s where it has one, or the layered EI(0) times s as an override where the
  planform is uniform (the same hinges, and the form Mutlu et al. 2013's fit wrote before).
* The mass is a scale on the free length's mass (the ``mass`` override: m(x) stays
  proportional to the file's); the tip block is kept.
* The damping is the file's first-mode damping ratio (Rayleigh damping beta K in the beam).

Every fitted number's uncertainty is the least-squares covariance scaled for correlated
residuals (:func:`mjeap.analysis.identify.covariance`): a smooth misfit widens it, white noise
leaves it as it is.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Sequence, Tuple

import numpy as np

from ..errors import ParameterError
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")

__all__ = ["ScaleFit", "scaled_actuator", "check_residual", "fit_tip_trajectory", "trajectory_actuator",
           "RESIDUAL_WARNING", "RESIDUAL_LIMIT"]

#: a fit whose rms residual exceeds this fraction of the data's swing is told loudly
RESIDUAL_WARNING = 0.02
#: ... and this fraction is refused: nothing is written
RESIDUAL_LIMIT = 0.10
#: a parameter whose relative 1-sigma exceeds this is not told apart by the data (held at the file's)
UNRESOLVED = 0.25
#: ... or whose change by a factor e moves the fitted trajectory by less than this fraction of
#: its swing (a model error could then set it)
SENSITIVITY = 0.05


def check_residual(rms: float, swing: Optional[float], what: str, nothing_written: str = "") -> Optional[str]:
    """None where the fit's ``rms`` residual is within RESIDUAL_WARNING of the data's
    ``swing`` (None: ``rms`` is relative already, a log ratio); a warning's text up to
    RESIDUAL_LIMIT; beyond it a ParameterError."""
    ratio = rms if swing is None else (rms / swing if swing > 0 else np.inf)
    told = f"a relative rms residual of {ratio:.1%}" if swing is None else \
        f"an rms residual of {rms:.3g} ({ratio:.1%} of the data's swing {swing:.3g})"
    text = (f"the fit leaves {told}: the model does not describe the data (check the columns' units, the voltage, "
            "the drive, the scene)")
    if ratio > RESIDUAL_LIMIT:
        raise ParameterError(what, f"a residual of {ratio:.1%} of the swing",
                             f"data the identified model reproduces within {RESIDUAL_LIMIT:.0%} of its swing",
                             text + (f"; {nothing_written}" if nothing_written else ""))
    return text if ratio > RESIDUAL_WARNING else None


def _uniform(act) -> bool:
    p = act.planform
    return p.base_width == p.tip_width and all(l.width is None for l in act.layers)


def scaled_actuator(act, *, stiffness: float = 1.0, mass: float = 1.0, damping_ratio: Optional[float] = None,
                    sources: Optional[Dict[str, str]] = None):
    """``act`` with its EI(x) times ``stiffness``, its free length's mass times ``mass`` and its
    damping ratio (module text); ``sources`` (keys 'stiffness', 'mass', 'damping_ratio') are
    the identified numbers' sources (default: 'scaled')."""
    from ..model.actuator import Sourced
    src = {"stiffness": "scaled", "mass": "scaled", "damping_ratio": "scaled", **(sources or {})}
    new = act
    if stiffness != 1.0:
        if act.flexural_rigidity is not None:
            o = act.flexural_rigidity
            new = dataclasses.replace(new, flexural_rigidity=Sourced(o.value * stiffness, o.unit,
                                                                     f"{src['stiffness']}; was {o.value:.6g} N m^2"))
        elif _uniform(act):
            EI = float(act.flexural_rigidity_at(0.0)[0])
            new = dataclasses.replace(new, flexural_rigidity=Sourced(EI * stiffness, "N m^2", src["stiffness"]))
        else:
            layers = tuple(dataclasses.replace(
                l, youngs_modulus=l.youngs_modulus * stiffness,
                sources={**l.sources, "youngs_modulus": f"{src['stiffness']}; x {stiffness:.6g} of "
                                                        f"{l.youngs_modulus:.6g} Pa ({l.provenance('youngs_modulus')})"})
                for l in act.layers)
            new = dataclasses.replace(new, layers=layers)
    if mass != 1.0:
        m0 = act.total_mass()
        new = dataclasses.replace(new, mass=Sourced(m0 * mass, "kg", f"{src['mass']}; was {m0:.6g} kg"))
    if damping_ratio is not None:
        new = dataclasses.replace(new, damping_ratio=Sourced(float(damping_ratio), "-", src["damping_ratio"]))
    return new


@dataclass
class ScaleFit:
    """What a fit of a file's stiffness scale, mass scale and damping ratio found (each with
    its 1-sigma; ``fitted`` names those the data determined, ``notes`` why the others were
    held at the file's)."""

    stiffness_scale: float
    stiffness_scale_std: float
    mass_scale: float
    mass_scale_std: float
    damping_ratio: float
    damping_ratio_std: float
    rms_residual: float
    swing: float
    inflation: float
    evaluations: int
    fitted: Tuple[str, ...]
    notes: List[str] = field(default_factory=list)

    def as_dict(self) -> dict:
        return {k: (list(v) if isinstance(v, tuple) else v) for k, v in dataclasses.asdict(self).items()}


_NAMES = ("stiffness", "mass", "damping_ratio")


def fit_tip_trajectory(scene, time, tip, voltage, drive=None, drive_params: Optional[dict] = None,
                       fit: Sequence[str] = _NAMES) -> ScaleFit:
    """Fit ``scene.actuator``'s stiffness scale, mass scale and damping ratio (those in ``fit``)
    so that its tip deflection (m, clamp frame y) under ``voltage`` (a waveform) follows the
    measured ``tip`` at ``time`` (s), every trial the identified file itself built as ``scene``
    is (scipy.optimize.least_squares on the logarithms). A parameter the data do not
    determine (relative 1-sigma above UNRESOLVED, or a factor e on it moving the trajectory
    by less than SENSITIVITY of its swing: the mass of a quasi-static record, the damping of
    one without ringing) is held at the file's and the reason noted."""
    from .identify import scene_like, check_series, covariance
    from ..simulation.rollout import rollout
    t, y = check_series(time, tip, names=["tip_deflection"])
    swing = float(np.ptp(y))
    if swing == 0:
        raise ParameterError("tip_deflection", "a constant trajectory", "a trajectory that moves")
    act = scene.actuator
    z0 = float(act.damping_ratio.value)
    duration = float(t[-1]) + scene.timestep
    count = [0]

    def simulate(x, names):
        v = dict(zip(names, np.exp(x)))
        variant = scaled_actuator(act, stiffness=v.get("stiffness", 1.0), mass=v.get("mass", 1.0),
                                  damping_ratio=v.get("damping_ratio", z0))
        sc = scene_like(scene, variant)
        interval = max(sc.timestep, float(np.min(np.diff(t))) / 2)
        r = rollout(sc, voltage, duration + sc.timestep, drive=drive, drive_params=drive_params, progress=False,
                    sample_interval=interval)
        count[0] += 1
        return np.interp(t, r.time, r.tip_position[:, 1])

    names = [n for n in _NAMES if n in fit]
    notes: List[str] = []
    start = {"stiffness": 0.0, "mass": 0.0, "damping_ratio": np.log(z0)}
    bounds = {"stiffness": (np.log(1e-3), np.log(1e3)), "mass": (np.log(1e-3), np.log(1e3)),
              "damping_ratio": (np.log(1e-4), np.log(0.95))}
    while True:
        lo, hi = zip(*(bounds[n] for n in names))
        res = optimize.least_squares(lambda x: (simulate(x, names) - y) / swing, [start[n] for n in names],
                                     bounds=(lo, hi), diff_step=1e-4, xtol=1e-9, ftol=1e-9, max_nfev=200)
        cov, inflation = covariance(res.jac, res.fun)
        rel = dict(zip(names, np.sqrt(np.abs(np.diag(cov)))))
        moves = dict(zip(names, np.abs(res.jac).max(axis=0)))
        weak = [n for n in ("mass", "damping_ratio") if n in names and
                not (rel[n] <= UNRESOLVED and moves[n] >= SENSITIVITY)]
        if not weak:
            break
        best = dict(zip(names, res.x))
        for drop in weak:
            names.remove(drop)
            notes.append(_NOT_RESOLVED[drop].format(rel[drop], moves[drop]))
        start.update({n: float(best[n]) for n in names})
    v = dict(zip(names, np.exp(res.x)))
    std = {n: v[n] * rel[n] for n in names}
    rms = float(np.sqrt(np.mean(res.fun ** 2)) * swing)
    return ScaleFit(v.get("stiffness", 1.0), std.get("stiffness", 0.0), v.get("mass", 1.0), std.get("mass", 0.0),
                    v.get("damping_ratio", z0), std.get("damping_ratio", 0.0), rms, swing, inflation, count[0],
                    tuple(names), notes)


_NOT_RESOLVED = {
    "mass": ("the mass was held at the file's: the data do not tell it apart from the stiffness (relative 1-sigma "
             "{:.2g}; a factor e on it moves the trajectory by {:.2g} of its swing: a record without the first "
             "mode's ringing fixes only the stiffness)"),
    "damping_ratio": ("the damping ratio was held at the file's: the data do not determine it (relative 1-sigma "
                      "{:.2g}; a factor e on it moves the trajectory by {:.2g} of its swing: no ringing or decay of "
                      "the first mode in the record)")}


def trajectory_actuator(scene, fit: ScaleFit, data: str, drive: Optional[str] = None,
                        given: Optional[Dict[str, tuple]] = None):
    """``scene.actuator`` with ``fit`` in it (module text), each number's source naming the
    ``data`` file, its 1-sigma and how; driven by ``drive`` (default its own) with ``given``
    over its parameters."""
    from ..drives import default_drive_name
    from .identify import noted, file_drive_rows
    act = scene.actuator
    how = f"identified from {data} (mjeap identify hinges: the tip trajectory fitted with the file's own model"
    infl = f", residual {fit.rms_residual:.3g} m rms; 1-sigma includes x {np.sqrt(fit.inflation):.3g} for its correlation)"
    src = {"stiffness": f"{how}: EI(x) x {fit.stiffness_scale:.6g} +- {fit.stiffness_scale_std:.2g}, proportional to "
                        f"the file's{infl}",
           "mass": f"{how}: mass x {fit.mass_scale:.6g} +- {fit.mass_scale_std:.2g}, m(x) proportional to the file's"
                   f"{infl}",
           "damping_ratio": f"{how}: first-mode damping ratio {fit.damping_ratio:.6g} +- {fit.damping_ratio_std:.2g}"
                            f"{infl}"}
    new = scaled_actuator(act, stiffness=fit.stiffness_scale, mass=fit.mass_scale,
                          damping_ratio=fit.damping_ratio if "damping_ratio" in fit.fitted else None, sources=src)
    drive = drive or default_drive_name(act)
    return dataclasses.replace(new, drive=drive, notes=noted(act, data, "hinges"),
                               drive_parameters=file_drive_rows(act, drive, given or {}))
