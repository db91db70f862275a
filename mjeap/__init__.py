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

from .studies.optimize import optimize  # noqa: E402  (design optimisation: the module is mjeap.studies.optimize)
__all__.append("optimize")
from .analysis.frf import frequency_response  # noqa: E402  (small-signal response, mjeap frf)
__all__.append("frequency_response")

import importlib as _importlib  # noqa: E402
import importlib.abc as _abc  # noqa: E402
import sys as _sys  # noqa: E402

#: the modules that moved, importable under their earlier names (documented aliases, the same
#: module objects): ``import mjeap.sweep`` is ``mjeap.studies.sweep``, ``mjeap.design`` is
#: ``mjeap.model.variants`` (the earlier ``mjeap.sweep.design`` is ``mjeap.studies.sweep.points``)
ALIASES = {"mjeap.sweep.design": "mjeap.studies.sweep.points", "mjeap.sweep": "mjeap.studies.sweep",
           "mjeap.design": "mjeap.model.variants"}


class _AliasLoader(_abc.Loader):
    """Imports an alias as the module it names (the same object, under both names)."""

    def create_module(self, spec):
        module = _importlib.import_module(ALIASES.get(spec.name) or
                                          ALIASES["mjeap.sweep"] + spec.name[len("mjeap.sweep"):])
        spec.loader_state = module.__spec__         # the import sets the alias's spec on it: put back below
        return module

    def exec_module(self, module):
        own = module.__spec__.loader_state
        module.__spec__, module.__loader__ = own, own.loader


class _AliasFinder(_abc.MetaPathFinder):
    """Finds the names of :data:`ALIASES` (and their submodules)."""

    def find_spec(self, fullname, path=None, target=None):
        if fullname in ALIASES or fullname.startswith("mjeap.sweep."):
            from importlib.machinery import ModuleSpec
            return ModuleSpec(fullname, _AliasLoader())
        return None


if not any(isinstance(f, _AliasFinder) for f in _sys.meta_path):
    _sys.meta_path.insert(0, _AliasFinder())

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
