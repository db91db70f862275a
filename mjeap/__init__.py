"""mjeap: electroactive-polymer and piezoelectric bending actuators as MuJoCo scenes.

SI units at the API; MuJoCo runs in scaled internal units (see :mod:`mjeap.units`).
"""
import os as _os

# headless by default: mjeap never opens a window, and dm_control must not probe GLFW
_os.environ.setdefault("MUJOCO_GL", "disable")

def _mujoco_warning(message: str) -> None:
    """MuJoCo's warnings as Python warnings (not stderr and a MUJOCO_LOG.TXT in the working
    directory); its times are in the model's internal units (ms by default)."""
    import warnings
    warnings.warn(f"MuJoCo: {message.strip()} (times in the model's internal units; mjeap's default unit is "
                  "1 ms)", RuntimeWarning, stacklevel=2)


def install_mujoco_warnings() -> None:
    """Route MuJoCo's warnings through :func:`_mujoco_warning` (again after a library such
    as dm_control installed its own handler)."""
    import mujoco
    mujoco.set_mju_user_warning(_mujoco_warning)


install_mujoco_warnings()

from .catalog import CATALOG, Actuator, Layer, Planform, get_actuator, actuator_ids  # noqa: E402
from .discretize import BeamLayout, Payload, discretize, parse_quantity  # noqa: E402
from .errors import DivergenceError, MjeapError, ParameterError, UnknownNameError  # noqa: E402
from .mjcf import REPRESENTATIONS, build_spec  # noqa: E402
from .scene import Scene  # noqa: E402
from .fields import load_mjcf  # noqa: E402
from .units import DEFAULT_UNITS, UnitSystem  # noqa: E402
from . import analytical  # noqa: E402
from .drives import DRIVES, Drive, register_drive  # noqa: E402
from .rollout import RolloutResult, free_vibration, rollout, rollout_batch  # noqa: E402
from .waveforms import Waveform, parse_waveform  # noqa: E402

__version__ = "0.1.0"
__all__ = ["CATALOG", "Actuator", "Layer", "Planform", "get_actuator", "actuator_ids", "BeamLayout",
           "Payload", "discretize", "parse_quantity", "DivergenceError", "MjeapError", "ParameterError",
           "UnknownNameError", "REPRESENTATIONS", "build_spec", "Scene", "load_mjcf", "DEFAULT_UNITS",
           "UnitSystem", "analytical", "DRIVES", "Drive", "register_drive", "RolloutResult", "free_vibration", "rollout", "rollout_batch",
           "Waveform", "parse_waveform"]
