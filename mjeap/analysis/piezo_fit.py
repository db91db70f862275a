"""Identifying a piezoelectric bender from the measurements designers take (``mjeap identify
piezo``): stroke against voltage, a tip frequency response, an impedance sweep, or a published
resonance, fitted together with the actuator file's own small-signal model
(:mod:`mjeap.analysis.frf`), so that the identified file is the model that was fitted.

Parameters, each a factor on the file's value (fitted on its logarithm):

* ``coupling``: the drive's moment per volt Gamma (f31 for piezo-bimorph), also its motional
  coupling (reciprocity);
* ``stiffness``: EI(x) as a whole (:func:`mjeap.analysis.file_fit.scaled_actuator`);
* ``tip_mass``: the rigid tip block's mass (its material and residual);
* ``damping_ratio``; ``capacitance`` (dielectric, blocked) and ``conductance`` (1/R).

What each measurement tells: stroke per volt (quasi-static) is Gamma / EI times the beam's
shape; a tip FRF adds f1 ~ sqrt(EI / m) and the damping; an impedance sweep of a free actuator
through resonance gives C, and from resonance and antiresonance k_eff^2 ~ Gamma^2 / (EI C);
one of a fixed (blocked) actuator gives C and R only. Where the data leave a combination
undetermined (f1 alone cannot tell a modulus scale from a tip mass; stroke alone cannot tell
Gamma from EI) the parameters are held at the file's values in the order ``stiffness``,
``tip_mass``, ``coupling``, and the output says which and why: a fit whose parameter has a
relative 1-sigma above :data:`mjeap.analysis.file_fit.UNRESOLVED` (J^T J singular: a
combination the data do not see) or whose factor e moves the fit by less than
:data:`~mjeap.analysis.file_fit.SENSITIVITY` drops it.

Residuals: the stroke's about a fitted offset, relative to its swing; the FRF's and the
admittance's magnitudes as log ratios and their phases in radians; a given resonance relative.
Uncertainties: :func:`mjeap.analysis.identify.covariance` (residual correlation counted); none
where the data are exactly as many as the parameters they fix (then the measurement's own
uncertainty carries over).
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Dict, List, Optional, Tuple

import numpy as np

from ..errors import ParameterError
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize, linalg = (lazy_module(f"scipy.{m}") for m in ("optimize", "linalg"))

__all__ = ["PiezoData", "PiezoFit", "read_stroke", "read_frf", "read_impedance", "fit_piezo", "piezo_actuator",
           "COUPLING_PARAMETER"]

#: the drive parameter a drive's moment per volt is proportional to (the one ``coupling`` scales)
COUPLING_PARAMETER = {"piezo-bimorph": "f31", "piezo": "d31"}
PARAMETERS = ("coupling", "stiffness", "tip_mass", "damping_ratio", "capacitance", "conductance")
#: held first where the data leave a combination open (module text)
HOLD_ORDER = ("stiffness", "tip_mass", "coupling", "damping_ratio", "conductance", "capacitance")


@dataclass
class PiezoData:
    """Measurements, SI: ``stroke`` (volts, deflection m), ``frf`` (Hz, tip per volt complex m/V
    or magnitude, whether it has a phase), ``impedance`` (Hz, admittance complex S or
    magnitude, whether it has a phase, 'free' or 'fixed'), ``resonance`` (Hz, published: the
    first mode); ``sources`` names each (a file, a publication)."""

    stroke: Optional[Tuple[np.ndarray, np.ndarray]] = None
    frf: Optional[Tuple[np.ndarray, np.ndarray, bool]] = None
    impedance: Optional[Tuple[np.ndarray, np.ndarray, bool, str]] = None
    resonance: Optional[float] = None
    sources: Dict[str, str] = field(default_factory=dict)

    def given(self) -> List[str]:
        return [k for k in ("stroke", "frf", "impedance", "resonance") if getattr(self, k) is not None]


# ---------------------------------------------------------------- reading the measurements
def _header(path) -> List[str]:
    from ..io.csvio import read_rows
    from ..model.quantity import split_header
    return [split_header(h.strip())[0] for h in read_rows(path, "data file")[0]]


def read_stroke(path, voltage: str = "voltage", stroke: str = "stroke") -> Tuple[np.ndarray, np.ndarray]:
    """(voltage V, tip deflection m) of a stroke-voltage CSV (units from the headers)."""
    from .identify import read_columns
    d = read_columns(path, [voltage, stroke], min_samples=2, units={voltage: "V", stroke: "m"}, time_base=False)
    return d[voltage], d[stroke]


def read_frf(path) -> Tuple[np.ndarray, np.ndarray, bool]:
    """(frequency Hz, tip per volt m/V, whether a phase was given) of a tip FRF CSV: columns
    frequency, tip_per_volt and optionally tip_phase (deg), as ``mjeap frf`` writes them."""
    from .identify import read_columns
    phase = "tip_phase" in _header(path)
    cols = ["frequency", "tip_per_volt"] + (["tip_phase"] if phase else [])
    d = read_columns(path, cols, min_samples=3, units={"frequency": "Hz", "tip_per_volt": "m/V", "tip_phase": "rad"},
                     time_base=False)
    h = d["tip_per_volt"] * (np.exp(1j * d["tip_phase"]) if phase else 1.0)
    return d["frequency"], h, phase


def read_impedance(path) -> Tuple[np.ndarray, np.ndarray, object]:
    """(frequency Hz, admittance S, whether a phase was given) of an impedance sweep: columns
    frequency and one of admittance [+ admittance_phase (deg)], impedance [+ impedance_phase]
    (ohm), or capacitance [+ resistance] (the parallel C-R an impedance analyser's Cp-Rp mode
    and Jayaram et al. 2018, eqs. 3b-3c, give: Y = 1/R + i omega C; a capacitance alone is
    the susceptance, 'susceptance' in place of the flag: it is compared with Im Y)."""
    from .identify import read_columns
    names = _header(path)
    for mag, ph, unit in (("admittance", "admittance_phase", "S"), ("impedance", "impedance_phase", "ohm")):
        if mag in names:
            phase = ph in names
            d = read_columns(path, ["frequency", mag] + ([ph] if phase else []), min_samples=1,
                             units={"frequency": "Hz", mag: unit, ph: "rad"}, time_base=False)
            y = d[mag] if mag == "admittance" else 1.0 / d[mag]
            p = d[ph] if phase else 0.0
            return d["frequency"], y * np.exp(1j * (p if mag == "admittance" else -p)), phase
    if "capacitance" in names:
        res = "resistance" in names
        d = read_columns(path, ["frequency", "capacitance"] + (["resistance"] if res else []), min_samples=1,
                         units={"frequency": "Hz", "capacitance": "F", "resistance": "ohm"}, time_base=False)
        g = 1.0 / d["resistance"] if res else 0.0
        return d["frequency"], g + 2j * np.pi * d["frequency"] * d["capacitance"], True if res else "susceptance"
    raise ParameterError("impedance file", str(path), "columns frequency and admittance (S), impedance (ohm) or "
                         "capacitance (F) (each with its unit in the header)", f"it has {', '.join(names)}")


# ---------------------------------------------------------------- the model
class _Model:
    """The file's small-signal model with the parameters' factors applied (module text)."""

    def __init__(self, scene, drive_params: Optional[dict] = None):
        from .frf import SmallSignalModel
        from .identify import scene_like
        self.scene = scene
        self.base = SmallSignalModel(scene, drive_params=drive_params)
        if self.base.drive.name not in COUPLING_PARAMETER:
            raise ParameterError("drive", self.base.drive.name, f"a piezoelectric drive ({', '.join(COUPLING_PARAMETER)})")
        lin = scene.linearization
        self.M0, self.Kel, self.Kg0 = lin.M, lin.K_elastic, lin.K_gravity
        act = scene.actuator
        self.block = act.planform.tip_block_mass
        if self.block > 0:          # the mass and gravity matrices are linear in the block's mass
            twice = dataclasses.replace(act, planform=dataclasses.replace(
                act.planform, residual_tip_mass=act.planform.residual_tip_mass + self.block))
            lin2 = scene_like(scene, twice).linearization
            self.dM, self.dKg = lin2.M - self.M0, lin2.K_gravity - self.Kg0
        else:
            self.dM = self.dKg = np.zeros_like(self.M0)
        self.ss0 = self.base.small_signal
        self.pattern = np.clip(np.diag(self.Kel), 0.0, None)
        self.u = scene.units

    def set(self, v: Dict[str, float]) -> None:
        """Put the factors ``v`` (parameter -> factor; damping_ratio its value) in the model."""
        m, ss = self.base, self.ss0
        mu = v.get("tip_mass", 1.0) - 1.0
        m.M = self.M0 + mu * self.dM
        Kel = v.get("stiffness", 1.0) * self.Kel
        m.K = Kel + self.Kg0 + mu * self.dKg
        lam, phi = linalg.eigh(m.K, m.M)
        w1 = np.sqrt(max(lam[0], 0.0))
        k1 = float(phi[:, 0] @ (v.get("stiffness", 1.0) * self.pattern * phi[:, 0]))
        zeta = v.get("damping_ratio", self.scene.choice.damping_ratio)
        beta = 2 * zeta * w1 / k1
        m.D = np.diag(beta * v.get("stiffness", 1.0) * self.pattern)
        self.f1 = w1 / self.u.time / (2 * np.pi)
        a = v.get("coupling", 1.0)
        m.small_signal = dataclasses.replace(ss, moment_per_volt=a * ss.moment_per_volt, coupling=a * ss.coupling,
                                             capacitance=v.get("capacitance", 1.0) * ss.capacitance,
                                             conductance=v.get("conductance", 1.0) * ss.conductance)


def _residuals(model: _Model, data: PiezoData) -> Dict[str, np.ndarray]:
    out = {}
    m = model.base
    if data.stroke is not None:
        v, d = data.stroke
        h0 = float(np.real(m.tip([0.0])[0]))
        pred = h0 * v
        out["stroke"] = (pred + np.mean(d - pred) - d) / np.ptp(d)
    if data.frf is not None:
        f, h, phase = data.frf
        t = m.tip(f)
        r = [np.log(np.abs(t) / np.abs(h))]
        if phase:
            r.append(np.angle(t / h))
        out["frf"] = np.concatenate(r)
    if data.impedance is not None:
        f, y, phase, state = data.impedance
        if state == "fixed":
            ss = m.small_signal
            yy = ss.conductance + 2j * np.pi * f * ss.capacitance
        else:
            yy = m.admittance(f)
        if phase == "susceptance":
            r = [np.log(np.abs(yy.imag) / np.abs(y.imag))]
        else:
            r = [np.log(np.abs(yy) / np.abs(y))] + ([np.angle(yy / y)] if phase else [])
        out["impedance"] = np.concatenate(r)
    if data.resonance is not None:
        out["resonance"] = np.array([model.f1 / data.resonance - 1.0])
    return out


def _candidates(data: PiezoData, model: _Model) -> List[str]:
    """The parameters the given measurements can touch at all."""
    names = set()
    if data.stroke is not None:
        names |= {"coupling", "stiffness"}
    if data.frf is not None:
        names |= {"coupling", "stiffness", "tip_mass", "damping_ratio"}
    if data.resonance is not None:
        names |= {"stiffness", "tip_mass"}
    if data.impedance is not None:
        names |= {"capacitance", "conductance"}
        if data.impedance[3] == "free":
            names |= {"coupling", "stiffness", "tip_mass", "damping_ratio"}
    if model.block <= 0:
        names.discard("tip_mass")
    if model.ss0.conductance <= 0:
        names.discard("conductance")
    return [p for p in PARAMETERS if p in names]


# ---------------------------------------------------------------- the fit
@dataclass
class PiezoFit:
    """The identified factors (``values``; damping_ratio its value) with their 1-sigma
    (``std``, None where the data are exactly as many as the parameters), the parameters held
    at the file's and why (``held``), each measurement's rms residual, and derived numbers."""

    values: Dict[str, float]
    std: Dict[str, Optional[float]]
    held: Dict[str, str]
    residuals: Dict[str, float]
    inflation: float
    evaluations: int
    derived: Dict[str, float] = field(default_factory=dict)


_HELD = {
    "stiffness": "held at the file's: the data do not tell a modulus scale apart from {others} (a modulus scale "
                 "moves f1 and the stroke per volt together; it needs the stroke or quasi-static tip per volt and the "
                 "coupling seen in an impedance sweep through resonance, or a second mode)",
    "tip_mass": "held at the file's: the data do not determine it (f1 needs a resonance: an FRF or impedance through "
                "it, or a published one)",
    "coupling": "held at the file's: the data do not determine it (it needs a stroke, a quasi-static tip per volt or "
                "an impedance sweep through resonance)",
    "damping_ratio": "held at the file's: the data do not determine it (it needs the resonance's width: an FRF or "
                     "impedance sweep through it)",
    "capacitance": "held at the file's: the data do not determine it (it needs an impedance sweep)",
    "conductance": "held at the file's: the data do not determine it (the resistive current is below the sweep's "
                   "resolution)"}


#: the drive parameter each fitted factor scales (the coupling's is the drive's own, COUPLING_PARAMETER)
SCALES = {"capacitance": "capacitance", "conductance": "resistance"}


def fit_piezo(scene, data: PiezoData, drive_params: Optional[dict] = None) -> PiezoFit:
    """Fit the parameters the measurements ``data`` determine (module text) with the model of
    ``scene`` (its actuator file built as the user asked) and its drive with ``drive_params``
    over the file's (those given are kept: their factors are not fitted), by
    scipy.optimize.least_squares on their logarithms; held ones are named with the reason."""
    from .file_fit import SENSITIVITY, UNRESOLVED
    from .identify import covariance
    if not data.given():
        raise ParameterError("identify piezo", "no measurement", "at least one of --stroke, --frf, --impedance "
                             "or --resonance")
    model = _Model(scene, drive_params)
    given = {p for p, key in {**SCALES, "coupling": COUPLING_PARAMETER[model.base.drive.name]}.items()
             if key in (drive_params or {})}
    names = [p for p in _candidates(data, model) if p not in given]
    held = {p: _HELD[p].format(others="the tip mass") for p in PARAMETERS if p not in names}
    held.update({p: "given on the command line (--param): kept as given" for p in given})
    z0 = scene.choice.damping_ratio
    start = {p: 0.0 for p in PARAMETERS}
    start["damping_ratio"] = np.log(z0)
    count = [0]

    def values(x, free):
        v = dict(zip(free, np.exp(x)))
        return v

    def residual(x, free):
        count[0] += 1
        model.set(values(x, free))
        return np.concatenate(list(_residuals(model, data).values()))

    # the resonance moves the misfit's valleys: start from the best of a grid on the factor
    # that moves f1 (the stiffness, else the tip mass), the others at the file's
    for q in ("stiffness", "tip_mass"):
        if q in names:
            grid = np.log(np.geomspace(0.25, 4.0, 41)) * (1 if q == "stiffness" else -1)
            cost = [float(np.sum(residual(np.array([g if n == q else start[n] for n in names]), names) ** 2))
                    for g in grid]
            start[q] = float(grid[int(np.argmin(cost))])
            break
    while True:
        lo = [np.log(1e-4) if p == "damping_ratio" else np.log(1e-3) for p in names]
        hi = [np.log(0.95) if p == "damping_ratio" else np.log(1e3) for p in names]
        x0 = np.clip([start[p] for p in names], lo, hi)
        res = optimize.least_squares(residual, x0, args=(names,), bounds=(lo, hi), diff_step=1e-6, xtol=1e-12,
                                     ftol=1e-12, gtol=1e-12, max_nfev=400 * max(1, len(names)))
        n, p = res.jac.shape
        cov, inflation = covariance(res.jac, res.fun)
        rel = dict(zip(names, np.sqrt(np.abs(np.diag(cov)))))
        moves = dict(zip(names, np.abs(res.jac).max(axis=0)))
        exact = n <= p
        # first what the data do not see at all, then (one at a time, in HOLD_ORDER) what they
        # see only in combination with another
        weak = [q for q in HOLD_ORDER if q in names and moves[q] < SENSITIVITY]
        if not weak:
            weak = [q for q in HOLD_ORDER if q in names and
                    ((not exact and not rel[q] <= UNRESOLVED) or (exact and not np.isfinite(rel[q])))][:1]
        if not weak and exact and np.linalg.matrix_rank(res.jac, tol=1e-8 * np.abs(res.jac).max()) < p:
            weak = [q for q in HOLD_ORDER if q in names][:1]
        if not weak:
            break
        best = dict(zip(names, res.x))
        for drop in weak:
            names.remove(drop)
            others = ", ".join(q.replace("_", " ") for q in names if q in ("tip_mass", "coupling")) or "the rest"
            held[drop] = _HELD[drop].format(others=others)
        start.update({q: float(best[q]) for q in names})
        if not names:
            raise ParameterError("identify piezo", ", ".join(data.given()), "measurements that determine at least "
                                 "one parameter", "; ".join(f"{k}: {v}" for k, v in held.items()))
    model.set(values(res.x, names))
    v = values(res.x, names)
    std = {q: (None if n <= p else float(v[q] * rel[q])) for q in names}
    parts = _residuals(model, data)
    rms = {k: float(np.sqrt(np.mean(r ** 2))) for k, r in parts.items()}
    fit = PiezoFit(v, std, held, rms, inflation, count[0])
    fit.derived = _derived(model)
    return fit


def _derived(model: _Model) -> Dict[str, float]:
    """Numbers of the identified model: f1, the admittance's resonance and antiresonance, k_eff,
    the quasi-static tip per volt, the free capacitance C + the motional charge per volt at
    f1/100, and the tip velocity per motional current (Jayaram et al. 2018's alpha, eq. 9)."""
    m = model.base
    f1 = model.f1
    out = {"first_frequency_hz": f1}
    fr, fa, _ = m.resonances(0.25 * f1, 4 * f1)
    if fr is not None:
        out["resonance_frequency_hz"] = fr
    if fa is not None:
        out["antiresonance_frequency_hz"] = fa
        out["coupling_factor"] = float(np.sqrt(max(0.0, 1 - (fr / fa) ** 2)))
    f = f1 / 100
    q, _ = m.solve(f)
    ss = m.small_signal
    out["quasi_static_tip_per_volt_m_per_v"] = float(abs(m.tip_row @ q))
    motional = float(np.real(ss.coupling @ (m.P.T @ q)))
    out["blocked_capacitance_f"] = ss.capacitance
    out["free_capacitance_f"] = ss.capacitance + motional
    out["velocity_per_motional_current_m_per_a_s"] = float(abs(m.tip_row @ q) / abs(motional))
    return out


def piezo_actuator(scene, fit: PiezoFit, data: PiezoData, given: Optional[Dict[str, tuple]] = None):
    """``scene.actuator`` with ``fit`` in it, each identified number's source naming the
    measurement(s) it came from, its 1-sigma and how; ``given`` drive parameters over the
    file's."""
    from .file_fit import scaled_actuator
    from .identify import noted, file_drive_rows
    act = scene.actuator
    drive = act.drive or _drive_name(act)
    rows = file_drive_rows(act, drive, given or {})
    used = ", ".join(f"{k} {data.sources.get(k, '')}".strip() for k in data.given())
    cls_params = _drive_params(scene)

    def how(p):
        sd = fit.std.get(p)
        unc = "exactly determined: the measurement's own uncertainty carries over" if sd is None else \
            f"relative 1-sigma {sd / fit.values[p]:.2g}, residual correlation counted"
        return f"identified from {used} (mjeap identify piezo, the file's small-signal model fitted; {unc})"

    v = fit.values
    new = scaled_actuator(act, stiffness=v.get("stiffness", 1.0),
                          damping_ratio=v.get("damping_ratio"),
                          sources={"stiffness": f"{how('stiffness')}: EI(x) x {v.get('stiffness', 1.0):.6g}",
                                   "damping_ratio": how("damping_ratio")})
    if "tip_mass" in v:
        p = act.planform
        total = v["tip_mass"] * p.tip_block_mass
        src = f"{how('tip_mass')}: tip block {p.tip_block_mass:.6g} -> {total:.6g} kg"
        plan = dataclasses.replace(p, residual_tip_mass=total - p.extension_mass, residual_source=src) \
            if total >= p.extension_mass else \
            dataclasses.replace(p, extension_mass=total, residual_tip_mass=0.0, extension_source=src)
        new = dataclasses.replace(new, planform=plan)
    name = COUPLING_PARAMETER[drive]
    if drive == "piezo" and "coupling" in v:      # a laminate's coupling is each piezo layer's own d31
        new = _scaled_d31(new, v["coupling"], how("coupling"))
    for p, key, f in (("coupling", name, lambda x: x), ("capacitance", SCALES["capacitance"], lambda x: x),
                      ("conductance", SCALES["conductance"], lambda x: 1.0 / x)):
        if p in v and not (drive == "piezo" and p == "coupling"):
            old = rows[key][0] if key in rows else cls_params.get(key)
            if old is None:     # the laminate's own: its dielectric term (capacitance), no leakage (resistance)
                old = _laminate_default(scene, key)
            rows[key] = (float(old * f(v[p])), "", f"{how(p)}: x {f(v[p]):.6g} of {old:.6g}")
    new = dataclasses.replace(new, drive=drive, drive_parameters=rows, notes=noted(act, used, "piezo"))
    return new


def _scaled_d31(act, factor: float, how: str):
    """``act`` with every piezo layer's d31 times ``factor`` (the laminate's moment and motional
    coupling scale with it), each layer's d31 given in the file with its source."""
    import dataclasses
    from ..model.laminate import piezo_layers
    layers = list(act.layers)
    for p in piezo_layers(act):
        layer = layers[p.index]
        layers[p.index] = dataclasses.replace(layer, d31=float(p.d31 * factor), sources={
            **layer.sources, "d31": f"{how}: x {factor:.6g} of {p.d31:.6g} m/V"})
    return dataclasses.replace(act, layers=tuple(layers))


def _laminate_default(scene, key: str) -> float:
    """A laminate drive's parameter it derives when the file gives none: the dielectric
    (blocked) capacitance, F; a resistance: none (refused: the data cannot scale a leakage the
    file does not have)."""
    from ..drives import make_drive
    from ..errors import ParameterError
    if key == "capacitance":
        return float(make_drive(None, scene).capacitances()["blocked"][0])
    raise ParameterError("identify piezo", key, "a file with a resistance to scale (the data fitted a conductance "
                         "the laminate does not have: give [drive.parameters] resistance)")


def _drive_name(act) -> str:
    from ..drives import default_drive_name
    return default_drive_name(act)


def _drive_params(scene) -> Dict[str, float]:
    from ..drives import make_drive
    return dict(make_drive(None, scene).params)
