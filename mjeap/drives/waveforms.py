"""Voltage waveforms v(t) (SI: V, s), vectorised, and their short CLI spelling.

Grammar: ``KIND:AMPLITUDE[@FREQUENCY][,key=value...]``, e.g. ``step:3V``,
``square:1.5V@0.1Hz``, ``sine:25V@100Hz,offset=50V``, ``triangle:1V@0.5Hz``,
``chirp:25V@1Hz..2000Hz,offset=25V`` (sweeps over the rollout's duration unless
``duration=`` is given), ``csv:path/to/file.csv`` (columns time, voltage; linear
interpolation, held constant outside the samples). Keys: offset (V), duty (0..1, square),
phase (rad), delay (s).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, Dict, Optional

import numpy as np

from ..model.discretize import parse_quantity
from ..errors import ParameterError, UnknownNameError, check_positive, check_range


@dataclass(frozen=True)
class Waveform:
    """A voltage signal; call it with times (s) to get volts."""

    kind: str
    amplitude: float = 0.0
    frequency: float = 0.0
    offset: float = 0.0
    duty: float = 0.5
    phase: float = 0.0
    delay: float = 0.0
    frequency_end: float = 0.0
    duration: Optional[float] = None
    samples: Optional[tuple] = None  # (t, v) arrays for 'csv'
    text: str = ""

    def __call__(self, t) -> np.ndarray:
        t = np.asarray(t, dtype=float) - self.delay
        on = t >= 0
        a, f = self.amplitude, self.frequency
        if self.kind == "step":
            v = np.where(on, a, 0.0)
        elif self.kind == "square":
            frac = np.mod(f * t + self.phase / (2 * np.pi), 1.0)
            v = np.where(on, np.where(frac < self.duty, a, -a), 0.0)
        elif self.kind == "sine":
            v = np.where(on, a * np.sin(2 * np.pi * f * t + self.phase), 0.0)
        elif self.kind == "triangle":
            frac = np.mod(f * t + self.phase / (2 * np.pi) + 0.25, 1.0)
            v = np.where(on, a * (4 * np.abs(frac - 0.5) - 1) * -1, 0.0)
        elif self.kind == "chirp":
            T = self.duration
            k = (self.frequency_end - f) / T
            ph = 2 * np.pi * (f * t + 0.5 * k * t * t)
            v = np.where(on & (t <= T), a * np.sin(ph + self.phase), 0.0)
        elif self.kind == "csv":
            ts, vs = self.samples
            return np.interp(t + self.delay, ts, vs)
        else:  # pragma: no cover - kinds are checked on construction
            raise UnknownNameError("waveform", self.kind, WAVEFORMS)
        return v + self.offset

    def with_duration(self, duration: float) -> "Waveform":
        """A chirp without its own duration sweeps over the rollout's duration."""
        if self.kind == "chirp" and self.duration is None:
            return Waveform(**{**self.__dict__, "duration": duration})
        return self

    @property
    def max_frequency(self) -> float:
        return max(self.frequency, self.frequency_end)

    def content_above(self, f_cut: float) -> float:
        """Fraction of the signal's (non-constant) energy above ``f_cut`` (Hz) for ``csv``
        samples (linear interpolation on their finest spacing, scipy-free rfft); for the
        analytic kinds 1 where the fundamental (a chirp's end) reaches ``f_cut``, else 0."""
        if self.kind != "csv":
            return 1.0 if self.max_frequency >= f_cut else 0.0
        ts, vs = self.samples
        dt = float(np.min(np.diff(ts)))
        n = int(min((ts[-1] - ts[0]) / dt + 1, 2**22))
        grid = np.linspace(ts[0], ts[-1], n)
        spec = np.abs(np.fft.rfft(np.interp(grid, ts, vs) - np.mean(vs))) ** 2
        f = np.fft.rfftfreq(n, (ts[-1] - ts[0]) / max(n - 1, 1))
        total = spec.sum()
        return float(spec[f >= f_cut].sum() / total) if total > 0 else 0.0


def _csv_samples(path: str) -> tuple:
    """(time s, voltage V) of a ``csv:`` waveform: the columns named time (or t, t_s) and
    voltage (or v, v_v), each in the unit its header gives, ``time (ms)``, ``voltage (mV)``
    (:func:`mjeap.model.quantity.column_scale`; none: SI; an unknown one refused)."""
    from ..io.csvio import read_rows
    from ..model.quantity import column_scale, split_header
    rows = read_rows(path, "csv")
    if len(rows) < 3:
        raise ParameterError("csv", path, "a CSV file with a header and at least 2 rows")
    names = [split_header(h)[0].strip().lower() for h in rows[0]]
    try:
        it = next(i for i, h in enumerate(names) if h.startswith("time") or h in ("t", "t_s"))
        iv = next(i for i, h in enumerate(names) if h.startswith("voltage") or h in ("v", "v_v"))
    except StopIteration:
        raise ParameterError("csv", path, f"columns 'time' and 'voltage' (found {rows[0]})") from None
    scale = np.array([column_scale(rows[0][it].strip(), "s", path), column_scale(rows[0][iv].strip(), "V", path)])
    try:
        data = np.array([[float(r[it]), float(r[iv])] for r in rows[1:] if r], dtype=float) * scale
    except (ValueError, IndexError) as e:
        raise ParameterError("csv", path, f"numbers in every row ({e})") from None
    if len(data) < 2:
        raise ParameterError("csv", path, "at least 2 samples")
    if not np.all(np.isfinite(data)):
        bad = int(np.argmax(~np.all(np.isfinite(data), axis=1))) + 2
        raise ParameterError("csv", path, f"finite numbers only (NaN or inf on line {bad})")
    if np.any(np.diff(data[:, 0]) <= 0):
        raise ParameterError("csv", path, "strictly increasing time")
    return data[:, 0].copy(), data[:, 1].copy()


WAVEFORMS: Dict[str, str] = {
    "step": "step:AMPLITUDE", "square": "square:AMPLITUDE@FREQ[,duty=,offset=]",
    "sine": "sine:AMPLITUDE@FREQ[,offset=,phase=]", "triangle": "triangle:AMPLITUDE@FREQ",
    "chirp": "chirp:AMPLITUDE@F0..F1[,duration=]", "csv": "csv:PATH",
}


def parse_waveform(text: str) -> Waveform:
    """Parse the CLI spelling (see module docstring) into a :class:`Waveform`."""
    if isinstance(text, Waveform):
        return text
    s = str(text).strip()
    kind, _, rest = s.partition(":")
    kind = kind.strip().lower()
    if kind not in WAVEFORMS:
        raise UnknownNameError("waveform", kind, WAVEFORMS)
    if kind == "csv":
        t, v = _csv_samples(rest.strip())
        return Waveform("csv", samples=(t, v), text=s)
    main, *opts = [p.strip() for p in rest.split(",")]
    amp, _, freq = main.partition("@")
    kw = dict(kind=kind, text=s, amplitude=parse_quantity(amp, "V"))
    if kind != "step":
        if not freq:
            raise ParameterError("voltage", text, f"a frequency: {WAVEFORMS[kind]}")
        if kind == "chirp":
            f0, _, f1 = freq.partition("..")
            kw["frequency"] = check_positive("chirp start frequency", parse_quantity(f0, "Hz"), "Hz")
            kw["frequency_end"] = check_positive("chirp end frequency", parse_quantity(f1, "Hz"), "Hz")
        else:
            kw["frequency"] = check_positive("frequency", parse_quantity(freq, "Hz"), "Hz")
    for o in opts:
        key, _, val = o.partition("=")
        key = key.strip().lower()
        if key in ("duty", "phase"):
            try:
                num = float(val)
            except ValueError:
                raise ParameterError(f"voltage option {key}", val, "a number, e.g. "
                                     + ("duty=0.3" if key == "duty" else "phase=1.57 (rad)")) from None
        if key == "offset":
            kw["offset"] = parse_quantity(val, "V")
        elif key == "duty":
            kw["duty"] = check_range("duty", num, 0.0, 1.0, lo_open=True, hi_open=True)
        elif key == "phase":
            kw["phase"] = num
        elif key == "delay":
            kw["delay"] = parse_quantity(val, "s")
        elif key == "duration":
            kw["duration"] = check_positive("duration", parse_quantity(val, "s"), "s")
        else:
            raise ParameterError("voltage option", key, "one of offset, duty, phase, delay, duration")
    return Waveform(**kw)


def waveform_function(w) -> Callable[[np.ndarray], np.ndarray]:
    """Accept a Waveform, its text, or any callable v(t)."""
    if callable(w):
        return w
    return parse_waveform(w)
