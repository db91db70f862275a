"""Golden tip-curvature trajectories: one representative rollout per catalog actuator, kept
downsampled as small CSV files in ``tests/golden/`` and compared by ``tests/simulation/test_golden.py``.

After an intentional physics change, regenerate them and review the diff:

    python scripts/regenerate_golden.py && git diff --stat tests/golden
"""
from __future__ import annotations

from pathlib import Path
from typing import Dict, Tuple

import numpy as np

#: samples kept per trajectory
SAMPLES = 200
#: allowed deviation, as a fraction of the trajectory's range (see tests/simulation/test_golden.py)
RTOL = 1e-5

#: actuator id -> (scene keyword arguments, waveform, duration s, initial curvature 1/m, drive params)
SCENARIOS: Dict[str, Tuple[dict, str, float, float, dict]] = {
    "pedot-micro": ({"orientation": "up", "payload": "12.6mg@6.27mm"}, "square:1.5V@0.1Hz", 20.0, -303.0, {}),
    "ppy-trilayer": ({"segments": 16}, "square:1V@0.1Hz", 15.0, 0.0, {}),
    "pvdf-60": ({}, "step:700V", 0.5, 0.0, {}),
    "pvdf-60-half": ({}, "step:700V", 0.5, 0.0, {}),
    "pvdf-130": ({}, "step:1516V", 0.5, 0.0, {}),
    "pzt-hamr-large": ({}, "sine:50V@200Hz,offset=100V", 0.01, 0.0, {"bias": 200.0}),
    "pzt-hamr-small": ({}, "sine:50V@200Hz,offset=100V", 0.01, 0.0, {"bias": 200.0}),
    "pzt-robobee": ({}, "sine:50V@200Hz,offset=100V", 0.01, 0.0, {"bias": 200.0}),
}


#: where the golden files live
FOLDER = Path(__file__).resolve().parents[2] / "tests" / "golden"


def simulate(actuator_id: str, engine: str = "loop") -> Tuple[np.ndarray, np.ndarray]:
    """(time s, tip curvature 1/m) of the actuator's scenario, SAMPLES + 1 samples, on the
    lockstep loop (the reference every other engine is tested against) or ``engine``."""
    from ..simulation.rollout import rollout
    from ..simulation.scene import Scene
    kw, wave, duration, k0, params = SCENARIOS[actuator_id]
    scene = Scene(actuator_id, **kw)
    r = rollout(scene, wave, duration, drive_params=params, initial_curvature=k0, progress=False,
                sample_interval=duration / SAMPLES, engine=engine)
    return r.time, r.tip_curvature


def header(actuator_id: str) -> str:
    kw, wave, duration, k0, params = SCENARIOS[actuator_id]
    return (f"# {actuator_id}: scene {kw}, voltage {wave}, {duration:g} s, initial curvature {k0:g} 1/m, "
            f"drive parameters {params}\n# regenerate: python scripts/regenerate_golden.py\ntime (s),tip_curvature (1/m)")


def write(folder: Path) -> None:
    from ..io.outputs import replacing
    for a in SCENARIOS:
        t, k = simulate(a)
        with replacing(folder / f"{a}.csv", "folder", picked=True) as tmp:
            np.savetxt(tmp, np.column_stack([t, k]), fmt="%.9e", delimiter=",", header=header(a), comments="")


def read(folder: Path, actuator_id: str) -> Tuple[np.ndarray, np.ndarray]:
    d = np.loadtxt(folder / f"{actuator_id}.csv", delimiter=",", comments="#", skiprows=3)
    return d[:, 0], d[:, 1]
