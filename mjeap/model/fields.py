"""The custom numeric fields of mjeap's model files, so that other tools can read them:
``mjeap_units`` (L M T: the SI size of one internal length, mass and time unit) and
``[PREFIX/]mjeap_dof_damping`` (per-dof damping MJCF cannot state, e.g. one per dof of a
ball joint); :func:`load_mjcf` loads a file with them applied."""
from __future__ import annotations

import os
import stat
from pathlib import Path
from typing import Optional

import mujoco
import numpy as np

from ..errors import ParameterError
from ..units import UnitSystem

__all__ = ["UNITS_FIELD", "DOF_DAMPING_FIELD", "add_units", "read_numeric", "read_units", "apply_dof_damping",
           "load_mjcf"]

UNITS_FIELD = "mjeap_units"
DOF_DAMPING_FIELD = "mjeap_dof_damping"


def add_units(spec: mujoco.MjSpec, units: UnitSystem) -> None:
    """Declare the internal units in the file: custom numeric ``mjeap_units`` = L M T (SI)."""
    for n in spec.numerics:
        if n.name == UNITS_FIELD:
            n.data = [units.length, units.mass, units.time]
            return
    spec.add_numeric(name=UNITS_FIELD, data=[units.length, units.mass, units.time])


def read_numeric(model: mujoco.MjModel, name: str, size: int, accepted: str,
                 positive: bool = False) -> Optional[np.ndarray]:
    """The values of the custom numeric ``name`` (None if the model has none), refused
    unless there are exactly ``size`` of them, finite and >= 0 (> 0 if ``positive``):
    MuJoCo keeps every numeric in one array, so a short field read at its length would
    run into the next one. ``accepted`` says what they are, for the message."""
    i = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_NUMERIC, name)
    if i < 0:
        return None
    a, n = int(model.numeric_adr[i]), int(model.numeric_size[i])
    v = np.array(model.numeric_data[a:a + n], dtype=float)
    if n != size:
        raise ParameterError(name, f"{n} values", f"{size} values: {accepted}")
    bad = ~np.isfinite(v) | ((v <= 0) if positive else (v < 0))
    if bad.any():
        j = int(np.argmax(bad))
        raise ParameterError(name, f"{float(v[j])!r} at index {j}",
                             f"finite values {'> 0' if positive else '>= 0'}: {accepted}")
    return v


def read_units(model: mujoco.MjModel) -> Optional[UnitSystem]:
    """The unit system a model declares in ``mjeap_units`` (None if it declares none)."""
    v = read_numeric(model, UNITS_FIELD, 3, "L M T, the SI size of one internal length (m), mass (kg) "
                     "and time (s) unit", positive=True)
    return None if v is None else UnitSystem(*map(float, v))


def apply_dof_damping(model: mujoco.MjModel) -> mujoco.MjModel:
    """Apply the per-dof Rayleigh damping stored in a generated model (cable), in place:
    ``mjeap_dof_damping`` holds one value per dof of the model, ``PREFIX/mjeap_dof_damping``
    (a beam attached under ``PREFIX/``, :mod:`mjeap.simulation.system`) one per dof of the joints
    named ``PREFIX/...``, in dof order. Values that are not finite and >= 0, or not one per
    dof, are refused with the field named."""
    for i in range(model.nnumeric):
        name = mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_NUMERIC, i) or ""
        prefix = name[:-len(DOF_DAMPING_FIELD)]
        if not name.endswith(DOF_DAMPING_FIELD) or not (prefix == "" or prefix.endswith("/")):
            continue
        if prefix:
            joints = [j for j in range(model.njnt)
                      if (mujoco.mj_id2name(model, mujoco.mjtObj.mjOBJ_JOINT, j) or "").startswith(prefix)]
            dofs = np.flatnonzero(np.isin(model.dof_jntid, joints))
        else:
            dofs = np.arange(model.nv)
        model.dof_damping[dofs] = read_numeric(
            model, name, len(dofs), f"one damping per dof of {'the model' if not prefix else repr(prefix)} "
            "(internal units)")
    return model


def _regular(target: Path, path, why: str) -> None:
    """Refuse ``target`` where it exists and is not a regular file (a FIFO, a device, a
    folder): MuJoCo's reader would wait on it without end."""
    try:
        mode = os.stat(target).st_mode
    except OSError:
        return                           # missing: MuJoCo says so
    if not stat.S_ISREG(mode):
        kind = "a FIFO" if stat.S_ISFIFO(mode) else "a folder" if stat.S_ISDIR(mode) else "not a regular file"
        raise ParameterError("path", str(path), "an MJCF file whose includes are regular files", f"{why} {target} "
                             f"is {kind}")


def check_includes(path) -> None:
    """The MJCF file ``path`` and every file it ``<include>`` s (and they include, relative to
    the main file's folder or the including file's) are regular files, checked before MuJoCo
    reads them: a FIFO among them would hang MuJoCo's reader."""
    import xml.etree.ElementTree as ET
    main = Path(path)
    if not main.is_file():
        raise ParameterError("path", str(path), "an existing MJCF file (a regular file)")
    todo, seen = [main], set()
    while todo:
        f = todo.pop()
        if f in seen:
            continue
        seen.add(f)
        try:
            root = ET.parse(f).getroot()
        except (ET.ParseError, OSError):
            continue                     # MuJoCo's own error names the problem
        for inc in root.iter("include"):
            name = inc.get("file")
            if not name:
                continue
            for target in dict.fromkeys((main.parent / name, f.parent / name)):
                _regular(target, path, f"<include file={name!r}> in {f.name}:")
                if target.is_file():
                    todo.append(target)


def load_mjcf(path: str) -> mujoco.MjModel:
    """Load a model written by mjeap (``assets/mjcf``) with its per-dof damping applied; a
    file, or a file it includes, that is not a regular file (a FIFO would hang MuJoCo's
    reader) is refused first (:func:`check_includes`)."""
    check_includes(path)
    return apply_dof_damping(mujoco.MjModel.from_xml_path(str(path)))
