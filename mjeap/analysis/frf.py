"""Small-signal frequency response of an actuator about its drive's operating point: tip
deflection and electrical admittance per volt, from the linearised model.

The beam is the scene's own linearisation (:attr:`mjeap.Scene.linearization`, the MuJoCo
finite-difference mass and stiffness matrices ``first_frequency`` is computed from, gravity
included) with its Rayleigh damping D = beta diag(K_el) (the first mode's damping ratio,
:mod:`mjeap.simulation.scene`); the drive is its small-signal model
(:meth:`mjeap.drives.Drive.small_signal`: moment per volt, blocked admittance, motional
coupling, internal states). Per volt of the drive's input, at s = i omega::

    [ M s^2 + D s + K    -P G      ] [q]   [P b]
    [ -F P^T             s I - A   ] [x] = [ B ]

q the dofs, x the drive's states, P the hinge moments' generalised forces (one dof per hinge:
the hinge chain, the cable); the tip deflection is the tip's Jacobian times q and the
current g + s C + s c . P^T q + h . x. The beam is linearised about its reference
configuration as ``first_frequency`` is; the operating voltage sets the drive's
coefficients (an electrostrictive drive's dM/dV), the static bend it causes is not in the
beam's geometry (second order in the deflection).

Resonance and antiresonance are the admittance's first maximum and the minimum after it
(f_m and f_n of IEEE Std 176; the series and parallel resonances for light damping),
refined on the model itself; the effective coupling is k_eff = sqrt(1 - (f_r / f_a)^2).
"""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Optional

import mujoco
import numpy as np

from ..errors import ParameterError, check_integer, check_positive
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
optimize = lazy_module("scipy.optimize")

__all__ = ["FrequencyResponse", "SmallSignalModel", "frequency_response", "parse_frequency", "check_sweep", "sweep_limit",
           "write_frf", "plot_frf", "FRF_COLUMNS"]

#: the columns of frf.csv
FRF_COLUMNS = ("frequency (Hz)", "tip_per_volt (m/V)", "tip_phase (deg)", "admittance (S)", "admittance_phase (deg)")
#: samples per decade of the dense grid the resonances are searched on (then refined)
SEARCH_PER_DECADE = 2000
#: the most points a sweep may ask for
MAX_POINTS = 100_000


def parse_frequency(value, name: str = "frequency") -> float:
    """A frequency in Hz from a number (Hz) or text with a unit ('200Hz', '2 kHz'); refused
    unless finite and positive."""
    from ..model.quantity import to_si
    return check_positive(name, to_si(value, "Hz", name) if isinstance(value, str) else value, "Hz")


class SmallSignalModel:
    """A scene's linearised beam coupled to its drive's small-signal model about
    ``operating_voltage`` (V; default the drive's rest voltage). :meth:`tip` and
    :meth:`admittance` evaluate the response at any frequencies (Hz)."""

    def __init__(self, scene, drive=None, drive_params: Optional[dict] = None, operating_voltage: Optional[float] = None):
        from ..drives import Drive, make_drive
        part = scene.part
        if part.bend_dof is None:
            raise ParameterError("representation", scene.representation, "'hinge' or 'cable' (one dof per hinge)",
                                 "the frequency response applies the drive's moments to the hinges' dofs; the rod's "
                                 "bending has none")
        if scene.choice.buckled:
            raise ParameterError("orientation", scene.orientation, "a beam stable under its load",
                                 scene.buckled_warning() + "; a linear response has no steady state there")
        self.scene = scene
        self.drive = drive if isinstance(drive, Drive) else make_drive(drive, scene, **(drive_params or {}))
        v0 = self.drive.rest_voltage() if operating_voltage is None else float(operating_voltage)
        from ..drives.small_signal import SmallSignal
        self.small_signal = ss = self.drive.small_signal(v0)
        u, lin, n = scene.units, scene.linearization, scene.layout.segments
        if not isinstance(ss, SmallSignal) or ss.moment_per_volt.shape != (n,):
            raise ParameterError(f"drive {self.drive.name}", type(ss).__name__, f"a small_signal() that returns a "
                                 f"mjeap.drives.SmallSignal with one moment per volt for each of the {n} hinges")
        self.units = u
        self.M, self.K = lin.M, lin.K
        beta = scene.choice.rayleigh_beta / u.time
        self.D = np.diag(beta * np.clip(np.diag(lin.K_elastic), 0.0, None))
        nv = self.M.shape[0]
        self.P = np.zeros((nv, n))
        self.P[np.asarray(part.bend_dof), np.arange(n)] = 1.0
        self.tip_row = self._tip_row(scene)
        if not (np.any(ss.moment_per_volt) or (ss.states and np.any(ss.moment_from_state) and np.any(ss.state_input))):
            raise ParameterError("offset", v0, "an operating voltage at which the drive's moment changes with the "
                                 "voltage", f"the {self.drive.name} drive's moment per volt is zero at "
                                 f"V0 = {v0:g} V" + (f" ({ss.notes})" if ss.notes else ""))

    @staticmethod
    def _tip_row(scene) -> np.ndarray:
        """d(tip deflection, m, clamp frame y) / d(dof) at the reference configuration."""
        m, part = scene.model, scene.part
        d = mujoco.MjData(m)
        mujoco.mj_forward(m, d)
        jacp = np.zeros((3, m.nv))
        mujoco.mj_jacSite(m, d, jacp, None, part.tip_site_id)
        return part.clamp_frame(jacp.T)[:, 1]

    @property
    def operating_voltage(self) -> float:
        return self.small_signal.operating_voltage

    @property
    def carries_current(self) -> bool:
        return self.small_signal.current

    def solve(self, f: float):
        """(dofs q, drive states x) per volt at ``f`` Hz (q internal, x SI)."""
        ss, u = self.small_signal, self.units
        s = 2j * np.pi * f
        si = s * u.time
        Z = self.M * si * si + self.D * si + self.K
        k = ss.states
        if not k:
            q = np.linalg.solve(Z, self.P @ ss.moment_per_volt / u.moment)
            return q, np.zeros(0)
        nv = Z.shape[0]
        top = np.hstack([Z, -self.P @ ss.moment_from_state / u.moment])
        bottom = np.hstack([-ss.state_from_angles @ self.P.T, s * np.eye(k) - ss.state_matrix])
        rhs = np.r_[self.P @ ss.moment_per_volt / u.moment, ss.state_input]
        z = np.linalg.solve(np.vstack([top, bottom]).astype(complex), rhs.astype(complex))
        return z[:nv], z[nv:]

    def respond(self, frequencies) -> tuple:
        """(tip deflection per volt (m/V), admittance (S) or None), complex, at ``frequencies`` (Hz)."""
        f = np.atleast_1d(np.asarray(frequencies, dtype=float))
        ss = self.small_signal
        tip, y = np.empty(f.size, complex), np.empty(f.size, complex)
        for i, fi in enumerate(f):
            q, x = self.solve(fi)
            s = 2j * np.pi * fi
            tip[i] = self.tip_row @ q
            y[i] = ss.conductance + s * ss.capacitance + s * (ss.coupling @ (self.P.T @ q)) + ss.current_from_state @ x
        return tip, (y if ss.current else None)

    def tip(self, frequencies) -> np.ndarray:
        return self.respond(frequencies)[0]

    def admittance(self, frequencies) -> np.ndarray:
        """The current per volt (S); refused for a drive whose model draws none."""
        if not self.carries_current:
            raise ParameterError("admittance", self.drive.name, "a drive whose model draws a current",
                                 self.small_signal.no_current)
        return self.respond(frequencies)[1]

    def resonances(self, f_lo: float, f_hi: float) -> tuple:
        """(resonance, antiresonance) in Hz: the admittance's first maximum in [f_lo, f_hi]
        and its first minimum after it, each found on a dense grid and refined on the model
        (scipy.optimize.minimize_scalar); None where there is none in the range, with the
        reason as a third element ('' where both were found)."""
        if not self.carries_current:
            return None, None, self.small_signal.no_current
        n = max(64, int(SEARCH_PER_DECADE * np.log10(f_hi / f_lo)) + 1)
        grid = np.geomspace(f_lo, f_hi, n)
        mag = np.abs(self.admittance(grid))
        peaks = [i for i in range(1, n - 1) if mag[i] >= mag[i - 1] and mag[i] > mag[i + 1]]
        if not peaks:
            return None, None, (f"the admittance has no maximum between {f_lo:.4g} and {f_hi:.4g} Hz "
                                f"(no motional resonance of the {self.drive.name} drive's current there)")
        i = peaks[0]
        fr = self._refine(grid[i - 1], grid[i + 1], -1.0)
        dips = [j for j in range(i + 1, n - 1) if mag[j] <= mag[j - 1] and mag[j] < mag[j + 1]]
        if not dips:
            return fr, None, f"the admittance has no minimum between {fr:.4g} and {f_hi:.4g} Hz"
        j = dips[0]
        return fr, self._refine(grid[j - 1], grid[j + 1], 1.0), ""

    def _refine(self, a: float, b: float, sign: float) -> float:
        r = optimize.minimize_scalar(lambda lf: sign * abs(self.admittance(np.exp(lf))[0]),
                                     bounds=(np.log(a), np.log(b)), method="bounded", options={"xatol": 1e-10})
        return float(np.exp(r.x))


def sweep_limit(scene) -> tuple:
    """(the highest frequency (Hz) a frequency response of ``scene`` may reach, why): the
    lower of its highest resolved mode (the chain's highest discrete mode) and its step's
    Nyquist limit 1 / (2 dt)."""
    c = scene.choice
    nyquist = 0.5 / c.timestep
    mode = c.highest_frequency
    if nyquist <= mode:
        return nyquist, (f"the step's Nyquist limit 1/(2 dt) = {nyquist:.6g} Hz (timestep {c.timestep:.4g} s: "
                         f"{c.reason}; a smaller --timestep raises it)")
    return mode, (f"the model's highest resolved mode, {mode:.6g} Hz ({scene.layout.segments} segments; more "
                  "--segments raise it)")


@dataclass
class FrequencyResponse:
    """A frequency response per volt of the drive's input: ``tip_per_volt`` (m/V) and
    ``admittance`` (S, None where the drive's model draws no current: ``admittance_reason``
    says why), complex, at ``frequency`` (Hz); the resonance and antiresonance (Hz) found
    from the admittance and the effective coupling factor."""

    frequency: np.ndarray
    tip_per_volt: np.ndarray
    admittance: Optional[np.ndarray]
    resonance_frequency: Optional[float]
    antiresonance_frequency: Optional[float]
    admittance_reason: str = ""
    resonance_reason: str = ""
    meta: dict = field(default_factory=dict)

    @property
    def coupling_factor(self) -> Optional[float]:
        """k_eff = sqrt(1 - (f_r / f_a)^2), None without both."""
        fr, fa = self.resonance_frequency, self.antiresonance_frequency
        return None if fr is None or fa is None else float(np.sqrt(max(0.0, 1.0 - (fr / fa) ** 2)))

    def rows(self):
        """frf.csv's rows (:data:`FRF_COLUMNS`); the admittance cells empty without one."""
        for i, f in enumerate(self.frequency):
            t = self.tip_per_volt[i]
            a = None if self.admittance is None else self.admittance[i]
            yield [float(f), float(abs(t)), float(np.degrees(np.angle(t))),
                   None if a is None else float(abs(a)), None if a is None else float(np.degrees(np.angle(a)))]

    def summary(self) -> dict:
        return {**self.meta, "resonance_frequency_hz": self.resonance_frequency,
                "antiresonance_frequency_hz": self.antiresonance_frequency, "coupling_factor": self.coupling_factor,
                "resonance_note": self.resonance_reason or None, "admittance": self.admittance_reason or "computed",
                "quasi_static_tip_per_volt_m_per_v": float(abs(self.tip_per_volt[0]))}


def check_sweep(start, stop, points) -> tuple:
    """(start Hz, stop Hz, points) checked: frequencies in Hz or with a unit, start below stop,
    at least two points; a ParameterError naming --from, --to or --points."""
    f0, f1 = parse_frequency(start, "--from"), parse_frequency(stop, "--to")
    n = check_integer("--points", points, 2, MAX_POINTS, "a sweep needs at least two frequencies")
    if not f0 < f1:
        raise ParameterError("--from", f"{f0:g} Hz", f"a frequency below --to ({f1:g} Hz)")
    return f0, f1, n


def frequency_response(actuator, start, stop, points: int = 200, *, offset: Optional[float] = None, drive=None,
                       drive_params: Optional[dict] = None, **scene_args) -> FrequencyResponse:
    """The small-signal frequency response of ``actuator`` (catalog id, file, Actuator or a
    built :class:`~mjeap.Scene`) from ``start`` to ``stop`` (Hz, or text with a unit:
    '200Hz', '2kHz') at ``points`` log-spaced frequencies, per volt of its drive's input
    about ``offset`` (V; default the drive's rest voltage, V_bias/2 for piezo-bimorph).
    ``scene_args`` build the Scene (segments, payload, orientation, ...). Refused before any
    work: ``start`` not below ``stop``, fewer than 2 points, ``stop`` above the model's
    highest resolved mode or its step's Nyquist limit (:func:`sweep_limit`)."""
    from ..simulation.scene import Scene
    f0, f1, n = check_sweep(start, stop, points)
    if scene_args and isinstance(actuator, Scene):
        raise ParameterError("scene arguments", ", ".join(scene_args), "none with a built Scene (they build one)")
    scene = actuator if isinstance(actuator, Scene) else Scene(actuator, **scene_args)
    limit, why = sweep_limit(scene)
    if f1 > limit * (1 + 1e-12):
        raise ParameterError("--to", f"{f1:g} Hz", f"a frequency up to {limit:.6g} Hz", why)
    model = SmallSignalModel(scene, drive, drive_params, offset)
    freq = np.geomspace(f0, f1, n)
    tip, y = model.respond(freq)
    fr, fa, note = model.resonances(f0, f1)
    ss = model.small_signal
    c = scene.choice
    meta = {"actuator": scene.actuator.id, "actuator_file": scene.actuator.source_file, "drive": model.drive.name,
            "per_volt_of": ss.input_name, "operating_voltage_v": ss.operating_voltage,
            "representation": scene.representation, "segments": scene.layout.segments,
            "first_frequency_hz": c.first_frequency, "damping_ratio": c.damping_ratio,
            "limit_hz": limit, "limit": why, "model": "MuJoCo linearisation at the reference configuration (as "
            "first_frequency) with Rayleigh damping, coupled to the drive's small-signal model",
            "drive_model": ss.notes}
    return FrequencyResponse(freq, tip, y, fr, fa, "" if ss.current else ss.no_current, note, meta)


# ---------------------------------------------------------------- outputs
def write_frf(result: FrequencyResponse, csv_path) -> None:
    """frf.csv: :data:`FRF_COLUMNS`, the admittance cells empty where the drive's model
    draws no current (the reason is in :meth:`FrequencyResponse.summary`, which ``mjeap
    frf`` writes to frf.json); written whole or not at all
    (:func:`mjeap.io.outputs.replacing`)."""
    from ..io import csvio
    from ..io.outputs import replacing
    with replacing(csv_path, "--out (frf.csv)") as tmp:
        with open(tmp, "w", newline="", encoding="utf-8") as fh:
            w = csvio.writer(fh)
            w.writerow(FRF_COLUMNS)
            w.writerows(result.rows())


def plot_frf(result: FrequencyResponse, png_path) -> None:
    """frf.png: Bode plots (magnitude, phase) of the tip deflection and the admittance per
    volt, the resonance and antiresonance marked (needs the ``report`` extra, matplotlib)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from ..io.outputs import replacing
    f = result.frequency
    m = result.meta
    fig, ax = plt.subplots(2, 2, figsize=(11, 6.5), sharex=True)
    label = f"mjeap small-signal model ({m['representation']}, {m['segments']} segments)"
    ax[0, 0].loglog(f, np.abs(result.tip_per_volt), label=label)
    ax[0, 0].set_ylabel("tip deflection per volt (m/V)")
    ax[1, 0].semilogx(f, np.degrees(np.unwrap(np.angle(result.tip_per_volt))))
    ax[1, 0].set_ylabel("tip phase (deg)")
    if result.admittance is not None:
        ax[0, 1].loglog(f, np.abs(result.admittance), color="C1", label=label)
        ax[1, 1].semilogx(f, np.degrees(np.angle(result.admittance)), color="C1")
        for x, name, style in ((result.resonance_frequency, "resonance", "--"),
                               (result.antiresonance_frequency, "antiresonance", ":")):
            if x is not None:
                for a in ax[:, 1]:
                    a.axvline(x, color="k", ls=style, lw=0.8, label=f"{name} {x:.5g} Hz" if a is ax[0, 1] else None)
        ax[0, 1].legend(fontsize=8)
    else:
        for a in ax[:, 1]:
            a.text(0.5, 0.5, "no admittance:\n" + _wrap(result.admittance_reason), ha="center", va="center",
                   transform=a.transAxes, fontsize=8)
            a.set_yticks([])
    ax[0, 1].set_ylabel("admittance (S)")
    ax[1, 1].set_ylabel("admittance phase (deg)")
    for a in ax[1]:
        a.set_xlabel("frequency (Hz)")
    for a in ax.flat:
        a.grid(True, which="both", lw=0.3)
    ax[0, 0].legend(fontsize=8)
    k = result.coupling_factor
    fig.suptitle(f"{m['actuator']} ({m['drive']}): per volt of {m['per_volt_of']} about {m['operating_voltage_v']:g} V"
                 + (f"; k_eff = {k:.3f}" if k is not None else ""), fontsize=10)
    fig.tight_layout()
    with replacing(png_path, "--out (frf.png)") as tmp:
        fig.savefig(tmp, dpi=120, format="png")
    plt.close(fig)


def _wrap(text: str, width: int = 50) -> str:
    import textwrap
    return "\n".join(textwrap.wrap(text, width))
