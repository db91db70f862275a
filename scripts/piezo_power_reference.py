#!/usr/bin/env python
"""Converged references of the piezo bimorphs' electrical power and motional-current phase
(trust issue, section 1): tests/golden/piezo_power.json, read by tests/drives/test_piezo_power.py.

Each case: the catalog actuator's default scene, a 20 V sine about V_bias / 2 = 100 V at
r x f_1 (rounded so that a period is a whole number of default steps), settled for
12 / (zeta_1 omega_1), then 4 periods sampled every step: the mean of V_eff x I_mech over
them and the lag of I_mech's fundamental behind V_eff's quadrature
(mjeap.analysis.frequency.driven_power). The reference runs at the default step / 32; the
same at / 16 shows its convergence (both written). CI runs only the default step.

    python scripts/piezo_power_reference.py            # about 5 minutes on 2 cores
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from mjeap import Scene  # noqa: E402
from mjeap.analysis.frequency import driven_power  # noqa: E402

ACTUATORS = ("pzt-hamr-large", "pzt-hamr-small", "pzt-robobee")
RATIOS = (0.1, 0.3, 0.5, 0.9, 1.0, 1.1, 1.5, 2.0)
FINE, CHECK = 32, 16
AMPLITUDE, OFFSET = 20.0, 100.0
OUT = Path(__file__).resolve().parent.parent / "tests" / "golden" / "piezo_power.json"


def frequency(scene: Scene, ratio: float) -> float:
    """r f_1 rounded to a whole number of the default scene's steps per period (Hz)."""
    return 1.0 / (round(1.0 / (ratio * scene.choice.first_frequency * scene.timestep)) * scene.timestep)


if __name__ == "__main__":
    import mujoco
    rows = []
    for a in ACTUATORS:
        s0 = Scene(a)
        for r in RATIOS:
            f = frequency(s0, r)
            fine, check = (driven_power(Scene(a, timestep=s0.timestep / k), f, AMPLITUDE, OFFSET) for k in (FINE, CHECK))
            rows.append({"actuator": a, "ratio": r, "frequency_hz": f, "default_timestep_s": s0.timestep,
                         "power_w": fine["power_w"], "lag_deg": fine["lag_deg"], "timestep_s": fine["timestep_s"],
                         f"power_w_at_step_over_{CHECK}": check["power_w"], f"lag_deg_at_step_over_{CHECK}": check["lag_deg"]})
            print(f"{a} r={r}: P={fine['power_w']:.6e} W (/{CHECK}: {check['power_w'] / fine['power_w'] - 1:+.2e}), "
                  f"lag {fine['lag_deg']:.4f} deg ({check['lag_deg'] - fine['lag_deg']:+.4f})", flush=True)
    from mjeap.io.outputs import write_text
    write_text(OUT, json.dumps({"what": __doc__.split("\n\n")[0], "mujoco": mujoco.__version__, "refinement": FINE,
                                "amplitude_v": AMPLITUDE, "offset_v": OFFSET, "cases": rows}, indent=1) + "\n",
               "reference file", picked=True)
    print(OUT)
