"""every shipped model file this MuJoCo loads (mjeap.assets.path: assets/mjcf, in seconds), as
a user plays it (mjeap.load_mjcf, MuJoCo's own stepping loop, one thread, its drive held off
rest): steps per second and simulated seconds per wall second (the real-time factor)."""
from __future__ import annotations


import mujoco
import numpy as np

from benchmarks.common import time_steps


def bench_models(min_seconds):
    """Every shipped model file this MuJoCo loads (mjeap.assets.path), as a user plays it
    (mjeap.load_mjcf: MuJoCo's own stepping loop, one thread), its drive held a tenth of its
    range off rest so that the beam moves: simulated seconds per wall second (the
    real-time factor; below 1 the file plays slower than real time in MuJoCo's viewer)."""
    from mjeap import load_mjcf
    from mjeap.assets import iter_assets, path
    from mjeap.errors import ParameterError
    from mjeap.model.fields import read_units
    rows = []
    for aid, rep in iter_assets():          # every shipped file ...
        try:
            f = path(aid, rep)              # ... that this MuJoCo loads
        except ParameterError:
            continue
        m = load_mjcf(f)
        d = mujoco.MjData(m)
        rest = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "rest")
        if rest >= 0:
            mujoco.mj_resetDataKeyframe(m, d, rest)
        if m.nu:
            lo, hi = m.actuator_ctrlrange[:, 0], m.actuator_ctrlrange[:, 1]
            d.ctrl[:] = np.clip(d.ctrl + 0.1 * (hi - lo), lo, hi)
        sps = time_steps(m, d, min_seconds)
        dt = m.opt.timestep * read_units(m).time
        rows.append({"file": f.name, "actuator": aid, "representation": rep, "nv": m.nv, "timestep_s": dt,
                     "steps_per_s": sps, "real_time_factor": sps * dt})
    return rows


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_models(args.min_seconds)
