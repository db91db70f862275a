"""The driven model file: a scene with its drive compiled in, as plain MuJoCo reads it
(``assets/mjcf``, ``mjeap mjcf``, ``mjeap view``): the actuator ``drive``'s ctrl is the
voltage (V), the internal units in the custom numeric ``mjeap_units``, a keyframe 'rest'
where the drive rests off 0 V, and what a viewer needs to see the bend."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Tuple

import mujoco

from ..drives import make_drive
from ..engines.native import why_not
from ..model.fields import add_units
from ..model.mjcf import FIXED_BENDING_FORCES

__all__ = ["ModelFile", "model_file", "add_viewing", "DRIVE_ACTUATOR"]

#: the name of the actuator whose ctrl is the drive voltage (V)
DRIVE_ACTUATOR = "drive"


@dataclass
class ModelFile:
    """``spec`` (internal units of the scene), ``note`` (how it was made, one paragraph),
    ``voltage_range`` (V, the ctrlrange of actuator 'drive'; None: a passive beam, the drive
    has no native form, ``why`` says why) and ``rest`` (V, the drive's rest voltage)."""

    spec: mujoco.MjSpec
    note: str
    voltage_range: Optional[Tuple[float, float]]
    rest: float = 0.0
    why: Optional[str] = None


def model_file(scene, drive=None, drive_params: Optional[dict] = None, how_to_view: str = "") -> ModelFile:
    """The scene's beam with ``drive`` (a name, None: the actuator's own) compiled in where
    the drive has a native form (:mod:`mjeap.drives.native`), else the passive beam."""
    drv = make_drive(drive, scene, **(drive_params or {}))
    why = why_not(scene, drv)
    if why is None:
        spec = scene.native_model(drv).spec.copy()
        lo, hi = drv.voltage_range()
        rest = drv.rest_voltage()
        if rest:
            spec.add_key(name="rest", ctrl=[rest])
        note = (f"Drive: {drv.describe()}, compiled in: the ctrl of actuator '{DRIVE_ACTUATOR}' is the voltage (V), "
                f"ctrlrange [{lo:g}, {hi:g}] V" + (f"; at rest at {rest:g} V (keyframe 'rest')" if rest else "")
                + "." + (" " + how_to_view if how_to_view else ""))
        out = ModelFile(spec, note, (float(lo), float(hi)), float(rest))
    else:
        spec = scene.spec.copy()
        add_units(spec, scene.units)
        engines = "loop or threaded engine" if scene.builder.has(FIXED_BENDING_FORCES) else "loop engine"
        out = ModelFile(spec, f"Passive beam: {why}. Drive it with mjeap ({engines}).", None, why=why)
    add_viewing(out.spec, scene)
    return out


def add_viewing(spec, scene) -> None:
    """What a viewer needs to see the bend (nothing that acts on the physics): the free
    camera looks down the hinge axis (the beam bends in its clamp's x-y plane, which the
    default view looks along), a key light, and a grid floor behind the beam that touches
    nothing (contype = conaffinity = 0)."""
    length = (scene.layout.length + scene.layout.extension_length) / scene.units.length
    width = float(max(scene.layout.link_width)) / scene.units.length
    g = spec.visual.global_
    g.azimuth, g.elevation = 90.0, -70.0
    spec.add_texture(name="grid", type=mujoco.mjtTexture.mjTEXTURE_2D, builtin=mujoco.mjtBuiltin.mjBUILTIN_CHECKER,
                     rgb1=[0.82, 0.84, 0.86], rgb2=[0.72, 0.74, 0.76], width=256, height=256,
                     mark=mujoco.mjtMark.mjMARK_EDGE, markrgb=[0.5, 0.5, 0.55])
    grid = spec.add_material(name="grid", texrepeat=[4, 4], texuniform=True, reflectance=0.0)
    grid.textures[mujoco.mjtTextureRole.mjTEXROLE_RGB] = "grid"
    spec.worldbody.add_geom(name="floor", type=mujoco.mjtGeom.mjGEOM_PLANE, material="grid",
                            size=[1.2 * length, 1.2 * length, length / 10], pos=[length / 2, 0, -width],
                            contype=0, conaffinity=0, group=2)
    spec.worldbody.add_light(name="key", pos=[length / 2, -length, 2 * length], dir=[0, 0.45, -0.9],
                             diffuse=[0.35, 0.35, 0.35])
