"""``mjeap/GripperGrasp-v0``: the PEDOT micro-gripper (:mod:`mjeap.robots.gripper`) grasping
its 13.9 mg steel bead as a Gymnasium environment.

* Action: the two fingers' voltages (V, pedot-micro's safe range), left then right, held for
  ``control_interval`` s (default 10 ms, the gripper experiment's sample interval).
* The base is scripted as in the gripper's lift tries (:func:`mjeap.robots.gripper.grip`):
  from ``lift_at`` s (1 s) it rises by LIFT = 1 mm over LIFT_TIME = 0.5 s, then holds for
  ``hold`` s (0.5 s); the episode is ``lift_at`` + 0.5 + ``hold`` s long (truncated then).
* Observation (float64, SI, 10 values): time (s), the base's rise (m), the bead's rise above
  its start, its x and y (m, world), its vertical speed (m/s), the two fingers' grip forces
  (N, normal to the bead, pressing positive) and tip curvatures (1/m).
* Reward after each step: the bead's rise as a fraction of LIFT, clipped to [0, 1]: 0 until
  the lift, 1 for every step the bead is held at the top.
* ``terminated`` when the bead is dropped: it lags the base by more than DROPPED = 0.1 mm
  (the experiment's criterion), or on divergence.

Physics that decides the task (docs/robots/gripper.md): a bead is lifted at 1 s only above
0.884 V (the closed form's 2 mu F = m g: 0.868 V), since the ionic drive's grip grows with
its charge.
"""
from __future__ import annotations

from typing import Optional

import mujoco
import numpy as np

from ..errors import check_range
from ..robots.gripper.experiments import DROPPED, LIFT, LIFT_TIME
from ..robots.gripper.model import build
from .rendering import check_render_mode
from .system_env import SystemEnv

__all__ = ["GripperGraspEnv", "ENV_ID"]

ENV_ID = "mjeap/GripperGrasp-v0"


class GripperGraspEnv(SystemEnv):
    """The gripper's grasp-and-lift task (see the module text)."""

    def __init__(self, control_interval: float = 1e-2, lift_at: float = 1.0, hold: float = 0.5,
                 render_mode: Optional[str] = None, width: int = 480, height: int = 480):
        check_render_mode(render_mode)          # before the robot is built
        self.lift_at = check_range("lift_at", lift_at, 0.0, 600.0, "s")
        self.hold = check_range("hold", hold, 0.0, 600.0, "s")
        system = build()
        m = system.model
        self._servo = m.actuator("lift").id
        self._slide = int(m.jnt_qposadr[m.joint("lift").id])
        self._bead = m.body("bead").id
        self._bead_dof = int(m.jnt_dofadr[m.body_jntadr[self._bead]])
        self._z0 = float(m.body_pos[self._bead][2])
        self._links = [sorted(int(b) for b in p.link_ids) for p in system.parts]
        camera = mujoco.MjvCamera()             # on the fingers and the bead (host units: mm)
        camera.lookat[:] = [0.5 * float(m.body_pos[self._bead][0]), 0.0, 0.0]
        camera.distance, camera.elevation, camera.azimuth = 12.0, -35.0, 150.0
        super().__init__(system, control_interval, self.lift_at + LIFT_TIME + self.hold, render_mode, width, height,
                         camera)

    def base_target(self, t: float) -> float:
        """The base's scripted rise (m) at ``t`` s."""
        return float(np.clip((t - self.lift_at) / LIFT_TIME, 0.0, 1.0)) * LIFT

    def _before_step(self) -> None:
        self.system.data.ctrl[self._servo] = self.base_target(self.time) / self.system.units.length

    def _rises(self):
        d, u = self.system.data, self.system.units
        return float(d.qpos[self._slide]) * u.length, (float(d.xpos[self._bead][2]) - self._z0) * u.length

    def _observe(self) -> np.ndarray:
        sy, d, u = self.system, self.system.data, self.system.units
        base, bead = self._rises()
        fc = sy.contact_forces()
        # the bead pushes the left finger to -y and the right one to +y (gripper.grip's sign)
        grip = [-float(fc[self._links[0]].sum(axis=0)[1]), float(fc[self._links[1]].sum(axis=0)[1])]
        return np.array([self.time, base, bead, d.xpos[self._bead][0] * u.length, d.xpos[self._bead][1] * u.length,
                         d.qvel[self._bead_dof + 2] * u.length / u.time, *grip,
                         *[p.tip_curvature() for p in sy.parts]])

    def _reward(self) -> float:
        return float(np.clip(self._rises()[1] / LIFT, 0.0, 1.0))

    def _terminated(self) -> str:
        base, bead = self._rises()
        lag = base - bead
        return f"dropped: the bead lags the base by {lag * 1e3:.3g} mm > {DROPPED * 1e3:g} mm" if lag > DROPPED else ""
