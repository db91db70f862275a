"""mjeap: electroactive-polymer and piezoelectric bending actuators as MuJoCo scenes.

SI units at the API; MuJoCo runs in scaled internal units (see :mod:`mjeap.units`).
"""
import os as _os
import sys as _sys

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

#: where the modules of mjeap's flat layout went (the layered packages): ``import mjeap.scene``
#: and the like keep working, as aliases of the modules themselves
MOVED = {"outputs": "io.outputs", "csvio": "io.csvio", "recording": "io.recording",
         "catalog": "model.catalog", "section": "model.section", "discretize": "model.discretize",
         "mjcf": "model.mjcf", "fields": "model.fields", "analytical": "model.analytical", "modes": "model.modes",
         "waveforms": "drives.waveforms", "native": "drives.native", "threaded": "engines.threaded",
         "scene": "simulation.scene", "component": "simulation.part", "system": "simulation.system",
         "accuracy": "simulation.accuracy", "rollout": "simulation.rollout",
         "native_model": "simulation.native_model", "frequency": "analysis.frequency",
         "identify": "analysis.identify", "calibration": "analysis.calibration", "stability": "analysis.stability"}


class _MovedModules:
    """Finds ``mjeap.<old name>`` as the module it moved to (:data:`MOVED`)."""

    @staticmethod
    def find_spec(name, path=None, target=None):
        import importlib.util
        old = name[len(__name__) + 1:] if name.startswith(__name__ + ".") else None
        if old not in MOVED:
            return None
        return importlib.util.spec_from_loader(name, _MovedModules)

    @staticmethod
    def create_module(spec):
        import importlib
        module = importlib.import_module(f"{__name__}.{MOVED[spec.name[len(__name__) + 1:]]}")
        spec.loader_state = module.__spec__
        return module

    @staticmethod
    def exec_module(module):
        module.__spec__ = module.__spec__.loader_state      # the import set the alias's spec: its own again


_sys.meta_path.append(_MovedModules)
# the function mjeap.rollout is not shadowed by the module of the same old name
_sys.modules[f"{__name__}.rollout"] = _sys.modules[f"{__name__}.simulation.rollout"]

from .versions import MJEAP_VERSION as __version__  # noqa: E402
__all__ = ["CATALOG", "Actuator", "Layer", "Planform", "get_actuator", "actuator_ids", "BeamLayout",
           "Payload", "discretize", "parse_quantity", "DivergenceError", "MjeapError", "ParameterError",
           "UnknownNameError", "REPRESENTATIONS", "build_spec", "Scene", "load_mjcf", "DEFAULT_UNITS",
           "UnitSystem", "analytical", "DRIVES", "Drive", "register_drive", "RolloutResult", "free_vibration", "rollout", "rollout_batch",
           "Waveform", "parse_waveform"]

from .optimize import optimize  # noqa: E402  (design optimisation, mjeap.optimize)
__all__.append("optimize")
