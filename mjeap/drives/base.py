"""Drive plugin interface: a voltage goes in, bending moments come out, in lockstep with MuJoCo.

A drive owns its internal state (charge, relaxation, force), is reset with the scene,
advances by one MuJoCo step from the input voltage (and, where its physics needs it, the
beam's state) and writes internal bending moments into the beam with
:meth:`mjeap.Scene.set_internal_moments`. Linear parts are discretised exactly over the
step (zero-order hold, ``scipy.signal.cont2discrete``), never by forward Euler.

Drives are registered by name with :func:`register_drive`, so a user's own model runs
with ``mjeap.rollout(..., drive="my-drive")`` without touching the package.
"""
from __future__ import annotations

import functools
from contextlib import contextmanager
from typing import ClassVar, Dict, Optional, Tuple, Type

import mujoco
import numpy as np

from ..errors import ParameterError, UnknownNameError, check_registration
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
signal = lazy_module("scipy.signal")

DRIVES: Dict[str, Type["Drive"]] = {}


def _drive_lacks(cls) -> Optional[str]:
    """Why ``cls`` cannot be registered as a drive (None: it can)."""
    if not isinstance(cls, type) or not issubclass(cls, Drive):
        return "an instance, not the class: register_drive(MyDrive)" if isinstance(cls, Drive) else "not a Drive"
    if cls.step is Drive.step:
        return "its step is Drive.step's, which applies no moment"
    if not isinstance(cls.actuators, (tuple, list)) or not all(isinstance(a, str) for a in cls.actuators):
        return f"its actuators is {cls.actuators!r}, not a tuple of catalog ids"
    if not isinstance(cls.PARAMETERS, dict) or not isinstance(cls.GENERIC_PARAMETERS, dict):
        return "its PARAMETERS or GENERIC_PARAMETERS is not a dict"
    return None


def register_drive(cls: Optional[Type["Drive"]] = None, *, replace: bool = False):
    """Class decorator: make a :class:`Drive` subclass (one that implements
    :meth:`Drive.step`) available by its ``name`` (letters, digits, '-', '_'). A name taken
    is refused unless ``replace`` (``@register_drive(replace=True)``)."""
    if cls is None:
        return lambda c: register_drive(c, replace=replace)
    check_registration("drive", DRIVES, getattr(cls, "name", None), cls, lacks=_drive_lacks(cls),
                       expected="a subclass of mjeap.Drive that implements step, with a name",
                       replace=replace, how="register_drive")
    DRIVES[cls.name] = cls
    return cls


def get_drive_class(name: str) -> Type["Drive"]:
    try:
        return DRIVES[name]
    except KeyError:
        raise UnknownNameError("drive", str(name), DRIVES) from None


def default_drive_name(actuator) -> str:
    """The actuator's own drive: the one its file names (an :class:`~mjeap.Actuator` or an
    actuator file's path), or for a catalog id the drive whose source document describes it."""
    from ..model.actuator_file import is_actuator_file
    from ..model.catalog import CATALOG, get_actuator
    if is_actuator_file(actuator):
        actuator = get_actuator(actuator)
    if not isinstance(actuator, str):
        if getattr(actuator, "drive", None):
            return actuator.drive
        actuator = actuator.id
    if actuator in CATALOG and CATALOG[actuator].drive:
        return CATALOG[actuator].drive
    for cls in DRIVES.values():
        if actuator in cls.actuators:
            return cls.name
    raise UnknownNameError("drive for actuator", actuator, DRIVES)


def make_drive(name: Optional[str], scene, **params) -> "Drive":
    """Instantiate the drive ``name`` (default: the actuator's own) for ``scene``."""
    name = name or default_drive_name(scene.actuator)
    return get_drive_class(name)(scene, **params)


@functools.lru_cache(maxsize=1024)
def zoh_first_order(pole: float, gain: float, dt: float) -> Tuple[float, float]:
    """x' = -pole x + gain u stepped exactly over ``dt`` s with u held (zero-order hold,
    scipy.signal.cont2discrete): returns (a, b) of x+ = a x + b u."""
    one = np.ones((1, 1))
    Ad, Bd, _, _, _ = signal.cont2discrete((-pole * one, gain * one, one, 0 * one), dt, method="zoh")
    return float(Ad[0, 0]), float(Bd[0, 0])


class ExactLTI:
    """A continuous linear system x' = A x + B u, y = C x + D u, stepped exactly for a
    zero-order-hold input (scipy.signal.cont2discrete); vectorised over ``n`` copies.
    ``advance`` works in place on preallocated arrays: a step allocates no array."""

    def __init__(self, A, B, C, D, dt: float, n: int = 1):
        Ad, Bd, Cd, Dd, _ = signal.cont2discrete((np.atleast_2d(A), np.atleast_2d(B).reshape(-1, 1),
                                                  np.atleast_2d(C), np.atleast_2d(D)), dt, method="zoh")
        self.Ad, self.Bd, self.Cd, self.Dd = Ad, Bd[:, 0], Cd, Dd[:, 0]
        self.x = np.zeros((n, Ad.shape[0]))
        self._first_order = Ad.shape == (1, 1)
        self._AdT = np.ascontiguousarray(Ad.T)
        self._next = np.empty_like(self.x)     # x A_d^T of the step being taken
        self._bu = np.empty_like(self.x)       # the input's contribution, u B_d^T
        if self._first_order:  # x+ = a x + b u, elementwise over the copies
            self._a, self._b = float(Ad[0, 0]), float(Bd[0, 0])
            self._x1 = self.x[:, 0]            # a view: writes through x[:] stay visible
            self._bu1 = self._bu[:, 0]

    def output(self, u) -> np.ndarray:
        return self.x @ self.Cd.T[:, 0] + self.Dd[0] * np.asarray(u)

    def advance(self, u) -> None:
        """One step with ``u`` held: a scalar for all copies or one value per copy."""
        if self._first_order:
            x, bu = self._x1, self._bu1
            if x.shape[0] == 1 and not isinstance(u, np.ndarray):   # one scalar state
                x[0] = self._a * float(x[0]) + self._b * u           # (ufuncs on size-1 arrays allocate)
                return
            if isinstance(u, np.ndarray):
                np.multiply(u, self._b, out=bu)
            else:
                bu.fill(self._b * u)
            np.multiply(x, self._a, out=x)
            np.add(x, bu, out=x)
            return
        np.matmul(self.x, self._AdT, out=self._next)
        np.multiply(np.reshape(u, (-1, 1)), self.Bd, out=self._bu)
        np.add(self._next, self._bu, out=self.x)


class Drive:
    """A drive stepped with the beam (what the loop engine needs): subclasses set ``name``,
    ``actuators`` (catalog ids the source describes), ``GENERIC_PARAMETERS`` (defaults with
    their sources; an actuator file's [drive.parameters] override them), ``UNITS`` (the
    units of parameters without a generic default), ``ROLES`` (the layer roles the drive
    reads) and implement :meth:`reset` and :meth:`step`. What the other engines need is
    mixed in: :class:`OpenLoop` (threaded), :class:`NativeForm` (native, systems)."""

    name: ClassVar[str] = ""
    actuators: ClassVar[Tuple[str, ...]] = ()
    #: per catalog id: defaults with their sources (a user drive's; the built-in drives'
    #: per-actuator values live in the actuators' files)
    PARAMETERS: ClassVar[Dict[str, Dict[str, Tuple[float, str, str]]]] = {}
    #: defaults for an actuator whose file gives none: (value SI, unit, source)
    GENERIC_PARAMETERS: ClassVar[Dict[str, Tuple[float, str, str]]] = {}
    #: units of the parameters that have no generic default (every one must then be given)
    UNITS: ClassVar[Dict[str, str]] = {}
    #: accepted (low, high) of numeric parameters, open bounds; every numeric one must be finite
    RANGES: ClassVar[Dict[str, Tuple[float, float]]] = {}
    #: layer roles the drive's physics reads and how many of each (an actuator without them
    #: is refused, naming the roles); :meth:`stack_reason` may ask more of the stack
    ROLES: ClassVar[Dict[str, int]] = {}
    model_used: str = ""

    def __init__(self, scene, **params):
        self.scene = scene
        # the actuator the drive acts on: a Scene's one part, or a part of a System
        self.part = getattr(scene, "part", scene)
        act = scene.actuator
        self._check_actuator(act)
        defaults = self.defaults_for(act)
        known = self.parameter_units()
        missing = [k for k in known if k not in defaults and k not in params]
        if missing:
            where = f" ({act.source_file})" if getattr(act, "source_file", None) else ""
            raise ParameterError("drive", self.name,
                                 f"every parameter given: {', '.join(known)} (an actuator file's [drive.parameters], "
                                 "or drive_params)",
                                 f"{act.id}{where} has no value for them; missing {', '.join(missing)}")
        self.params = {k: v[0] for k, v in defaults.items()}
        self.sources = {k: f"{v[1]}; {v[2]}" for k, v in defaults.items()}
        for k, v in params.items():
            if known and k not in known and k not in self.extra_parameters():
                raise ParameterError(f"{self.name} parameter", k, f"one of {', '.join(sorted(known))}")
            self.params[k] = v
            self.sources[k] = "given by the user"
        self._check_parameters()

    @classmethod
    def parameter_units(cls) -> Dict[str, str]:
        """Every parameter the drive takes, with its unit."""
        out = {k: row[1] for table in cls.PARAMETERS.values() for k, row in table.items()}
        out.update({k: row[1] for k, row in cls.GENERIC_PARAMETERS.items()})
        out.update(cls.UNITS)
        return out

    @classmethod
    def defaults_for(cls, actuator) -> Dict[str, Tuple[float, str, str]]:
        """The parameter defaults for ``actuator``: its file's [drive.parameters] over the
        generic ones where the file names this drive, else those of a user drive's
        ``PARAMETERS`` for its id, else the generic ones."""
        if getattr(actuator, "drive", None) == cls.name and actuator.drive_parameters:
            units = cls.parameter_units()
            return {**cls.GENERIC_PARAMETERS,
                    **{k: (v[0], units.get(k, v[1]), v[2]) for k, v in actuator.drive_parameters.items()}}
        return cls.PARAMETERS.get(actuator.id, cls.GENERIC_PARAMETERS)

    @classmethod
    def stack_reason(cls, actuator) -> Optional[str]:
        """Why this drive cannot take ``actuator``'s layer stack (None: it can): by default,
        a role of :attr:`ROLES` missing or present too few times."""
        roles = [l.role for l in actuator.layers]
        short = [f"{n} '{r}'" for r, n in cls.ROLES.items() if roles.count(r) < n]
        if not short:
            return None
        return (f"it needs {', '.join(short)} layer{'s' if sum(cls.ROLES.values()) > 1 else ''} (role = ...); "
                f"{actuator.id} has " + ", ".join(f"{l.name} ({l.role or 'no role'})" for l in actuator.layers))

    def _check_actuator(self, actuator) -> None:
        """Refuse an actuator whose layer stack the drive cannot take (:meth:`stack_reason`)."""
        why = self.stack_reason(actuator)
        if why is None:
            return
        try:
            own = f"; its own drive is '{default_drive_name(actuator)}'"
        except UnknownNameError:
            own = ""
        roles = " and ".join(f"'{r}'" for r in self.ROLES)
        raise ParameterError("drive", self.name,
                             f"a drive for an actuator with {roles} layer{'s' if len(self.ROLES) > 1 else ''} "
                             f"(in the catalog: {', '.join(self.actuators) or 'none'})", f"{why}{own}")

    def _parameter_table(self) -> Dict[str, Tuple[float, str, str]]:
        """The parameters this drive takes for this actuator, with their defaults."""
        return self.defaults_for(self.scene.actuator)

    def _check_parameters(self) -> None:
        """Every parameter that defaults to a number must be a finite number, within RANGES."""
        table = self._parameter_table()
        for k, v in self.params.items():
            default = table.get(k, (None,))[0]
            numeric = isinstance(default, (int, float)) and not isinstance(default, bool)
            if not numeric and not (k not in table and k in self.UNITS):   # a choice, a switch, a table
                continue
            if isinstance(v, bool) or not isinstance(v, (int, float, np.number)) or not np.isfinite(v):
                raise ParameterError(f"{self.name} parameter {k}", v, "a finite number")
            lo, hi = self.RANGES.get(k, (-np.inf, np.inf))
            if not lo < v < hi:
                raise ParameterError(f"{self.name} parameter {k}", v, f"a value in ({lo:g}, {hi:g})")

    def extra_parameters(self) -> Tuple[str, ...]:
        return ()

    @contextmanager
    def _acting_on(self, part):
        """Within the block the drive's loop methods (:meth:`step`, :meth:`signals`) act on
        ``part`` (a read-only view when replaying on a model that already drives the beam),
        its own part again after it: the one place a drive's part changes, the drive's own."""
        own = self.part
        self.part = part
        try:
            yield
        finally:
            self.part = own

    # -- to implement ------------------------------------------------------------------
    def reset(self, initial_curvature: float = 0.0) -> None:
        """Reset the drive state; the scene is already reset (and bent, if asked)."""

    def step(self, voltage: float, dt: float) -> None:
        """Advance one MuJoCo step of ``dt`` s with input ``voltage`` (V) held, writing the
        bending moments into the scene for this step."""
        raise NotImplementedError

    def signals(self) -> Dict[str, float]:
        """Drive quantities to record now, SI, keyed 'name (unit)'."""
        return {}

    def reference_curvature(self, t: np.ndarray, v: np.ndarray, initial_curvature: float = 0.0
                            ) -> Optional[np.ndarray]:
        """Analytical tip curvature (1/m) for this input, if the source has one."""
        return None

    def voltage_range(self) -> Tuple[float, float]:
        return tuple(self.scene.actuator.voltage_range)

    def rest_voltage(self) -> float:
        """The input (V) at which the drive applies no moment: where a run at rest starts."""
        return 0.0

    def check_voltage(self, v: np.ndarray) -> None:
        lo, hi = self.voltage_range()
        v = np.asarray(v)
        if not np.all(np.isfinite(v)):
            raise ParameterError("voltage", "NaN", "finite values")
        if v.min() < lo - 1e-12 or v.max() > hi + 1e-12:
            raise ParameterError("voltage", f"[{v.min():.4g}, {v.max():.4g}] V",
                                 f"values in the safe range [{lo:g}, {hi:g}] V of {self.scene.actuator.id} "
                                 f"under {self.name}")

    # -- what the other engines ask (the mixins below answer yes) -------------------------
    def closed_loop_reason(self) -> Optional[str]:
        """None where the moments follow from the voltage alone and the drive leaves the
        model unchanged, so their history can be computed before the run (the threaded
        engine, :class:`OpenLoop`); else why not."""
        return "its moments depend on the beam's state (the drive does not declare itself open-loop)"

    def native_reason(self) -> Optional[str]:
        """None where the drive has a native MJCF form (:class:`NativeForm`); else why not."""
        return f"the {self.name} drive declares no native MJCF form"

    def small_signal(self, operating_voltage: float):
        """The drive's linear model about the input ``operating_voltage`` (V), per volt of its
        input: moment per volt, blocked admittance, motional coupling and internal states
        (:class:`mjeap.drives.small_signal.SmallSignal`), what ``mjeap frf`` couples to the
        beam's linearised mechanics. A drive without one is refused there, naming it."""
        raise ParameterError("drive", self.name, "a drive that states its small-signal model "
                             "(Drive.small_signal, mjeap.drives.small_signal)",
                             f"the {self.name} drive states none; sine runs measure it instead "
                             "(mjeap.analysis.frequency.sine_sweep)")

    def _operating_voltage(self, v0: float) -> float:
        """``v0`` (V), refused outside the drive's safe range."""
        lo, hi = self.voltage_range()
        if not (np.isfinite(v0) and lo - 1e-12 <= v0 <= hi + 1e-12):
            raise ParameterError("offset", v0, f"an operating voltage in the safe range [{lo:g}, {hi:g}] V of "
                                 f"{self.scene.actuator.id} under {self.name}")
        return float(v0)

    def describe(self) -> str:
        return f"{self.name} ({self.model_used})" if self.model_used else self.name


class OpenLoop:
    """A drive whose moments follow from the voltage alone (the threaded engine's need,
    :mod:`mjeap.engines.threaded`): their whole history is computed up front
    (:meth:`open_loop_moments`) and the drive can be put in its state after any step
    (:meth:`seek`). Mixed in before :class:`Drive`."""

    def closed_loop_reason(self) -> Optional[str]:
        return None

    def open_loop_moments(self, v_steps: np.ndarray, dt: Optional[float] = None) -> np.ndarray:
        """Bending moment (N m) at every hinge over every step from reset, (steps, segments),
        for the voltages ``v_steps`` (V) held over steps of ``dt`` s (default the scene's
        timestep; a system's own where it steps at another); afterwards :meth:`seek` works."""
        self._v_history = np.asarray(v_steps, dtype=float)
        self._seek_dt = self.scene.timestep if dt is None else float(dt)
        return self._moment_history(self._v_history)

    def seek(self, k: int) -> None:
        """After :meth:`open_loop_moments`: put the drive in its state after ``k`` steps, so
        that :meth:`signals` reads what the lockstep loop would (the scene holds the beam).
        It replays the drive's own :meth:`step` k from the state before that step."""
        if k == 0:
            self.reset()
            return
        self._restore_before(k - 1)
        self.step(float(self._v_history[k - 1]), self._seek_dt)

    # hooks of the two above, for open-loop drives
    def _moment_history(self, v: np.ndarray) -> np.ndarray:
        """Vectorised: the moments (N m), (steps, segments), that :meth:`step` applies."""
        raise NotImplementedError(f"{self.name}: {self.closed_loop_reason()}")

    def _restore_before(self, k: int) -> None:
        """Set the drive's own state to what it is before step ``k`` (none by default)."""


class NativeForm:
    """A drive that can be compiled into the model as MuJoCo elements (the native engine's
    and :class:`mjeap.System`'s need, :mod:`mjeap.drives.native`): :meth:`add_native` and the
    read-outs of its state from a native run. The defaults replay the loop drive, for a
    drive that is also :class:`OpenLoop`. Mixed in before :class:`Drive`."""

    def native_reason(self) -> Optional[str]:
        return None

    def add_native(self, spec, joints, parent: str):
        """Add the drive to ``spec`` (the scene's, internal units) as MuJoCo elements acting
        on the hinge ``joints``; relaxation bodies go under body ``parent``. Returns the
        :class:`mjeap.drives.native.NativeHandles`."""
        raise NotImplementedError(self.native_reason())

    def native_reset(self, part, handles, prefix: str = "") -> None:
        """Set the native model's drive state at rest at the part's present shape (after
        the beam was reset and bent); the activation is zero after mj_resetData."""

    def native_prepare(self, v_steps: np.ndarray, dt: Optional[float] = None) -> None:
        """Before a native run with the voltages ``v_steps`` (V) held over steps of ``dt`` s
        (default the scene's timestep; a system's own), so that :meth:`native_signals` can
        read the drive's signals at any step."""
        self.open_loop_moments(v_steps, dt)

    def native_signals(self, k: int, part, handles, prefix: str = "", before=None) -> Dict[str, float]:
        """The drive's signals after step ``k`` of a native run, the part holding that
        state: by default the loop drive replayed to step k (:meth:`seek`) on a read-only
        view of its part, so that the replay adds no moment or stiffness to a beam the
        native model already drives (a system's, :mod:`mjeap.simulation.system`). ``before``:
        the model's full-physics state before step k, which the replayed step starts from
        as the loop's does (a drive reading the beam's rates needs it: the piezo bimorph's
        motional current); None: the state after it."""
        with self._acting_on(ReadOnlyPart(part)):
            with _state_before(part, before):
                self.seek(k)
            return self.signals()

    def native_signal_history(self, ks: np.ndarray, states: np.ndarray, part, handles,
                              prefix: str = "") -> Optional[Dict[str, np.ndarray]]:
        """The signals after the steps ``ks`` of a native run, all at once, from the model's
        full-physics states then (one row each); None where the drive reads them one
        sample at a time (:meth:`native_signals`)."""
        return None

    def native_leave(self, k: int, part, handles, prefix: str = "", before=None) -> None:
        """After a native run of ``k`` steps whose final state ``part`` holds: take over that
        state and apply the last step's moments to the drive's own part (the scene), as the
        loop leaves them; by default the loop drive replayed to step k (from ``before``, the
        native model's state before that step, as :meth:`native_signals`)."""
        with _state_before(part, before):
            self.seek(k)


@contextmanager
def _state_before(part, before):
    """Within the block ``part``'s model holds the full-physics state ``before`` (when not
    None); the state it held is put back after it."""
    if before is None:
        yield
        return
    m, d = part.model, part.data
    spec = mujoco.mjtState.mjSTATE_FULLPHYSICS
    now = np.empty(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, now, spec)
    mujoco.mj_setState(m, d, before, spec)
    try:
        yield
    finally:
        mujoco.mj_setState(m, d, now, spec)


class ReadOnlyPart:
    """A beam part seen by a replayed drive: reads pass through, the drive's writes (its
    moments, its stiffness scale) are kept here and never reach the model."""

    def __init__(self, part):
        self._part = part
        self.stiffness_scale = getattr(part, "stiffness_scale", 1.0)

    def __getattr__(self, name):
        return getattr(self._part, name)

    def set_internal_moments(self, moments) -> None:
        pass

    def set_bending_stiffness_scale(self, scale) -> None:
        self.stiffness_scale = scale
