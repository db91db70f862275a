"""Headless rollouts: a scene, a drive and a voltage waveform, stepped in lockstep.

Why an explicit loop and not MuJoCo's ``mjcb_control`` hook: the Python callback is one
global per process (two scenes, or a scene and a dm_control environment, would fight over
it) and it costs a C-to-Python call per step anyway. The loop below calls the drive, then
``mj_step``, once per step; the drive's cost per step is reported by ``scripts/bench.py``.
The waveform is evaluated for all steps up front (vectorised).
"""
from __future__ import annotations

import csv
import time as _time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Dict, Optional, Union

import mujoco
import numpy as np

from .analytical import arc_curvature
from .errors import DivergenceError, check_positive
from .scene import Scene
from .waveforms import Waveform, parse_waveform

try:  # progress bars are optional
    from tqdm import tqdm
except ImportError:  # pragma: no cover
    tqdm = None

#: at most this many samples are kept per rollout unless sample_interval is given
DEFAULT_SAMPLES = 5000
#: runs of more steps than this show a progress bar (when progress is None)
PROGRESS_STEPS = 200_000


@dataclass
class RolloutResult:
    """Sampled SI arrays of a rollout. Positions are in the clamp frame (x along the
    undeformed beam, y the deflection, z out of the bending plane). Sample i is the state
    after step k; its voltage is the one held over that step (zero-order hold), the same
    instant the drive signals describe."""

    time: np.ndarray                 # (n,) s
    voltage: np.ndarray              # (n,) V
    tip_position: np.ndarray         # (n, 3) m
    tip_angle: np.ndarray            # (n,) rad
    tip_curvature: np.ndarray        # (n,) 1/m, arc through clamp and tip (seed 000)
    centreline: np.ndarray           # (n, N + 2, 3) m
    payload_position: Optional[np.ndarray]
    signals: Dict[str, np.ndarray]   # drive quantities, 'name (unit)'
    reference_curvature: Optional[np.ndarray]
    meta: dict = field(default_factory=dict)

    def peak_to_peak(self, key: str = "tip_curvature", t_from: float = 0.0) -> float:
        y = getattr(self, key) if hasattr(self, key) else self.signals[key]
        sel = self.time >= t_from
        return float(np.max(y[sel]) - np.min(y[sel]))

    def to_csv(self, path: Union[str, Path]) -> None:
        """Time series (no centreline) as CSV with SI units in the header."""
        cols = {"time (s)": self.time, "voltage (V)": self.voltage,
                "tip_x (m)": self.tip_position[:, 0], "tip_y (m)": self.tip_position[:, 1],
                "tip_z (m)": self.tip_position[:, 2], "tip_angle (rad)": self.tip_angle,
                "tip_curvature (1/m)": self.tip_curvature, **self.signals}
        if self.reference_curvature is not None:
            cols["reference_curvature (1/m)"] = self.reference_curvature
        Path(path).parent.mkdir(parents=True, exist_ok=True)
        with open(path, "w", newline="") as fh:
            w = csv.writer(fh)
            w.writerow(cols)
            w.writerows(np.column_stack([np.asarray(c, dtype=float) for c in cols.values()]))


def rollout(scene: Scene, voltage: Union[str, Waveform, callable], duration: float,
            drive: Union[str, "object", None] = None, drive_params: Optional[dict] = None,
            initial_curvature: float = 0.0, rrd: Union[str, Path, None] = None,
            csv_path: Union[str, Path, None] = None, sample_interval: Optional[float] = None,
            progress: Optional[bool] = None, check_every: int = 100, controller=None) -> RolloutResult:
    """Run ``scene`` driven by ``drive`` (name, instance or None for the actuator's own)
    with ``voltage`` (waveform text, :class:`Waveform` or callable v(t)) for ``duration`` s.

    The beam starts at rest as a uniform arc of ``initial_curvature`` (1/m). Returns SI
    arrays sampled every ``sample_interval`` s (default: at most 5000 samples). With
    ``rrd`` a Rerun recording is written (also when the run fails: it then ends with the
    error), with ``csv_path`` the time series as CSV. A diverging run raises
    :class:`DivergenceError` naming the step, the drive and the timestep.
    """
    from .drives import make_drive
    from . import recording

    duration = check_positive("duration", duration, "s")
    wave = None if controller is not None else \
        parse_waveform(voltage) if isinstance(voltage, (str, Waveform)) else voltage
    if isinstance(wave, Waveform):
        wave = wave.with_duration(duration)
    drv = drive if (drive is not None and not isinstance(drive, str)) else \
        make_drive(drive, scene, **(drive_params or {}))
    dt = scene.timestep
    n_steps = max(1, int(round(duration / dt)))
    t_steps = np.arange(n_steps) * dt
    v_steps = np.zeros(n_steps) if wave is None else np.asarray(wave(t_steps), dtype=float) * np.ones(n_steps)
    drv.check_voltage(v_steps)
    every = max(1, int(round(sample_interval / dt))) if sample_interval else max(1, n_steps // DEFAULT_SAMPLES)
    sample_steps = np.arange(0, n_steps + 1, every)
    ns = len(sample_steps)

    scene.reset(curvature=initial_curvature)
    drv.reset(initial_curvature)
    ctrl_every, v_lo, v_hi, saturated, v_hold = n_steps + 1, *drv.voltage_range(), 0, 0.0
    if controller is not None:
        controller.reset(scene, drv)
        ctrl_every = max(1, int(round(getattr(controller, "interval", dt) / dt)))
        ctrl_name = getattr(controller, "name", type(controller).__name__)
    N = scene.layout.segments
    out_t, out_v = np.empty(ns), np.empty(ns)
    tip, ang, kap = np.empty((ns, 3)), np.empty(ns), np.empty(ns)
    cl = np.empty((ns, N + 2, 3))
    pay = np.empty((ns, 3)) if scene.payload is not None else None
    sig: Dict[str, np.ndarray] = {}

    def sample(i, step):
        scene.update_kinematics()
        out_t[i] = step * dt
        # the voltage held over the step that ended at this sample (the first sample: the
        # first step's), the same convention as the drive signals read now
        out_v[i] = v_hold if controller is not None else v_steps[max(step - 1, 0)]
        cl[i] = scene.centreline()
        tip[i] = cl[i, -1]                      # the centreline ends at the tip point
        ang[i] = scene.tip_angle()
        kap[i] = arc_curvature(tip[i, 0], tip[i, 1])
        if pay is not None:
            pay[i] = scene.payload_position()
        for k, v in drv.signals().items():
            if k not in sig:
                sig[k] = np.full(ns, np.nan)
            sig[k][i] = v
        if controller is not None and hasattr(controller, "signals"):
            for k, v in controller.signals().items():
                k = f"controller_{k}"
                if k not in sig:
                    sig[k] = np.full(ns, np.nan)
                sig[k][i] = v

    meta = {"actuator": scene.actuator.id, "drive": drv.describe(), "voltage": "closed loop" if wave is None else getattr(wave, "text", str(wave)),
            "duration_s": duration, "initial_curvature_per_m": initial_curvature, "steps": n_steps,
            "scene": scene.summary(), "drive_parameters": {k: [v, drv.sources.get(k, "")] for k, v in drv.params.items()}}
    show = (n_steps > PROGRESS_STEPS) if progress is None else progress
    bar = tqdm(total=n_steps, unit="step", desc=f"{scene.actuator.id} {drv.name}", disable=not show,
               leave=False) if tqdm else None
    m, d = scene.model, scene.data
    step_fn = mujoco.mj_step
    i_sample, error = 0, None
    wall0 = _time.perf_counter()
    try:
        sample(0, 0)
        i_sample = 1
        nxt = sample_steps[1] if ns > 1 else n_steps + 1
        for k in range(n_steps):
            if controller is not None:
                if k % ctrl_every == 0:
                    scene.update_kinematics()
                    u = float(controller(k * dt, scene))
                    v_hold = min(max(u, v_lo), v_hi)
                    saturated += v_hold != u
                v_steps[k] = v_hold
            drv.step(v_steps[k], dt)
            step_fn(m, d)
            if (k + 1) % check_every == 0 or k + 1 == nxt:
                try:
                    scene._step_count = k + 1
                    scene.check_finite()
                except DivergenceError as e:
                    who = f" Controller: {ctrl_name} (check its gains)." if controller is not None else ""
                    raise DivergenceError(f"{e} Drive: {drv.describe()}, voltage {v_steps[k]:.4g} V.{who}") from None
            if k + 1 == nxt:
                sample(i_sample, k + 1)
                i_sample += 1
                nxt = sample_steps[i_sample] if i_sample < ns else n_steps + 1
                if bar is not None:
                    bar.update(every)
    except BaseException as e:  # record what was simulated, then re-raise
        error = e
        raise
    finally:
        if bar is not None:
            bar.close()
        meta["wall_time_s"] = _time.perf_counter() - wall0
        if controller is not None:
            meta["controller"] = ctrl_name
            meta["saturated_updates"] = int(saturated)
            if saturated:
                meta.setdefault("warnings", []).append(
                    f"{ctrl_name}: {saturated} voltage commands clipped to the safe range [{v_lo:g}, {v_hi:g}] V "
                    "(reference beyond reach or gains too high)")
        n_ok = i_sample
        ref = None
        if n_ok > 1:
            ref = drv.reference_curvature(out_t[:n_ok], out_v[:n_ok], initial_curvature)
        result = RolloutResult(out_t[:n_ok], out_v[:n_ok], tip[:n_ok], ang[:n_ok], kap[:n_ok], cl[:n_ok],
                               None if pay is None else pay[:n_ok], {k: v[:n_ok] for k, v in sig.items()},
                               ref, meta)
        if error is not None:
            meta["error"] = f"{type(error).__name__}: {error}"
        if rrd is not None:
            recording.write_recording(rrd, result, scene)
        if csv_path is not None and n_ok > 0:
            result.to_csv(csv_path)
    return result
