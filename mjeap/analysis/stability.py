"""Stability of Dadras et al. 2021's inverted actuator under a payload: the theory boundaries of a
payload x amplitude map and the simulated edge read off a sweep.

The beam stands up (clamp below), the payload sits at l_e past the clamp on a rigid arm
beyond the beam's end (L = 6 mm, l_e = 6.27 mm). Theory is amplitude independent: the
Euler column with the payload on the arm (k a tan(kL) = 1, :func:`analytical.critical_load_with_arm`)
with the instantaneous EI of eq. 8 and with its relaxed (DC) EI, x pole/zero = 0.3/0.52,
and the paper's own Region 3 model's marginal mass. Dadras et al. 2021's criterion for a point:
the tip curvature still changes sign in the third period of the square wave.

The map itself (its sweep, report, figure and recording) is :mod:`mjeap.stability_map`.
"""
from __future__ import annotations

from typing import Dict, Sequence

import numpy as np

from ..model import analytical as an

#: the sweep base of Dadras et al. 2021's map: standing up, payload at l_e, 0.1 Hz square wave, 30 s
#: (three periods)
MAP_BASE = dict(actuator="pedot-micro", orientation="up", payload_position=6.27e-3, waveform="square",
                frequency=0.1, duration=30.0)


def column_limits(l_e: float = 6.27e-3, length: float = 6e-3) -> Dict[str, float]:
    """Payload masses (kg) of the theory boundaries, by name."""
    model = an.DadrasModel()
    ei, g = 1.0 / model.mechanical_gain, model.gravity
    p_arm = an.critical_load_with_arm(length, ei, l_e - length)
    return {"column, instantaneous EI": p_arm / g,
            "column, relaxed EI (static limit)": model.pole / model.zero * p_arm / g,
            "paper's Region 3 model (marginal)": model.marginal_mass(l_e)}


def simulated_edges(mass: Sequence[float], amplitude: Sequence[float], returns: Sequence[bool]) -> Dict[float, float]:
    """Per amplitude: the mass midway between the heaviest returning point and the lightest
    heavier one that does not return (NaN where the sweep does not bracket the edge)."""
    m, v, ok = np.asarray(mass, float), np.asarray(amplitude, float), np.asarray(returns, bool)
    edges = {}
    for amp in np.unique(v):
        sel = v == amp
        good, bad = m[sel & ok], m[sel & ~ok]
        above = bad[bad > good.max()] if good.size else bad
        edges[float(amp)] = 0.5 * (good.max() + above.min()) if good.size and above.size else float("nan")
    return edges
