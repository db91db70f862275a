"""A scene's beam with its drive compiled in (:class:`NativeModel`), the model the native
engine (:mod:`mjeap.engines.native`) steps."""
from __future__ import annotations

import hashlib

import mujoco
import numpy as np

from .part import ActuatorPart
from ..caching import BoundedCache
from ..engines.native import why_not
from ..errors import ParameterError
from ..model.fields import add_units, apply_dof_damping
from ..model.modes import linearize, spectral_radius

__all__ = ["NativeModel"]

#: native models found stable, keyed on their content: a digest of the compiled model's
#: MJB bytes (every number MuJoCo steps with: timestep, masses, stiffness, damping, the
#: drive's elements) and the integrator. The same model built again (an accuracy target's
#: model at the next point of a sweep, another amplitude) skips the check, whose answer it
#: already has. Oldest dropped past STABLE_CACHE_SIZE
STABLE_CACHE_SIZE = 512
_STABLE = BoundedCache("stable native models", max_entries=STABLE_CACHE_SIZE, locked=True)


def _content_key(model: mujoco.MjModel, integrator: str) -> tuple:
    """A digest of ``model``'s MJB bytes, with ``integrator``: equal only for the same model."""
    buf = np.empty(mujoco.mj_sizeModel(model), np.uint8)
    mujoco.mj_saveModel(model, None, buf)
    return hashlib.blake2b(buf.tobytes(), digest_size=16).digest(), integrator


class NativeModel:
    """A scene's beam with its drive compiled in (internal units, the scene's timestep,
    damping and present hinge parameters): ``model``, ``data``, the actuator's ``part``
    (the scene's names, so the same read-outs) and the drive's ``handles``."""

    def __init__(self, scene, drive, check_stability: bool = True):
        why = why_not(scene, drive)
        if why is not None:
            raise ParameterError("engine", "native", f"'loop' or 'auto' for this run: {why}")
        spec = scene.spec.copy()
        # the hinges as built or set by hand (identify sets them), without a drive's present
        # stiffness scale (a run's leftover would otherwise be compiled in and cached)
        k, b = scene.part.built_hinge_parameters()
        for name, kj, bj in zip(scene.handles.joints, k, b):
            spec.joint(name).stiffness = [float(kj), 0.0, 0.0]
            spec.joint(name).damping = [float(bj), 0.0, 0.0]
        self.handles = drive.add_native(spec, scene.handles.joints, scene.handles.clamp_body)
        add_units(spec, scene.units)
        self.spec, self.drive, self.scene = spec, drive, scene
        self.model = apply_dof_damping(spec.compile())
        if check_stability:
            self.check_stability()
        self.data = mujoco.MjData(self.model)
        self.part = ActuatorPart(self.model, scene.handles, scene.layout, scene.actuator, scene.units,
                                 scene.representation, payload=scene.payload, rotation=scene.rotation)
        self.part.bind(self.data)
        self.actuator_id = mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_ACTUATOR, self.handles.actuator)

    def check_stability(self) -> None:
        """The scene chose its timestep for the bare beam; the drive's elements (Maxwell arms)
        must not make the linearised step map unstable at that timestep (a model already
        found stable, by its content, is not checked again)."""
        key = _content_key(self.model, self.scene.integrator)
        if _STABLE.get(key):
            return
        lin = linearize(self.model)
        rho = spectral_radius(lin, self.model.dof_damping, self.model.opt.timestep, self.scene.integrator)
        if rho > 1.0 + 1e-9:
            raise ParameterError("timestep", self.scene.timestep, "a timestep at which the native drive is stable",
                                 f"spectral radius {rho:.6g} of the native model's step map")
        _STABLE.put(key, True)

    def reset(self, initial_curvature: float = 0.0) -> None:
        """Rest at a uniform arc of ``initial_curvature`` (1/m), the drive state at rest there;
        the scene's tip loads act here too."""
        mujoco.mj_resetData(self.model, self.data)
        self.scene.part.carry_loads(self.part)
        lay = self.scene.layout
        if initial_curvature:
            self.part.set_hinge_angles(np.full(lay.segments, initial_curvature * lay.ds), forward=False)
        mujoco.mj_forward(self.model, self.data)
        self.drive.native_reset(self.part, self.handles)
