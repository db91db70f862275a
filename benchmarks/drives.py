"""cost of one drive step (us) for every drive on its actuator's 20-hinge beam."""
from __future__ import annotations

import time
from pathlib import Path


from mjeap import Scene


#: drives no catalog actuator uses, timed on an example file
EXAMPLE_ACTUATORS = {"piezo": "examples/actuators/laminate/pzt-hamr-small.toml"}


def bench_drives(n=20000):
    """Drive step cost (us), 20 hinges, the voltage alternating every step (worst case for
    drives that cache on it)."""
    from mjeap.drives import DRIVES, make_drive
    rows = []
    for name, cls in DRIVES.items():
        example = EXAMPLE_ACTUATORS.get(name)
        if not cls.actuators and example is None:   # a drive no actuator uses ('none'): nothing to time
            continue
        s = Scene(cls.actuators[0] if cls.actuators else str(Path(__file__).resolve().parent.parent / example))
        drv = make_drive(name, s)
        drv.reset(0.0)
        lo, hi = drv.voltage_range()
        v = (0.5 * (lo + hi) + 0.3 * (hi - lo), 0.5 * (lo + hi) + 0.2 * (hi - lo))
        for k in range(100):
            drv.step(v[k % 2], s.timestep)
        t0 = time.perf_counter()
        for k in range(n):
            drv.step(v[k % 2], s.timestep)
        rows.append({"drive": name, "actuator": s.actuator.id, "segments": s.layout.segments,
                     "step_us": (time.perf_counter() - t0) / n * 1e6,
                     "open_loop": drv.closed_loop_reason() is None})
    return rows


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_drives()
