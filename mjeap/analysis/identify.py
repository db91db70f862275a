"""System identification the way the source papers do it, on measured or simulated data (SI).

* :func:`fit_step_response` (Dadras et al. 2021, eqs. 7-8): a curvature step response fitted by two
  exponentials, kappa(t) = A + B exp(-p t) + C exp(-a t); the fast pole a is electrical
  (1/RC), the slow pole p and a zero z mechanical (back-relaxation), the initial curvature
  decays on the mechanical pole. Returns the transfer function and a drive that runs it.
* :func:`fit_hinge_parameters` (Mutlu et al. 2013): joint stiffness and damping of the hinge chain
  fitted to a measured tip trajectory by nonlinear least squares (scipy.optimize), the chain
  itself (a :class:`~mjeap.simulation.scene.Scene`) being the model.
* :func:`read_columns`: a user's CSV, checked (columns present, time increasing, finite,
  enough samples) with errors that say what is wrong.
* :func:`step_actuator`, :func:`hinge_actuator`: an actuator (a user's file) with what was
  identified put in it, each number's source naming the data file, so that measure,
  identify, simulate and design are one path (``mjeap identify ... --out identified.toml``):
  the step fit gives the ``rc-relaxation`` drive's eq. (8) parameters; the hinge fit's joint
  stiffness k becomes a flexural-rigidity override EI = k ds (ds = L / N, the hinge chain's
  midpoint rule, :mod:`mjeap.model.discretize`) and its joint damping b the first-mode
  damping ratio whose Rayleigh damping is b = beta k in the fit's scene.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import Dict, Optional, Sequence, Tuple, Union

import numpy as np

from ..errors import ParameterError
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize, signal = (lazy_module(f"scipy.{m}") for m in ("optimize", "signal"))

#: fewest samples accepted by the fits
MIN_SAMPLES = 20
#: a step fit's transient must exceed its rms residual this many times
SNR = 5.0


# ---------------------------------------------------------------- data
def check_series(time, *series, names: Sequence[str] = (), min_samples: int = MIN_SAMPLES) -> Tuple[np.ndarray, ...]:
    """Validate a time base and series of equal length: finite, strictly increasing time,
    at least ``min_samples`` samples. Returns float arrays."""
    t = np.asarray(time, dtype=float)
    names = list(names) or [f"series {i}" for i in range(len(series))]
    if t.ndim != 1 or len(t) < min_samples:
        raise ParameterError("time", f"{len(np.atleast_1d(t))} samples", f"at least {min_samples} samples")
    out = [t]
    for name, y in zip(names, series):
        y = np.asarray(y, dtype=float)
        if y.shape[0] != len(t):
            raise ParameterError(name, f"{y.shape[0]} samples", f"as many samples as time ({len(t)})")
        bad = np.flatnonzero(~np.isfinite(y.reshape(len(t), -1)).all(axis=1))
        if len(bad):
            raise ParameterError(name, f"NaN or inf at row {bad[0]} (t = {t[bad[0]]:g} s)", "finite numbers")
        out.append(y)
    bad = np.flatnonzero(~np.isfinite(t))
    if len(bad):
        raise ParameterError("time", f"NaN or inf at row {bad[0]}", "finite numbers")
    back = np.flatnonzero(np.diff(t) <= 0)
    if len(back):
        i = back[0]
        raise ParameterError("time", f"t[{i + 1}] = {t[i + 1]:g} s after t[{i}] = {t[i]:g} s",
                             "strictly increasing time")
    return tuple(out)


def read_columns(path: Union[str, Path], columns: Sequence[str], min_samples: int = MIN_SAMPLES,
                 units: Optional[Dict[str, str]] = None, time_base: bool = True) -> Dict[str, np.ndarray]:
    """Read the named columns of a CSV with a header row, in SI. A header matches a
    requested name when it is equal or is the name with a unit, ``name (unit)`` or ``name
    [unit]`` ('time (ms)' for 'time'); its numbers are converted from that unit to the SI
    unit ``units`` gives the column (:func:`mjeap.model.quantity.column_scale`: 'ms', 'um',
    'mV', 'nF', ...; a header without a unit is SI; an unknown unit, or one of another
    quantity, is refused naming the column). Without ``units`` the first column is time
    ('s') and the others are converted from the unit they name to SI, whatever it is. With ``time_base`` the first column is the
    time base and is checked like :func:`check_series` (else it must only increase, a
    frequency or a voltage axis)."""
    from ..io.csvio import number, read_rows
    from ..model.quantity import column_scale, split_header
    rows = read_rows(path, "data file")
    header = [h.strip() for h in rows[0]]
    units = dict(units or {columns[0]: "s"})
    idx, scale = {}, {}
    for c in columns:
        hits = [i for i, h in enumerate(header) if h == c or (split_header(h)[0] == c and split_header(h)[1])]
        if not hits:
            raise ParameterError("column", c, f"one of the file's columns: {', '.join(header)}")
        idx[c] = hits[0]
        h = header[hits[0]]
        scale[c] = column_scale(h, units.get(c), str(path))
    data = {c: np.empty(len(rows) - 1) for c in columns}
    for r, row in enumerate(rows[1:], start=2):
        for c, i in idx.items():
            data[c][r - 2] = number(row[i], f"column '{c}'", r) if i < len(row) and row[i].strip() else np.nan
    data = {c: v * scale[c] for c, v in data.items()}
    if time_base:
        t, *rest = check_series(data[columns[0]], *(data[c] for c in columns[1:]), names=columns[1:],
                                min_samples=min_samples)
        return {columns[0]: t, **dict(zip(columns[1:], rest))}
    check_series(np.arange(len(rows) - 1.0), *(data[c] for c in columns), names=columns, min_samples=min_samples)
    back = np.flatnonzero(np.diff(data[columns[0]]) <= 0)
    if len(back):
        raise ParameterError(f"column '{columns[0]}'", f"{data[columns[0]][back[0] + 1]:g} after "
                             f"{data[columns[0]][back[0]]:g} (row {back[0] + 3})", "strictly increasing values")
    return data


#: the highest lag-one autocorrelation counted (a residual of one smooth hump)
RHO_MAX = 0.995


def covariance(jac: np.ndarray, residual: np.ndarray) -> Tuple[np.ndarray, float]:
    """(covariance of the parameters, the variance inflation) of a least-squares fit with
    Jacobian ``jac`` at residual ``residual``: s^2 (J^T J)^-1 with s^2 = |r|^2 / (n - p),
    scaled for correlated residuals. A model that misses the data leaves a smooth residual,
    whose lag-one autocorrelation rho leaves (1 - rho) / (1 + rho) as many independent samples
    as there are samples (the AR(1) effective sample size), so the variance is multiplied by
    (1 + rho) / (1 - rho); white noise leaves it as it is. inf where J^T J is singular."""
    n, p = jac.shape
    r = np.asarray(residual, float)
    s2 = float(r @ r) / max(n - p, 1)
    rho = float(np.clip((r[:-1] @ r[1:]) / (r @ r), 0.0, RHO_MAX)) if r @ r > 0 and n > 2 else 0.0
    inflation = (1 + rho) / (1 - rho)
    try:
        jtj = jac.T @ jac
        if np.linalg.cond(jtj) > 1e14:
            raise np.linalg.LinAlgError
        return np.linalg.inv(jtj) * s2 * inflation, inflation
    except np.linalg.LinAlgError:
        return np.full((p, p), np.inf), inflation


# ---------------------------------------------------------------- Dadras et al. 2021: step response
@dataclass(frozen=True)
class StepFit:
    """kappa(t) = A + B exp(-p t) + C exp(-a t) after a step of ``voltage`` V at t = 0, and
    the transfer function K/V = gain (s + zero) / ((s + p)(s + a)) it implies (1/m per V)."""

    A: float
    B: float
    C: float
    pole_mechanical: float       # p, 1/s
    pole_electrical: float       # a, 1/s
    voltage: float
    gain: float
    zero: float
    initial_curvature: float     # kappa(0-), 1/m
    rms_residual: float          # 1/m

    @property
    def transfer_function(self) -> signal.TransferFunction:
        return signal.TransferFunction([self.gain, self.gain * self.zero],
                                       np.polymul([1, self.pole_mechanical], [1, self.pole_electrical]))

    def curve(self, t) -> np.ndarray:
        t = np.asarray(t, float)
        return self.A + self.B * np.exp(-self.pole_mechanical * t) + self.C * np.exp(-self.pole_electrical * t)

    def drive_parameters(self) -> Dict[str, float]:
        """Parameters of the ``rc-relaxation`` drive that runs this model."""
        return {"gain": self.gain, "zero": self.zero, "pole_mechanical": self.pole_mechanical,
                "pole_electrical": self.pole_electrical}

    def make_drive(self, scene):
        from ..drives import make_drive
        return make_drive("rc-relaxation", scene, **self.drive_parameters())


def fit_step_response(time, curvature, voltage: float, t_step: float = 0.0) -> StepFit:
    """Fit a curvature step response (time in s, curvature in 1/m, the step of ``voltage`` V
    applied at ``t_step``) as Dadras et al. 2021 does (eq. 7) and derive eq. (8)'s form.

    From the step response of gain (s + z)/((s + p)(s + a)) x V/s plus the zero-input term
    kappa0 exp(-p t): A = g V z/(p a), C = g V (z - a)/(a (a - p)), hence
    g V = A p - C (a - p), z = A a p/(g V), and kappa0 = A + B + C."""
    t, k = check_series(time, curvature, names=["curvature"])
    if not np.isfinite(voltage) or voltage == 0:
        raise ParameterError("voltage", voltage, "the step's non-zero amplitude in V")
    try:
        t_step = float(t_step)
    except (TypeError, ValueError):
        t_step = float("nan")
    if not t[0] <= t_step < t[-1]:              # NaN too: a step outside the record shifts every exponential
        raise ParameterError("t_step", t_step, f"the step's time within the data's span [{t[0]:g}, {t[-1]:g}) s",
                             "the fit measures time from the step: a step before the record starts (or after it "
                             "ends) scales B and C by exp(p t) and gives a wrong gain")
    sel = t >= t_step
    if sel.sum() < MIN_SAMPLES:
        raise ParameterError("t_step", t_step, f"a time leaving at least {MIN_SAMPLES} samples after it")
    t, k = t[sel] - t_step, k[sel]
    span = t[-1]

    def model(x, tt):
        A, B, C, lp, ld = x
        p = np.exp(lp)
        return A + B * np.exp(-p * tt) + C * np.exp(-(p + np.exp(ld)) * tt)

    with np.errstate(over="ignore", invalid="ignore"):     # judged below: non-finite fits are refused
        best = _best_fit(model, t, k, span)
    return _step_fit(model, best, t, voltage)


def _best_fit(model, t, k, span):
    best = None
    for p0 in (1.0 / span, 3.0 / span, 10.0 / span):
        for ratio in (3.0, 10.0, 30.0):
            x0 = [k[-1], 0.5 * (k[0] - k[-1]), 0.5 * (k[0] - k[-1]), np.log(p0), np.log(p0 * (ratio - 1))]
            res = optimize.least_squares(lambda x: model(x, t) - k, x0, method="lm", max_nfev=4000)
            if best is None or res.cost < best.cost:
                best = res
    return best


def _step_fit(model, best, t, voltage) -> "StepFit":
    A, B, C, lp, ld = best.x
    p = float(np.exp(lp))
    a = p + float(np.exp(ld))
    gV = A * p - C * (a - p)
    if gV == 0:
        raise ParameterError("curvature", "a response without a step", "a step response with a visible transient")
    with np.errstate(over="ignore", invalid="ignore"):
        z = A * a * p / gV
        rms = float(np.sqrt(np.mean(best.fun ** 2)))
        swing = float(np.ptp(model(best.x, t)))
    if not np.all(np.isfinite([A, B, C, p, a, gV, z, rms])):
        raise ParameterError("curvature", "a fit with non-finite parameters", "data whose step response fits "
                             "kappa = A + B exp(-p t) + C exp(-a t) with finite numbers (check the units and scale)")
    if not swing > SNR * rms:
        raise ParameterError("curvature", f"a transient of {swing:.3g} 1/m against a residual of {rms:.3g} 1/m",
                             f"a step response whose transient is at least {SNR:g} x the fit's residual (flat data "
                             "or noise has no transfer function to identify)")
    return StepFit(float(A), float(B), float(C), p, a, float(voltage), float(gV / voltage), float(z),
                   float(A + B + C), rms)


# ---------------------------------------------------------------- Mutlu et al. 2013: joint stiffness and damping
@dataclass(frozen=True)
class HingeFit:
    stiffness: float             # N m / rad, every hinge
    damping: float               # N m s / rad, every hinge
    stiffness_std: float         # 1-sigma, the residual's correlation counted (covariance)
    damping_std: float
    rms_residual: float          # m
    evaluations: int


def simulate_tip(scene, stiffness: float, damping: float, voltage, duration: float, times: np.ndarray,
                 drive=None, drive_params: Optional[dict] = None) -> np.ndarray:
    """Tip deflection (m, clamp frame y) of ``scene`` with uniform hinge ``stiffness`` and
    ``damping`` driven by ``voltage`` for ``duration`` s, interpolated at ``times``."""
    from ..simulation.rollout import rollout
    scene.set_hinge_parameters(stiffness=stiffness, damping=damping)
    r = rollout(scene, voltage, duration, drive=drive, drive_params=drive_params, progress=False,
                sample_interval=max(scene.timestep, float(np.min(np.diff(times))) / 2) if len(times) > 1 else None)
    return np.interp(times, r.time, r.tip_position[:, 1])


def fit_hinge_parameters(scene, time, tip_deflection, voltage, drive=None, drive_params: Optional[dict] = None,
                         initial: Optional[Tuple[float, float]] = None) -> HingeFit:
    """Fit one stiffness and one damping for every hinge of ``scene`` (a hinge chain) so that
    its tip deflection under ``voltage`` (waveform) follows the measured ``tip_deflection``
    (m) at ``time`` (s), by nonlinear least squares (scipy.optimize.least_squares on the
    logarithms; Mutlu et al. 2013 identifies its 16-link chain this way). ``initial`` = (k, b) start,
    default the scene's own values. The scene's hinges are left at the fitted values."""
    t, y = check_series(time, tip_deflection, names=["tip_deflection"])
    if np.ptp(y) == 0:
        raise ParameterError("tip_deflection", "a constant trajectory", "a trajectory that moves")
    k0, b0 = initial if initial is not None else (float(np.mean(scene.hinge_stiffness())),
                                                  float(np.mean(scene.hinge_damping())))
    if not (k0 > 0 and b0 > 0):
        raise ParameterError("initial", (k0, b0), "positive stiffness (N m/rad) and damping (N m s/rad)")
    duration = float(t[-1]) + scene.timestep
    scale = float(np.ptp(y))
    n_eval = [0]

    def residual(x):
        n_eval[0] += 1
        return (simulate_tip(scene, np.exp(x[0]), np.exp(x[1]), voltage, duration, t, drive, drive_params) - y) / scale

    res = optimize.least_squares(residual, [np.log(k0), np.log(b0)], diff_step=1e-4, x_scale=1.0,
                                 xtol=1e-10, ftol=1e-10, max_nfev=200)
    k, b = np.exp(res.x)
    cov, _ = covariance(res.jac, res.fun)           # scaled for correlated residuals (model error)
    sk, sb = np.sqrt(np.diag(cov))
    scene.set_hinge_parameters(stiffness=k, damping=b)
    return HingeFit(float(k), float(b), float(k * sk), float(b * sb),
                    float(np.sqrt(np.mean(res.fun ** 2)) * scale), n_eval[0])


# ---------------------------------------------------------------- which identification applies
#: the identifications that fit a drive's own model, by drive (``identify hinges`` fits the
#: beam of any drive: its stiffness, mass and damping)
IDENTIFICATIONS = {"step": ("rc-relaxation", "blocking-force"), "piezo": ("piezo-bimorph", "piezo")}
_WHAT = {"step": "Dadras et al. 2021's ionic step response (the rc-relaxation drive)",
         "piezo": "a piezoelectric drive's coupling, capacitance, resonance and damping"}


def check_identification(act, which: str) -> None:
    """Refuse ``mjeap identify which`` on an actuator whose drive it does not fit, naming the
    identification that does (before any work)."""
    from ..drives import default_drive_name
    drive = act.drive or default_drive_name(act)
    if drive in IDENTIFICATIONS.get(which, (drive,)):
        return
    applies = [w for w, drives in IDENTIFICATIONS.items() if drive in drives] or ["hinges"]
    raise ParameterError("mjeap identify", which, f"an actuator whose drive {which} fits: "
                         f"{', '.join(IDENTIFICATIONS[which])} ({_WHAT[which]})",
                         f"{act.id}{' (' + act.source_file + ')' if act.source_file else ''} is driven by {drive}: "
                         f"use mjeap identify {' or '.join(applies)}"
                         + ("" if "hinges" in applies else " (or identify hinges for its beam's stiffness, mass "
                            "and damping)"))


# ---------------------------------------------------------------- what was identified, into an actuator
#: the drive whose parameters a step fit identifies (Dadras et al. 2021, eq. 8)
STEP_DRIVE = "rc-relaxation"
#: the identified file must reproduce the fitted tip trajectory to this fraction of its swing
REPRODUCE = 0.02


def file_drive_rows(act, drive: Optional[str], given: Dict[str, tuple]) -> Dict[str, tuple]:
    """The drive parameter rows (value SI, '', source) of ``act`` driven by ``drive``
    (default its own): its file's own where it names that drive (another drive's are
    dropped), ``given`` over them. A name the drive does not take is refused."""
    from ..drives import default_drive_name, get_drive_class
    from ..model.quantity import to_si
    drive = drive or default_drive_name(act)
    cls = get_drive_class(drive)
    units = cls.parameter_units()
    known = {*units, *cls.extra_parameters(None)}
    for k, v in given.items():
        if k not in known:
            raise ParameterError("--param", f"{k}={v[0]}", f"a parameter of the {drive} drive: "
                                 f"{', '.join(sorted(known)) or 'none'}")
        if k in units:                       # a number (NaN, inf and text refused): the file must read back
            given = {**given, k: (to_si(v[0], units[k], f"--param {k}"), *v[1:])}
    own = dict(act.drive_parameters) if (act.drive or default_drive_name(act)) == drive else {}
    return {**own, **given}


def given_rows(params: Optional[dict], how: str) -> Dict[str, tuple]:
    """Drive parameters given alongside a fit (``--param``) as rows with their source."""
    return {k: (v, "", f"given on the command line ({how} --param)") for k, v in (params or {}).items()}


def step_rows(act, given: Optional[Dict[str, tuple]] = None) -> Dict[str, tuple]:
    """The rc-relaxation rows ``act`` keeps or is ``given`` besides the four a step fit
    identifies; raises, before the fit, where the drive would lack one (its capacitance:
    a curvature step does not identify it)."""
    from ..drives import get_drive_class
    rows = file_drive_rows(act, STEP_DRIVE, given or {})
    fitted = ("gain", "zero", "pole_mechanical", "pole_electrical")
    missing = [k for k in get_drive_class(STEP_DRIVE).parameter_units() if k not in rows and k not in fitted]
    if missing:
        where = act.source_file or act.id
        raise ParameterError(f"{where}: drive.parameters.{missing[0]}", "missing",
                             f"a value for the {STEP_DRIVE} drive's {', '.join(missing)} (a curvature step does not "
                             f"identify it): in the file's [drive.parameters], or --param {missing[0]}=VALUE",
                             f"the file's drive is {act.drive or 'not named'}" if act.drive != STEP_DRIVE else "")
    return rows


def step_actuator(act, fit: StepFit, data: str, given: Optional[Dict[str, tuple]] = None):
    """``act`` driven by the rc-relaxation drive with the eq. (8) parameters of ``fit``, each
    sourced to the ``data`` file it was identified from; the drive's other parameters the
    file's own (same drive) or ``given``. The initial curvature is a state, not written."""
    rows = step_rows(act, given)
    how = (f"identified from {data} (mjeap identify step: Dadras et al. 2021 eqs. 7-8 fitted to a {fit.voltage:g} V step, "
           f"rms residual {fit.rms_residual:.3g} 1/m)")
    fitted = {k: (float(v), "", how) for k, v in fit.drive_parameters().items()}
    rows = {**fitted, **{k: v for k, v in rows.items() if k not in fitted}}
    return dataclasses.replace(act, drive=STEP_DRIVE, drive_parameters=rows, notes=noted(act, data, "step"))


def noted(act, data: str, what: str) -> str:
    line = f"identified from {data} by mjeap identify {what}"
    return f"{act.notes}; {line}" if act.notes else line


def hinge_actuator(scene, fit: HingeFit, data: str, drive: Optional[str] = None,
                   given: Optional[Dict[str, tuple]] = None):
    """``scene.actuator`` with the hinge fit put in it (sources naming ``data``):
    flexural_rigidity EI = k ds (every hinge k = EI / ds, ds = L / N: the chain's midpoint
    rule, uniform along the beam as the fit is) and the damping ratio whose first-mode
    Rayleigh damping in the fit's scene gives the fitted joint damping, beta = b / k (plus
    the timestep 'discrete' adds itself); driven by ``drive`` (default its own) with
    ``given`` over its parameters."""
    from ..drives import default_drive_name
    from ..model.actuator import Sourced
    act = scene.actuator
    drive = drive or default_drive_name(act)
    n, ds = scene.layout.segments, scene.layout.ds
    how = f"identified from {data} (mjeap identify hinges: Mutlu et al. 2013's joint fit on {n} hinges"
    EI = Sourced(fit.stiffness * ds, "N m^2",
                 f"{how}, k = {fit.stiffness:.4g} +- {fit.stiffness_std:.2g} N m/rad at every hinge; EI = k L/N, "
                 "uniform along the beam)")
    new = dataclasses.replace(act, flexural_rigidity=EI, drive=drive, notes=noted(act, data, "hinges"),
                              drive_parameters=file_drive_rows(act, drive, given or {}))
    beta = fit.damping / fit.stiffness + scene.choice.integrator_beta
    zeta = beta / _beta_per_damping_ratio(scene, new)
    if not 0.0 < zeta < 1.0:
        raise ParameterError("damping_ratio", f"{zeta:.4g} (identified: b = {fit.damping:.4g} N m s/rad, "
                             f"k = {fit.stiffness:.4g} N m/rad)", "a first-mode damping ratio in (0, 1), as an "
                             "actuator file takes it", "the fitted joint damping is outside what the file can hold; "
                             "check the data's time base and units")
    return dataclasses.replace(new, damping_ratio=Sourced(
        zeta, "-", f"{how}, b = {fit.damping:.4g} +- {fit.damping_std:.2g} N m s/rad at every hinge: the first-mode "
                   f"damping ratio of Rayleigh damping beta = b/k = {beta:.4g} s in the fit's scene "
                   f"({scene.representation}, {scene.orientation}, {'payload, ' if scene.payload else ''}"
                   f"{scene.integrator}))"))


def scene_like(scene, act, **kw):
    """A Scene of ``act`` built as ``scene`` is (representation, segments, orientation,
    payload, units, gravity, integrator), ``kw`` over it."""
    from ..simulation.scene import Scene
    a = scene.arguments
    args = dict(representation=a["representation"], segments=scene.layout.segments, orientation=a["orientation"],
                payload=a["payload"], units=a["units"], gravity=a["gravity"], integrator=scene.integrator)
    return Scene(act, **{**args, **kw})


def _beta_per_damping_ratio(scene, act) -> float:
    """The Rayleigh beta (s) per unit first-mode damping ratio of ``act`` built as ``scene``
    (beta = 2 zeta w1 / k1 is linear in zeta: the probe is built at zeta = 1)."""
    return scene_like(scene, act, damping_ratio=1.0).choice.rayleigh_beta


def reproduction_error(scene, fit: HingeFit, act, time, voltage, drive=None, drive_params=None) -> Tuple[float, float]:
    """(rms difference, swing) in m between the tip trajectory of ``scene`` with the fitted
    hinges and that of ``act`` alone (its file's drive and parameters), built as ``scene``
    is but with its own timestep, under ``voltage`` at ``time``: whether a file holds what
    was fitted."""
    from ..simulation.rollout import rollout
    t = np.asarray(time, float)
    duration = float(t[-1]) + scene.timestep
    fitted = simulate_tip(scene, fit.stiffness, fit.damping, voltage, duration, t, drive, drive_params)
    r = rollout(scene_like(scene, act), voltage, duration, progress=False)
    mine = np.interp(t, r.time, r.tip_position[:, 1])
    return float(np.sqrt(np.mean((mine - fitted) ** 2))), float(np.ptp(fitted))
