"""MuJoCo's viewer on a scene, in physical time or slowed down (``mjeap view``).

What it shows is the driven model file (:mod:`mjeap.simulation.model_file`, in mm, mg and
the second): where the drive has a native form its voltage is the slider of actuator
'drive' in the viewer's control panel (V, the drive's range); a waveform (``voltage``)
plays through it instead, and drives without a native form play a waveform through mjeap's
own drive, stepped in lockstep; a System (a robot) shows one slider per actuator. The pacing keeps simulated time = wall time / slow motion
(:func:`steps_due`); a 100 Hz piezo needs a slow motion of ~100 to be seen."""
from __future__ import annotations

import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Callable, Optional, Tuple

import mujoco

from ..drives import make_drive
from ..drives.waveforms import waveform_function
from ..errors import MjeapError, ParameterError, check_positive
from ..model.fields import apply_dof_damping, load_mjcf, read_units
from ..units import REAL_TIME_UNITS, UnitSystem
from .model_file import DRIVE_ACTUATOR, model_file

__all__ = ["NoDisplayError", "display_reason", "window_reason", "ViewModel", "view_model", "file_view_model", "system_view_model",
           "steps_due", "view",
           "MAX_STEPS_PER_FRAME"]

#: the most steps between two frames: a slower machine falls behind (told at the end)
#: rather than freezing the window
MAX_STEPS_PER_FRAME = 20000


class NoDisplayError(MjeapError, RuntimeError):
    """No window can open here (no display, or MuJoCo's GL disabled)."""


def display_reason(environ=None, platform: str = sys.platform) -> Optional[str]:
    """None where MuJoCo's viewer can open a window; else why not. The viewer opens its
    window through GLFW whatever ``MUJOCO_GL`` says (that variable picks the off-screen
    renderer's GL, and mjeap sets it to 'disable' where unset); on Linux it needs an X11 or
    Wayland display."""
    env = os.environ if environ is None else environ
    if platform.startswith("linux") and not (env.get("DISPLAY") or env.get("WAYLAND_DISPLAY")):
        return "no display: neither DISPLAY nor WAYLAND_DISPLAY is set (the viewer opens a GLFW window)"
    return None


def window_reason() -> Optional[str]:
    """None where a viewer window opens here: a display (:func:`display_reason`) that GLFW
    can initialise (tried, then let go); else why not."""
    why = display_reason()
    if why is not None:
        return why
    try:
        import glfw
    except ImportError as e:
        return f"MuJoCo's viewer needs the glfw package ({e})"
    import warnings
    with warnings.catch_warnings(record=True) as said:
        warnings.simplefilter("always")
        ok = glfw.init()
    if not ok:
        return "GLFW cannot open the display" + (f": {said[-1].message}" if said else "")
    glfw.terminate()
    return None


@dataclass
class ViewModel:
    """What the viewer shows: ``model`` and ``data`` (in ``units``), the slider's
    ``voltage_range`` (V; None: no slider), ``voltage`` (a function v(t s) -> V, or None:
    the slider sets it), ``drive`` (mjeap's drive stepped in lockstep, or None: compiled
    in) and ``note`` (what is shown, one line)."""

    model: mujoco.MjModel
    data: mujoco.MjData
    units: UnitSystem
    voltage_range: Optional[Tuple[float, float]]
    voltage: Optional[Callable[[float], float]]
    drive: object
    note: str
    stepper: Optional[Callable[[int], None]] = None     # steps n (a System's own step); None: mj_step
    timestep: float = field(init=False)     # s

    def __post_init__(self):
        self.timestep = self.model.opt.timestep * self.units.time

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self.data.time * self.units.time

    def advance(self, nstep: int) -> None:
        """``nstep`` steps: the waveform's voltage (where one plays), then the step."""
        m, d = self.model, self.data
        if nstep <= 0:
            return
        if self.stepper is not None:
            self.stepper(nstep)
            return
        if self.voltage is None:            # the slider's voltage, held: MuJoCo steps alone
            mujoco.mj_step(m, d, nstep=nstep)
            return
        for _ in range(nstep):
            v = float(self.voltage(self.time))
            if self.drive is None:
                d.ctrl[0] = v
                mujoco.mj_step(m, d)
            else:
                self.drive.step(v, self.timestep)
                mujoco.mj_step(m, d)


def view_model(scene, drive=None, drive_params: Optional[dict] = None, voltage=None) -> ViewModel:
    """The view of a scene (built in :data:`REAL_TIME_UNITS`, see :func:`mjeap.Scene`):
    its driven model with the drive's voltage on a slider, or ``voltage`` (waveform text or
    v(t)) played through it; a drive without a native form needs ``voltage`` and is stepped
    by mjeap on the scene's own model."""
    f = model_file(scene, drive, drive_params)
    wave = None if voltage is None else waveform_function(voltage)
    if f.voltage_range is not None:
        model = apply_dof_damping(f.spec.compile())
        data = mujoco.MjData(model)
        rest = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_KEY, "rest")
        if rest >= 0:
            mujoco.mj_resetDataKeyframe(model, data, rest)
        lo, hi = f.voltage_range
        how = f"slider '{DRIVE_ACTUATOR}' in the control panel, {lo:g} to {hi:g} V" if wave is None else \
            f"the waveform {voltage}"
        return ViewModel(model, data, scene.units, f.voltage_range, wave, None,
                         f"{scene.actuator.id} ({scene.representation}), drive compiled in; voltage: {how}")
    if wave is None:
        raise ParameterError("voltage", None, "a waveform, e.g. 'square:1V@0.5Hz' (--voltage)",
                             f"{f.why}: no slider, mjeap steps this drive itself")
    drv = make_drive(drive, scene, **(drive_params or {}))
    scene.reset()
    drv.reset()
    return ViewModel(scene.model, scene.data, scene.units, None, wave, drv,
                     f"{scene.actuator.id} ({scene.representation}), {drv.name} drive stepped by mjeap; "
                     f"voltage: the waveform {voltage}")


def file_view_model(path, voltage=None) -> ViewModel:
    """The view of an MJCF file (its units from ``mjeap_units``, the second where absent);
    a slider where it has an actuator 'drive'."""
    model = load_mjcf(path)
    units = read_units(model) or UnitSystem(1.0, 1.0, 1.0)
    data = mujoco.MjData(model)
    a = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_ACTUATOR, DRIVE_ACTUATOR)
    rng = None if a < 0 else tuple(float(x) for x in model.actuator_ctrlrange[a])
    if voltage is not None and a != 0:
        raise ParameterError("voltage", voltage, "no waveform for this file",
                             "it has no actuator 'drive' as its first actuator")
    return ViewModel(model, data, units, rng, None if voltage is None else waveform_function(voltage), None,
                     f"{path}" + ("" if rng is None else f"; voltage: slider '{DRIVE_ACTUATOR}', {rng[0]:g} to "
                                  f"{rng[1]:g} V"))


def system_view_model(system, name: str = "system") -> ViewModel:
    """The view of a :class:`mjeap.System` (a robot): every actuator's voltage (V) on its own
    slider in the control panel (the actuators' ctrl), stepped by the system."""
    m = system.model
    sliders = ", ".join(f"'{m.actuator(i).name}' {m.actuator_ctrlrange[i, 0]:g} to {m.actuator_ctrlrange[i, 1]:g} V"
                        for i in range(m.nu))
    rng = None if m.nu == 0 else (float(m.actuator_ctrlrange[:, 0].min()), float(m.actuator_ctrlrange[:, 1].max()))
    return ViewModel(m, system.data, system.units, rng, None, None, f"{name}; voltages: sliders {sliders}",
                     stepper=system.step)


def steps_due(sim_time: float, wall_elapsed: float, slow_motion: float, timestep: float,
              max_steps: int = MAX_STEPS_PER_FRAME) -> int:
    """Steps of ``timestep`` s that bring the simulated time ``sim_time`` (s) up to
    ``wall_elapsed`` / ``slow_motion`` (s), at most ``max_steps``; never negative."""
    behind = wall_elapsed / slow_motion - sim_time
    return max(0, min(int(math.floor(behind / timestep + 1e-9)), int(max_steps)))


def view(vm: ViewModel, slow_motion: float = 1.0, duration: Optional[float] = None) -> dict:
    """Open MuJoCo's passive viewer on ``vm`` and step it paced to wall time / ``slow_motion``
    until the window closes (or ``duration`` s of simulated time); refused first where no
    window can open. Returns the simulated and wall time and how far the pacing fell behind."""
    check_positive("slow_motion", slow_motion)
    why = window_reason()
    if why is not None:
        raise NoDisplayError(f"mjeap view needs a display: {why}. The models it shows are files too: "
                             "mjeap mjcf NAME -o FILE, or mjeap.assets.path(NAME)")
    import mujoco.viewer
    lag = 0.0
    with mujoco.viewer.launch_passive(vm.model, vm.data) as handle:
        start = time.perf_counter()
        while handle.is_running() and (duration is None or vm.time < duration):
            with handle.lock():
                vm.advance(steps_due(vm.time, time.perf_counter() - start, slow_motion, vm.timestep))
            handle.sync()
            lag = max(lag, (time.perf_counter() - start) / slow_motion - vm.time)
            time.sleep(1 / 240)
    return {"simulated_s": vm.time, "wall_s": time.perf_counter() - start, "max_lag_s": lag}
