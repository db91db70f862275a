"""mjeap: electroactive-polymer and piezoelectric bending actuators as MuJoCo scenes.

SI units at the API; MuJoCo runs in scaled internal units (see :mod:`mjeap.units`).
"""
import os as _os

# headless by default: mjeap never opens a window, and dm_control must not probe GLFW
_os.environ.setdefault("MUJOCO_GL", "disable")

from .errors import install_mujoco_warnings  # noqa: E402

install_mujoco_warnings()

from .errors import DivergenceError, MjeapError, ParameterError, UnknownNameError  # noqa: E402
from .units import DEFAULT_UNITS, UnitSystem  # noqa: E402
from .model import analytical  # noqa: E402
from .model.catalog import CATALOG, Actuator, Layer, Planform, get_actuator, actuator_ids  # noqa: E402
from .model.discretize import BeamLayout, Payload, discretize, parse_quantity  # noqa: E402
from .model.fields import load_mjcf  # noqa: E402
from .model.mjcf import REPRESENTATIONS, build_spec  # noqa: E402
from .drives import DRIVES, Drive, register_drive  # noqa: E402
from .drives.waveforms import Waveform, parse_waveform  # noqa: E402
from .simulation.scene import Scene  # noqa: E402
from .simulation.rollout import RolloutResult, free_vibration, rollout, rollout_batch  # noqa: E402
from .simulation.system import System, attach  # noqa: E402

from .versions import MJEAP_VERSION as __version__  # noqa: E402
__all__ = ["CATALOG", "Actuator", "Layer", "Planform", "get_actuator", "actuator_ids", "BeamLayout",
           "Payload", "discretize", "parse_quantity", "DivergenceError", "MjeapError", "ParameterError",
           "UnknownNameError", "REPRESENTATIONS", "build_spec", "Scene", "load_mjcf", "DEFAULT_UNITS",
           "UnitSystem", "analytical", "DRIVES", "Drive", "register_drive", "RolloutResult", "free_vibration", "rollout", "rollout_batch",
           "Waveform", "parse_waveform", "System", "attach"]

from .optimize import optimize  # noqa: E402  (design optimisation, mjeap.optimize)
__all__.append("optimize")
from .analysis.frf import frequency_response  # noqa: E402  (small-signal response, mjeap frf)
__all__.append("frequency_response")

import importlib.util as _util  # noqa: E402

if _util.find_spec("gymnasium") is not None:
    # the Gymnasium ids, as entry-point strings: no environment module is imported here
    from .envs.registration import register_envs as _register_envs
    _register_envs()


def __getattr__(name):
    """The environments at the top level, imported when first asked for (not by ``import
    mjeap``, nor by ``from mjeap import *``): ``mjeap.make_environment``
    (:mod:`mjeap.envs.environment`, the dm_env environments on any MuJoCo) and
    ``mjeap.CurvatureTrackingEnv`` (:mod:`mjeap.envs.gymnasium_env`, the optional gymnasium's;
    ``import mjeap`` registers every Gymnasium id, :mod:`mjeap.envs.registration`)."""
    if name == "make_environment":
        from .envs.environment import make_environment
        return make_environment
    if name == "CurvatureTrackingEnv":
        from .envs.gymnasium_env import CurvatureTrackingEnv
        return CurvatureTrackingEnv
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
