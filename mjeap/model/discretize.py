"""Discretisation of a catalog beam into rigid segments and compliant hinges (SI).

Midpoint rule: with ds = L / N, hinge j sits at x_j = (j + 1/2) ds and carries the
compliance of the segment [j ds, (j + 1) ds] around it, k_j = EI(x_j) / ds. The half
segment next to the clamp is rigid (part of the clamp), links join consecutive hinges, and
the last link is half a segment long. Every part of the beam is represented by exactly one
hinge, so the tip rotation under a uniform moment is exact and deflections converge at
second order in 1/N (a hinge at the clamp with EI/ds over-counts the clamp half segment
and converges at first order only).
"""
from __future__ import annotations

from dataclasses import dataclass
import re
from typing import Optional, Tuple

import numpy as np

from .actuator import Actuator
from ..caching import BoundedCache
from ..errors import ParameterError, check_positive, check_range

#: density used for a payload whose size is not given: sintered NdFeB, as the magnets
#: of Dadras et al. 2021 (literature default, 7.5 g/cm^3)
PAYLOAD_DENSITY = 7500.0
#: how far past the tip a payload centre may sit, as a fraction of the beam length
MAX_PAYLOAD_OVERHANG = 0.25


@dataclass(frozen=True)
class Payload:
    """A rigid tip payload: ``mass`` (kg) centred ``position`` (m) from the clamp along the
    beam (Dadras et al. 2021's effective length l_e; it may sit on a rigid tip extension and overhang
    the tip by up to 25 % of L, a magnet stuck on the tip). Its rotary inertia about its
    centre (kg m^2): ``inertia`` if given (0 is a point mass, :meth:`point`), else that of a
    solid sphere of ``radius`` (m), by default an NdFeB sphere of the same mass.

    Gravity loads the payload in the bending plane only under the orientations ``up`` and
    ``down``: the default ``horizontal`` lays the bending plane horizontal (gravity across
    the width), so there a payload adds inertia, not a static bend (:func:`clamp_rotation`)."""

    mass: float
    position: float
    radius: Optional[float] = None
    rotary_inertia: Optional[float] = None

    def __post_init__(self):
        check_positive("payload.mass", self.mass, "kg")
        check_positive("payload.position", self.position, "m")
        if self.radius is not None:
            check_positive("payload.radius", self.radius, "m")
        if self.rotary_inertia is not None:
            check_range("payload.inertia", self.rotary_inertia, 0.0, np.inf, "kg m^2")
            if self.radius is not None:
                raise ParameterError("payload", f"radius={self.radius}, inertia={self.rotary_inertia}",
                                     "a radius or an inertia, not both")

    @classmethod
    def point(cls, mass: float, position: float) -> "Payload":
        """A point mass (kg) at ``position`` (m): no rotary inertia."""
        return cls(mass, position, rotary_inertia=0.0)

    @property
    def sphere_radius(self) -> float:
        """Radius (m) of the sphere drawn for it (and giving its inertia unless one is set)."""
        if self.radius is not None:
            return self.radius
        return (3 * self.mass / (4 * np.pi * PAYLOAD_DENSITY)) ** (1 / 3)

    @property
    def inertia(self) -> float:
        """Rotary inertia about its centre (kg m^2)."""
        if self.rotary_inertia is not None:
            return self.rotary_inertia
        return 0.4 * self.mass * self.sphere_radius**2

    @staticmethod
    def parse(text: str) -> "Payload":
        """Parse ``MASS@POSITION[,point|,r=RADIUS|,I=INERTIA]`` with units, e.g.
        ``12.6mg@6.27mm`` (NdFeB sphere), ``12.6mg@6.27mm,point`` (no rotary inertia),
        ``12.6mg@6.27mm,r=1mm`` or ``12.6mg@6.27mm,I=2e-12`` (kg m^2); SI if no unit."""
        usage = "MASS@POSITION[,point|,r=RADIUS|,I=INERTIA kg m^2], e.g. 12.6mg@6.27mm or 12.6mg@6.27mm,point"
        try:
            head, *opts = [t.strip() for t in text.split(",")]
            m, p = head.split("@")
            kw = {}
            for o in opts:
                if o == "point":
                    kw["rotary_inertia"] = 0.0
                elif o.startswith("r="):
                    kw["radius"] = parse_quantity(o[2:], "m")
                elif o.startswith("I="):
                    kw["rotary_inertia"] = float(o[2:])
                else:
                    raise ValueError(o)
            return Payload(parse_quantity(m, "kg"), parse_quantity(p, "m"), **kw)
        except ValueError as e:
            if isinstance(e, ParameterError):
                raise
            raise ParameterError("payload", text, usage) from None


_PREFIX = {"": 1.0, "k": 1e3, "M": 1e6, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "n": 1e-9}
_QUANTITY = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*([A-Za-zµ]*)\s*$")


def parse_quantity(text: str, unit: str) -> float:
    """Parse a number with an optional SI-prefixed unit into SI: ``parse_quantity('6.27mm', 'm')``
    is 6.27e-3. For ``unit='kg'`` grams with a prefix are accepted ('12.6mg'). A bare number
    is taken as SI."""
    m = _QUANTITY.match(str(text))
    if m is None:
        raise ParameterError("quantity", text, f"a number with an optional unit {unit!r}, e.g. '1.5{unit}'")
    value, suffix = float(m.group(1)), m.group(2)
    if not np.isfinite(value):
        raise ParameterError("quantity", text, f"a finite number (with unit {unit!r}); {m.group(1)} overflows")
    if suffix == "":
        return value
    base = {"kg": ("g", 1e-3)}.get(unit, (unit, 1.0))
    for name, factor in ((unit, 1.0), base):
        if suffix.endswith(name) and suffix[: len(suffix) - len(name)] in _PREFIX:
            pre = suffix[: len(suffix) - len(name)]
            if name == "kg" and pre:      # 'kg' takes no further prefix
                continue
            return value * _PREFIX[pre] * factor
    raise ParameterError("quantity", text, f"a number with unit {unit!r} (SI prefixes k, m, u, n allowed)")


@dataclass(frozen=True)
class BeamLayout:
    """Segments and hinges of a discretised beam, SI (m, kg, N m / rad)."""

    actuator_id: str
    length: float
    segments: int
    thickness: float
    hinge_x: np.ndarray          # (N,) hinge positions from the clamp
    hinge_stiffness: np.ndarray  # (N,) EI(x_j) / ds
    hinge_width: np.ndarray      # (N,) planform width at the hinge
    link_start: np.ndarray       # (N,) start of link j (= hinge_x[j])
    link_end: np.ndarray         # (N,) end of link j
    link_mass: np.ndarray        # (N,)
    link_com: np.ndarray         # (N,) centre of mass of link j from the clamp
    link_inertia: np.ndarray     # (N, 3) about the link's centre of mass, local (x, y, z)
    link_width: np.ndarray       # (N,) width at the link's centre
    extension_length: float
    extension_mass: float
    poisson_ratio: float

    @property
    def ds(self) -> float:
        return self.length / self.segments

    @property
    def tip_x(self) -> float:
        return self.length + self.extension_length

    def link_containing(self, x: float) -> int:
        """Index of the link whose span holds x (the last link holds everything beyond)."""
        j = int(np.searchsorted(self.link_start, x, side="right") - 1)
        return max(0, min(self.segments - 1, j))


def block_inertia(mass: float, length: float, thickness: float, width: float) -> Tuple[float, float, float]:
    """Principal inertias (kg m^2) of a solid block about its centre, in the beam's frame:
    x along the beam (``length``), y the bending direction (``thickness``), z the hinge axis
    (``width``); the rigid tip block's."""
    return (mass * (thickness**2 + width**2) / 12, mass * (length**2 + width**2) / 12,
            mass * (length**2 + thickness**2) / 12)


def discretize(act: Actuator, segments: int) -> BeamLayout:
    """Midpoint-rule layout of ``act`` with ``segments`` hinges (see module docstring)."""
    if isinstance(segments, bool) or int(segments) != segments or segments < 2 or segments > 1000:
        raise ParameterError("segments", segments, "an integer in [2, 1000]")
    N, L = int(segments), act.length
    ds = L / N
    hx = (np.arange(N) + 0.5) * ds
    EI = act.flexural_rigidity_at(hx)
    start = hx.copy()
    end = np.append(hx[1:], L)
    t = act.thickness
    # mass properties of each link by 4-point Gauss quadrature of mu(x) (exact for the
    # linear-width planforms of the catalog)
    xg, wg = np.polynomial.legendre.leggauss(4)
    mass, com, inertia, width = [], [], [], []
    for a, b in zip(start, end):
        x = a + (b - a) * 0.5 * (xg + 1)
        w = 0.5 * (b - a) * wg
        mu = act.mass_per_length_at(x)
        m = float(np.sum(w * mu))
        c = float(np.sum(w * mu * x) / m)
        Izz_line = float(np.sum(w * mu * (x - c) ** 2))   # about the com, along the length
        wc = float(act.width_at(c))
        Ixx = m * (wc**2 + t**2) / 12.0                    # about the beam axis (twist)
        Iyy = Izz_line + m * wc**2 / 12.0                  # about the thickness axis (in-plane)
        Izz = Izz_line + m * t**2 / 12.0                   # about the hinge axis (bending)
        mass.append(m); com.append(c); inertia.append((Ixx, Iyy, Izz)); width.append(wc)
    nu = float(np.mean([l.poisson_ratio for l in act.layers]))
    return BeamLayout(
        actuator_id=act.id, length=L, segments=N, thickness=t,
        hinge_x=hx, hinge_stiffness=EI / ds, hinge_width=np.asarray(act.width_at(hx), dtype=float),
        link_start=start, link_end=end, link_mass=np.array(mass), link_com=np.array(com),
        link_inertia=np.array(inertia), link_width=np.array(width),
        extension_length=act.planform.extension_length, extension_mass=act.planform.tip_block_mass,
        poisson_ratio=nu,
    )


#: layouts already built, keyed on the actuator object (held in the entry, so its id stays
#: its own while cached; actuators are frozen) and the segment count: a sweep's or an
#: accuracy target's many models of one actuator share them. Oldest dropped past LAYOUT_CACHE_SIZE
LAYOUT_CACHE_SIZE = 64
_LAYOUTS = BoundedCache("layouts", max_entries=LAYOUT_CACHE_SIZE, locked=True)


def _read_only(layout: BeamLayout) -> BeamLayout:
    for value in layout.__dict__.values():
        if isinstance(value, np.ndarray):
            value.flags.writeable = False
    return layout


def shared_layout(act: Actuator, segments: int) -> BeamLayout:
    """:func:`discretize` of ``act`` with ``segments`` hinges, built once per actuator object
    and segment count and shared (its arrays read-only): the same layout, bit for bit."""
    return _LAYOUTS.get_or_build(segments, lambda: _read_only(discretize(act, segments)), owner=act)


def check_payload(payload: Optional[Payload], layout: BeamLayout) -> None:
    if payload is None:
        return
    check_range("payload.position", payload.position, 0.0,
                layout.tip_x + layout.length * MAX_PAYLOAD_OVERHANG, "m", lo_open=True)


ORIENTATIONS: Tuple[str, ...] = ("horizontal", "up", "down")


def clamp_rotation(orientation) -> np.ndarray:
    """World rotation of the clamp frame (columns: beam axis x, deflection y, hinge axis z).

    horizontal: bending plane horizontal (hinge axis vertical), gravity out of the plane;
    up: beam points against gravity (Dadras et al. 2021's inverted payload case);
    down: beam hangs along gravity. A 3 x 3 rotation matrix is taken as it is (an
    actuator attached to a tilted mount, :func:`mjeap.attach`).
    """
    if not isinstance(orientation, str):
        R = np.asarray(orientation, dtype=float)
        if R.shape != (3, 3) or not np.allclose(R.T @ R, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0:
            raise ParameterError("orientation", orientation, f"one of {', '.join(ORIENTATIONS)} or a 3x3 rotation matrix")
        return R
    if orientation == "horizontal":
        return np.eye(3)
    if orientation == "up":
        return np.array([[0.0, 1, 0], [0, 0, 1], [1, 0, 0]])
    if orientation == "down":
        return np.array([[0.0, -1, 0], [0, 0, 1], [-1, 0, 0]])
    raise ParameterError("orientation", orientation, f"one of {', '.join(ORIENTATIONS)}")
