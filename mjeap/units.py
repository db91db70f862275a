"""Internal unit systems: MuJoCo sees scaled numbers, users see SI.

MuJoCo rejects masses and inertias below 1e-15 and its tolerances are absolute, so a
35 um, 0.7 mg beam cannot be simulated in SI. A :class:`UnitSystem` fixes the SI size of
the internal length, mass and time units; every other unit derives from those three.
Conversions happen only at the API edge (model building and reading results).
"""
from __future__ import annotations

from dataclasses import dataclass

from .errors import check_positive


#: the constraint solver's tolerance as an acceleration (m/s^2): MuJoCo's default 1e-8 in the
#: (mm, mg, ms) units mjeap used first, so that a model in other units stops its solver at
#: the same physical residual (the rod's edge equalities moved by 1e-5 of the swing in
#: (mm, mg, s) with the bare 1e-8: scripts/unit_change_check.py)
SOLVER_TOLERANCE = 1e-5


@dataclass(frozen=True)
class UnitSystem:
    """Internal units as their size in SI: ``length`` in m, ``mass`` in kg, ``time`` in s."""

    length: float = 1e-3   # 1 mm
    mass: float = 1e-6     # 1 mg
    time: float = 1e-3     # 1 ms

    def __post_init__(self):
        for name in ("length", "mass", "time"):
            check_positive(f"UnitSystem.{name}", getattr(self, name))

    # derived units, SI size of one internal unit
    @property
    def velocity(self) -> float:
        return self.length / self.time

    @property
    def acceleration(self) -> float:
        return self.length / self.time**2

    @property
    def force(self) -> float:
        return self.mass * self.acceleration

    @property
    def moment(self) -> float:
        """Torque / bending moment unit (N m)."""
        return self.force * self.length

    @property
    def rotational_stiffness(self) -> float:
        """N m / rad."""
        return self.moment

    @property
    def rotational_damping(self) -> float:
        """N m s / rad."""
        return self.moment * self.time

    @property
    def inertia(self) -> float:
        """kg m^2."""
        return self.mass * self.length**2

    @property
    def pressure(self) -> float:
        """Pa (Young's modulus, stress)."""
        return self.force / self.length**2

    @property
    def flexural_rigidity(self) -> float:
        """EI, N m^2."""
        return self.force * self.length**2

    @property
    def solver_tolerance(self) -> float:
        """MuJoCo's ``opt.tolerance`` for :data:`SOLVER_TOLERANCE` (its solver stops on an
        acceleration residual in internal units, so the number depends on the units)."""
        return SOLVER_TOLERANCE / self.acceleration

    def describe(self) -> str:
        return f"length {self.length:g} m, mass {self.mass:g} kg, time {self.time:g} s"


#: Default internal units (mm, mg, ms): the PEDOT beam then has EI ~ 20, mass ~ 0.7,
#: a timestep ~ 0.1 and gravity ~ 0.01; the piezo bimorphs stay within 1e-3..1e6.
DEFAULT_UNITS = UnitSystem()

#: The units of the shipped models (assets/mjcf, ``mjeap mjcf``, ``mjeap view``): mm and mg
#: as :data:`DEFAULT_UNITS` (the same masses, inertias and lengths for MuJoCo's 1e-15 floor)
#: and the second, so that MuJoCo's own viewer plays physical time. The same runs as in
#: DEFAULT_UNITS within 3e-13 of the swing (hinge, cable and rod: scripts/unit_change_check.py).
REAL_TIME_UNITS = UnitSystem(time=1.0)
