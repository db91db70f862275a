"""A compiled, ready-to-step beam scene: model building, damping and timestep choice,
loads, stepping with divergence checks, and SI read-outs.

Damping and timestep are derived from the compiled model, never tuned by hand:

1. Linearise (``mjeap.model.modes``) and find the first bending mode omega_1, phi_1 of the scene
   (payload and gravity included), the first elastic mode omega_el (gravity's load left
   out) and the highest discrete mode.
2. Joint damping is stiffness-proportional (Rayleigh), b_j = beta k_j with
   beta = 2 zeta_1 omega_1 / (phi_1' K_el phi_1) (phi_1 mass-normalised), so the first mode
   has the catalog's damping ratio zeta_1 whatever gravity's geometric stiffness adds to or
   takes from omega_1 (standing up, hanging, payloads); mode n has about
   zeta_n = beta omega_n / 2: the stiff discrete modes are overdamped, as material damping
   does to short wavelengths. Towards the buckling load omega_1 and with it beta go to zero;
   past it the straight column's growth rate takes omega_1's place, so nothing jumps there
   (both floored at 1 % of omega_el, ``NEAR_CRITICAL``).
3. Under ``implicitfast`` joint damping is implicit but stiffness (joint springs and the
   cable plugin) is explicit, so the step must satisfy the stability limit h_stab of the
   linearised step map (about beta + sqrt(beta^2 + 4/omega_max^2), i.e. ~2 beta for a fine
   chain). Under ``discrete`` joint stiffness is implicit too (hinge chain: no limit; the
   cable plugin stays explicit). Backward Euler on a hinge spring damps each mode by
   zeta = omega h / 2: Rayleigh damping with beta = h of the integrator's own. The hinge
   chain therefore gets joint damping (beta - h) k, so that the first mode's damping ratio
   is still zeta_1, and its timestep is at most beta / 2 (the joint keeps at least half).
   ``discrete`` also solves contacts in the metric M + hD + h^2 K of the implicit update:
   systems with contact need it (:mod:`mjeap.simulation.system`). The rod (:mod:`mjeap.model.rod`) runs
   under ``discrete`` only (MuJoCo 4.0 refuses rod elasticity under the implicit
   integrators), which takes its elasticity implicitly as it does the hinge springs: no
   stability limit, the flex's own Rayleigh damping gives it (beta - h) K and its
   timestep is at most beta / 2. Its modes are those of its bending angles
   (:meth:`mjeap.model.rod.RodBuilder.linearize`). Which of these apply to a beam is its
   builder's to say (:class:`mjeap.model.mjcf.BeamBuilder`).
4. The default timestep is min(T_1 / 50, T_el / 50, h_stab / 2): 50 steps per period of
   the first mode keeps its period error below 0.1 %; T_el bounds it near the buckling load,
   where T_1 grows without bound but the beam's elastic response to a drive does not; the
   factor 2 keeps away from the stability limit, which moves slightly with the
   large-deflection geometry. A user timestep above h_stab is refused with the limit in the
   message; under ``discrete`` on the hinge chain (no h_stab) so is one above T_1 / 50
   (accuracy) or beta / 2 (the joints' share (beta - h) k of the damping would fall below
   half, and to nothing at h = beta) (:meth:`Scene.check_timestep`, which a
   :class:`~mjeap.System` applies to every attached beam).
"""
from __future__ import annotations

import math
import warnings
from typing import Optional, Union

import mujoco
import numpy as np

from .accuracy import check_accuracy
from ..caching import BoundedCache, clear_caches
from ..errors import DivergenceError, ParameterError, check_positive, check_range
from ..model.catalog import Actuator, get_actuator
from ..model.discretize import BeamLayout, Payload, check_payload, clamp_rotation, shared_layout
from ..model.fields import apply_dof_damping
from ..model.mjcf import build_spec, get_builder
from ..model.modes import modal_frequencies, stability_limit
from ..units import DEFAULT_UNITS, UnitSystem
from .beam_analysis import ANALYSES, BeamAnalysis, TimestepChoice, floor_sig
from .part import ActuatorPart
from ..lazy import lazy_module

#: imported at its first use (mjeap.lazy)
linalg = lazy_module("scipy.linalg")

__all__ = ["Scene", "TimestepChoice", "as_scene", "input_files", "clear_build_caches", "diverged",
           "warn_heavy_payload", "DEFAULT_SEGMENTS", "INTEGRATORS", "DEFAULT_MAX_BEND"]

STEPS_PER_PERIOD = 50
STABILITY_SAFETY = 0.5
SETTLING_DAMPING_RATIO = 0.3
INTEGRATORS = {"implicitfast": mujoco.mjtIntegrator.mjINT_IMPLICITFAST,
               "discrete": mujoco.mjtIntegrator.mjINT_DISCRETE}
DEFAULT_SEGMENTS = 20
#: the first mode's rate is floored at this fraction of the elastic first mode (gravity's
#: load left out): within ~1e-4 of the buckling load its period would exceed 100 elastic
#: periods, and a damping ratio of a mode that does not oscillate means nothing
NEAR_CRITICAL = 0.01
#: a payload heavier than this many beams is probably a unit slip (kg for mg, a factor 1e6):
#: warned. The HAMR leg's reflected leg mass is 4.7e4 beams (mjeap.controllers.hamr_leg)
HEAVY_PAYLOAD = 1e5


def warn_heavy_payload(mass: float, beam_mass: float, what: str = "payload", stacklevel: int = 3) -> None:
    """The one check of a payload's unit (the Scene's, the environments' drawn masses): a
    warning where ``mass`` (kg) exceeds HEAVY_PAYLOAD x the beam's ``beam_mass``."""
    if mass > HEAVY_PAYLOAD * beam_mass:
        warnings.warn(f"{what} {mass:.4g} kg is {mass / beam_mass:.3g} x the beam's mass ({beam_mass:.3g} kg): "
                      "check its unit (SI is kg; '12.6mg' for milligrams)", stacklevel=stacklevel)
#: tip angle (rad) of the uniform arc at which the cable's stability limit is checked
#: besides the straight beam; Dadras et al. 2021's actuator bends to about 1.8 rad
DEFAULT_MAX_BEND = 2.0


def diverged(data: mujoco.MjData) -> bool:
    """MuJoCo warned of a bad acceleration, or the state is no longer finite (a sum is
    finite only if every entry is, and no entry is near overflow)."""
    return data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0 or \
        not math.isfinite(float(data.qpos.sum()) + float(data.qvel.sum()))


#: scenes built for reuse, per thread (a scene's data is its runs' state), by everything they
#: are built from: an accuracy target's models (:meth:`Scene.variant`: a map's points of one
#: payload at every amplitude, a refinement's companions) and a sweep's point scenes
#: (:meth:`Scene.shared`). Each run resets the state; a scene whose hinges were set by hand,
#: or a point scene left with a tip load, is built again. Oldest dropped past SHARED_SCENES
SHARED_SCENES = 64
SHARED_SCENE_BYTES = 256 * 2**20
_SHARED = BoundedCache("shared scenes", max_entries=SHARED_SCENES, max_bytes=SHARED_SCENE_BYTES,
                       nbytes=lambda s: 3 * mujoco.mj_sizeModel(s.model), per_thread=True)


def _orientation_key(v):
    if isinstance(v, str):
        return v
    a = np.asarray(v, dtype=float)
    return a.shape, a.tobytes()


def _shared(args: dict, chosen_model: bool) -> "Scene":
    """The scene of Scene's keywords ``args`` (the actuator an object) from this thread's
    cache, built and kept there where missing or no longer as built (hinges set by hand; a
    point scene left with a tip load). The cache holds at most SHARED_SCENES scenes and
    SHARED_SCENE_BYTES of compiled models (three per scene counted: its own, its data, a
    native model), the oldest dropped first."""
    key = (chosen_model,) + tuple((k, _orientation_key(v) if k == "orientation" else v)
                                  for k, v in sorted(args.items()) if k != "actuator")

    def build():
        s = Scene.__new__(Scene)
        s.chosen_model = chosen_model
        Scene.__init__(s, **args)
        return s
    return _SHARED.get_or_build(key, build, owner=args["actuator"],
                                valid=lambda s: not s.part.revision and (chosen_model or not s.part.has_tip_load()))


def clear_build_caches() -> None:
    """Forget everything built scenes share (:func:`mjeap.caching.clear_caches`: analyses,
    layouts, every thread's shared scenes, chain structures, native models' stability): a
    benchmark's cold start."""
    clear_caches()


class Scene:
    """A catalog actuator as a MuJoCo scene. Inputs and outputs in SI.

    Parameters: ``actuator`` (catalog id or :class:`Actuator`), ``representation``
    ('hinge' | 'cable' | 'rod', :mod:`mjeap.model.mjcf`), ``segments`` (>= 2), ``orientation``
    ('horizontal' | 'up' | 'down'), ``payload`` (:class:`Payload` or 'MASS@POSITION'),
    ``units`` (internal :class:`UnitSystem`), ``timestep`` (s, default from the model),
    ``integrator`` ('implicitfast' | 'discrete'; default the representation's own:
    'implicitfast', the rod 'discrete'), ``damping_ratio`` (first-mode, default from the
    catalog), ``gravity`` (bool), ``max_bend`` (rad: tip angle up to which the cable's
    timestep is checked for stability; the hinge chain needs none), ``accuracy`` (a
    target for this scene's rollouts, relative to the swing of the tip curvature: they
    then choose segments, integrator and timestep themselves and report their error,
    :mod:`mjeap.simulation.accuracy`; the scene as built keeps the arguments given).
    """

    def __init__(self, actuator: Union[str, Actuator], *, representation: str = "hinge",
                 segments: int = DEFAULT_SEGMENTS, orientation: str = "horizontal",
                 payload: Union[Payload, str, None] = None, units: Optional[UnitSystem] = None,
                 timestep: Optional[float] = None, integrator: Optional[str] = None,
                 damping_ratio: Optional[float] = None, gravity: bool = True,
                 max_bend: float = DEFAULT_MAX_BEND, accuracy: Optional[float] = None):
        self.actuator = get_actuator(actuator)
        self.accuracy = None if accuracy is None else check_accuracy(accuracy)
        #: set by :meth:`variant` for a model chosen by :mod:`mjeap.simulation.accuracy`: its timestep
        #: is bound by stability only (the accuracy target replaces the fixed rules)
        self.chosen_model = getattr(self, "chosen_model", False)
        self._arguments = dict(actuator=self.actuator, representation=representation, orientation=orientation,
                               payload=payload, units=units, damping_ratio=damping_ratio, gravity=gravity,
                               max_bend=max_bend, accuracy=accuracy)
        self.builder = builder = get_builder(representation)
        clamp_rotation(orientation)
        if integrator is None:
            integrator = builder.default_integrator
        if integrator not in INTEGRATORS:
            raise ParameterError("integrator", integrator, f"one of {', '.join(INTEGRATORS)}")
        why = builder.integrator_reason(integrator)
        if why is not None:
            raise ParameterError("integrator", integrator, " or ".join(map(repr, builder.integrators)), why)
        if isinstance(payload, str):
            payload = Payload.parse(payload)
        if payload is not None and not isinstance(payload, Payload):
            raise ParameterError("payload", payload, "a Payload(mass kg, position m) or text 'MASS@POSITION', "
                                 "e.g. '12.6mg@6.27mm'")
        if units is not None and not isinstance(units, UnitSystem):
            raise ParameterError("units", units, "a UnitSystem (SI size of one internal length, mass and time "
                                 "unit), e.g. UnitSystem(1e-3, 1e-6, 1e-3) for mm, mg, ms")
        self.units = units or DEFAULT_UNITS
        self.representation, self.orientation, self.payload = representation, orientation, payload
        self.integrator = integrator
        self.max_bend = check_range("max_bend", max_bend, 0.0, 2 * np.pi, "rad")
        self.layout: BeamLayout = shared_layout(self.actuator, segments)
        check_payload(payload, self.layout)
        beam_mass = float(self.layout.link_mass.sum())
        if payload is not None:
            warn_heavy_payload(payload.mass, beam_mass)
        zeta = self.actuator.damping_ratio.value if damping_ratio is None else \
            check_range("damping_ratio", damping_ratio, 0.0, 10.0)
        self.rotation = clamp_rotation(orientation)

        self.spec, self.handles = build_spec(self.layout, representation, orientation, payload,
                                             self.units, gravity)
        self.spec.option.integrator = INTEGRATORS[integrator]
        self.spec.option.disableflags |= mujoco.mjtDisableBit.mjDSBL_AUTORESET
        self.choice = self._choose_timestep_and_damping(zeta, timestep)
        self.model = apply_dof_damping(self.spec.compile())
        self.part = ActuatorPart(self.model, self.handles, self.layout, self.actuator, self.units,
                                 representation, payload=payload, rotation=self.rotation)
        self.data = mujoco.MjData(self.model)
        self.reset()

    # ------------------------------------------------------------------ construction
    def _choose_timestep_and_damping(self, zeta: float, timestep: Optional[float]) -> TimestepChoice:
        u = self.units
        b, hd, lay = self.builder, self.handles, self.layout
        o = self.orientation if isinstance(self.orientation, str) else self.rotation.tobytes()
        #: everything this scene's model was built from (the actuator by identity: see ANALYSES)
        self.build_key = key = (id(self.actuator), self.representation, lay.segments, o, self.payload, u,
                                self._arguments["gravity"], zeta, self.integrator, self.max_bend)
        a = ANALYSES.get_or_build(key, lambda: self._analyse(zeta), owner=self.actuator)
        self.linearization = a.linearization
        w_el, wmax, w1, buckled, beta, h_stab = a.w_el, a.wmax, a.w1, a.buckled, a.beta, a.h_stab
        kj = lay.hinge_stiffness / u.rotational_stiffness
        b.set_damping(self.spec, hd, beta, beta * kj, beta * a.pattern if b.stores_dof_damping else None)
        T1, T_el = 2 * np.pi / w1, 2 * np.pi / w_el
        T_short = min(T1, T_el)
        # accuracy: 50 steps per period of the first mode, and of the first mode without
        # gravity's load (near the buckling load T1 grows without bound, the beam's elastic
        # response to a drive or a push does not). The drives are discretised exactly
        # (zero-order hold), so their time constants set no bound of their own.
        h_acc = T_short / STEPS_PER_PERIOD
        # backward Euler on the hinge springs (the rod's elasticity) damps like Rayleigh
        # damping with beta = h
        numerical = b.implicit_stiffness(self.integrator)
        # the limits a timestep must keep (internal, why): stability, and where the integrator
        # takes the stiffness implicitly (no stability limit there) accuracy and the beam's
        # share of beta
        self._timestep_limits = [(h_stab, (
            f"stability limit of {self.actuator.id} ({self.representation}, {self.layout.segments} "
            f"segments) under {self.integrator}: highest bending mode {wmax / u.time / 2 / np.pi:.4g} Hz "
            f"with explicit stiffness, Rayleigh damping beta = {beta * u.time:.3g} s"))]
        if numerical and not self.chosen_model:     # a chosen model: the accuracy target binds instead
            self._timestep_limits.append((T_short / STEPS_PER_PERIOD, (
                f"accuracy under discrete: {STEPS_PER_PERIOD} steps per period of the first mode of "
                f"{self.actuator.id} (T = {T_short * u.time:.4g} s)")))
            if beta > 0:
                self._timestep_limits.append((0.5 * beta, (
                    f"damping under discrete: the step damps the first mode by beta = h itself and the joints "
                    f"carry the rest (beta - h) K of {self.actuator.id}'s Rayleigh beta = {beta * u.time:.4g} s "
                    f"(damping ratio {zeta:g}); h <= beta / 2 keeps at least half in the joints")))
        if numerical and beta > 0:
            h_acc = min(h_acc, 0.5 * beta)
        if timestep is None:
            # rounded down to 3 significant figures in SI: a clean number that does not
            # depend on the internal units (the limit itself is known to ~1e-4)
            h_si = min(h_acc, STABILITY_SAFETY * h_stab) * u.time
            h = floor_sig(h_si, 3) / u.time
            reason = (f"min(T1/{STEPS_PER_PERIOD} = {T1 / STEPS_PER_PERIOD * u.time:.3g} s, "
                      f"T_el/{STEPS_PER_PERIOD} = {T_el / STEPS_PER_PERIOD * u.time:.3g} s (no gravity load), "
                      f"{STABILITY_SAFETY} x stability limit {h_stab * u.time:.3g} s"
                      + (f", beta/2 = {0.5 * beta * u.time:.3g} s under discrete" if numerical and beta > 0 else "")
                      + ")")
        else:
            h = self.check_timestep(timestep) / u.time
            reason = "chosen for an accuracy target (mjeap.simulation.accuracy)" if self.chosen_model else "given by the user"
        self.spec.option.timestep = h
        h_num = h if numerical else 0.0
        choice = TimestepChoice(
            timestep=h * u.time, stability_limit=h_stab * u.time, accuracy_limit=h_acc * u.time,
            first_frequency=w1 / u.time / (2 * np.pi), highest_frequency=wmax / u.time / (2 * np.pi),
            damping_ratio=zeta, rayleigh_beta=beta * u.time, integrator_beta=h_num * u.time, integrator=self.integrator,
            buckled=buckled, reason=reason)
        if numerical:
            b.set_damping(self.spec, hd, self.rayleigh_share(h * u.time, choice), self.joint_damping(h * u.time, choice))
        b.finish(self.spec, hd, h)
        return choice

    def _analyse(self, zeta: float) -> "BeamAnalysis":
        """The timestep-independent part of the choice: linearisation, modes, Rayleigh beta and
        the stability limit of the spec as built (no damping yet)."""
        u = self.units
        try:
            model = self.spec.compile()
        except ValueError as e:
            if "mjMINVAL" not in str(e):
                raise
            raise ParameterError(
                "units", u, "units in which segment masses and inertias exceed MuJoCo's 1e-15 floor",
                f"{self.actuator.id}: smallest segment mass {self.layout.link_mass.min() / u.mass:.3g} and "
                f"inertia {self.layout.link_inertia.min() / u.inertia:.3g} in these units; use e.g. the default "
                f"(mm, mg, ms). MuJoCo said: {str(e).splitlines()[0]}") from None
        b, hd, lay = self.builder, self.handles, self.layout
        lin = b.linearize(model, hd, lay, u)
        lam, phi = linalg.eigh(lin.K, lin.M)       # gravity included, mass-normalised
        w2_el = modal_frequencies(lin, with_gravity=False)
        buckled = bool(lam[0] <= 0)
        w_el, wmax = np.sqrt(w2_el[0]), np.sqrt(w2_el[-1])
        # the first mode's rate: its frequency below the buckling load, the growth rate of
        # the straight column's unstable mode above it (near the load both go to zero like
        # sqrt|1 - P/P_cr|, so nothing jumps there), floored at NEAR_CRITICAL x w_el
        w1 = max(np.sqrt(abs(lam[0])), NEAR_CRITICAL * w_el)
        # Rayleigh damping D = beta K_el per degree of freedom (clipped diagonal: a ball joint
        # takes one scalar damping in MJCF, so the cable's per-dof values (bending, in-plane,
        # twist) travel in a custom numeric field that load_mjcf() and the scene apply after
        # compiling). The first mode phi_1 of K = K_el + K_gravity gets the modal damping
        # beta phi_1' D_1 phi_1 = 2 zeta w1 with D_1 the pattern per unit beta, so beta is
        # taken from that: with gravity's geometric stiffness in the frequency but not in
        # the damping, 2 zeta / w1 would give zeta (w_el / w1)^2 (0.16 standing up, 0.03
        # hanging with 100 mg on Dadras et al. 2021's beam).
        pattern = np.clip(np.diag(lin.K_elastic), 0.0, None)
        k1 = float(phi[:, 0] @ (pattern * phi[:, 0]))
        beta = 2 * zeta * w1 / k1
        dof_damping = beta * pattern
        T_short = min(2 * np.pi / w1, 2 * np.pi / w_el)
        h_stab = stability_limit(lin, dof_damping, self.integrator, h_max=T_short)
        if b.check_bent_stability:
            # the cable's tangent stiffness stops being diagonal in the joint coordinates
            # once bent (the stiff in-plane direction couples into twist), so diagonal
            # damping no longer damps it: check the design bend too
            bent = np.full(lay.segments, self.max_bend / lay.segments)
            h_stab = min(h_stab, stability_limit(b.linearize(model, hd, lay, u, angles=bent), dof_damping,
                                                 self.integrator, h_max=T_short))
        return BeamAnalysis(self.actuator, lin, w_el, wmax, w1, buckled, pattern, beta, h_stab)

    def check_timestep(self, timestep: float, name: str = "timestep") -> float:
        """``timestep`` (s), refused with the limit and its reason where this beam would not
        run correctly at it: above its stability limit; under 'discrete' on the hinge chain
        (no stability limit) above T_1 / 50 (accuracy) or beta / 2 (the joints' damping
        (beta - h) K would fall below half of it, and to 0 at h = beta)."""
        h = check_positive(name, timestep, "s")
        u = self.units
        for limit, why in sorted(self._timestep_limits, key=lambda x: x[0]):    # the tightest named
            if h > limit * u.time * (1 + 1e-9):
                raise ParameterError(name, timestep, f"a timestep <= {floor_sig(limit * u.time, 4):.4g} s", why)
        return h

    def joint_damping(self, timestep: float, choice: Optional[TimestepChoice] = None) -> np.ndarray:
        """Damping of each bending joint (internal units) that gives the first mode its
        damping ratio when stepped at ``timestep`` (s): beta k_j, of which 'discrete' adds
        h k_j itself on the hinge chain (backward Euler on the springs)."""
        u = self.units
        return self.rayleigh_share(timestep, choice) * self.layout.hinge_stiffness / u.rotational_stiffness

    def buckled_warning(self) -> str:
        """A run's warning where the straight beam is unstable under gravity (``choice.buckled``)."""
        return (f"{self.actuator.id}: the straight beam is unstable under gravity (the payload is above the column "
                "load): the run starts from that unstable equilibrium and only a disturbance (an initial curvature, "
                "a voltage) makes it buckle; a result near zero here is not a stable beam")

    def rayleigh_share(self, timestep: float, choice: Optional[TimestepChoice] = None) -> float:
        """The beam's own stiffness-proportional damping coefficient (internal time) when
        stepped at ``timestep`` (s): beta, less the h that an integrator taking the stiffness
        implicitly adds itself."""
        c, u = choice or self.choice, self.units
        numerical = self.builder.implicit_stiffness(c.integrator)
        beta = c.rayleigh_beta - (timestep if numerical else 0.0)
        return max(beta, 0.0) / u.time

    @property
    def arguments(self) -> dict:
        """The arguments this scene was built with (actuator, representation, orientation,
        payload, units, damping_ratio, gravity, max_bend, accuracy): a copy."""
        return dict(self._arguments)

    @classmethod
    def shared(cls, actuator: Union[str, Actuator], **kwargs) -> "Scene":
        """``Scene(actuator, **kwargs)`` from this thread's cache of built scenes (built and
        kept there where missing): a sweep's points of one scene, at every amplitude, share
        it (each run resets its state; one whose hinges were set by hand or that carries a
        tip load is built again)."""
        return _shared({"actuator": get_actuator(actuator), **kwargs}, chosen_model=False)

    def variant(self, segments: int, timestep: float, integrator: str) -> "Scene":
        """This scene (actuator, orientation, payload, units, damping, gravity) as a model
        of ``segments`` hinges stepped at ``timestep`` (s) under ``integrator``, as chosen for
        an accuracy target (:mod:`mjeap.simulation.accuracy`): only its stability limit binds the
        timestep; above beta under 'discrete' the step's own damping h K exceeds the beam's,
        an error the target's estimate accounts for. The tip loads set on this scene
        (:meth:`set_tip_force`, :meth:`set_tip_moment`) act on the variant too; hinge
        parameters set by hand belong to this model's hinges and are refused. Built once per
        thread for the same arguments and reused (:meth:`shared`'s cache)."""
        self.part.check_derivable()
        s = _shared({**self._arguments, "segments": segments, "timestep": timestep, "integrator": integrator},
                    chosen_model=True)
        self.part.carry_loads(s.part)
        return s

    @property
    def data(self) -> mujoco.MjData:
        """The scene's MjData (internal units)."""
        return self._data

    @data.setter
    def data(self, data: mujoco.MjData) -> None:
        # a dm_control Physics hands its own MjData to the scene; the views follow it
        self._data = data
        self.part.bind(data)

    # ------------------------------------------------------------------ the beam, SI
    @property
    def length(self) -> float:
        """Free (active) length L of the beam (m), without a rigid tip block."""
        return self.layout.length

    def flexural_rigidity(self, x) -> np.ndarray:
        """EI (N m^2) of the continuum beam at ``x`` (m from the clamp, scalar or array); the
        hinge j carries EI(x_j) / ds of it (``hinge_stiffness``)."""
        x = np.asarray(x, dtype=float)
        if np.any(x < 0) or np.any(x > self.layout.length):
            raise ParameterError("x", x, f"positions in [0, {self.layout.length:g}] m (the free length)")
        return self.actuator.flexural_rigidity_at(x).reshape(x.shape)

    # ------------------------------------------------------------------ state
    @property
    def timestep(self) -> float:
        """Timestep (s)."""
        return self.choice.timestep

    @property
    def time(self) -> float:
        """Simulated time (s)."""
        return self.data.time * self.units.time

    def reset(self, curvature: float = 0.0) -> None:
        """Reset to rest; ``curvature`` (1/m) starts the beam as a uniform arc of that
        curvature (Dadras et al. 2021 starts each experiment from a measured curvature)."""
        mujoco.mj_resetData(self.model, self.data)
        self.part.after_data_reset()         # mj_resetData clears qfrc/xfrc_applied; tip loads persist
        self.part.set_bending_stiffness_scale(1.0)
        if curvature:
            self.part.set_hinge_angles(np.full(self.layout.segments, curvature * self.layout.ds), forward=False)
        mujoco.mj_forward(self.model, self.data)
        #: steps since the last reset (the engines and environments that step it advance it)
        self.step_count = 0

    # ------------------------------------------------------------------ stepping
    def step(self, n: int = 1) -> None:
        """Advance ``n`` steps; raises :class:`DivergenceError` if the state blows up. Internal
        moments set on a beam whose moments follow its geometry (the rod) are applied again
        at each step's configuration."""
        if self.part.holds_moments:
            for _ in range(n):
                self.part.reapply_moments()
                mujoco.mj_step(self.model, self.data)
        else:
            mujoco.mj_step(self.model, self.data, nstep=n)
        self.step_count += n
        self.check_finite()
        self.update_kinematics()

    def update_kinematics(self) -> None:
        """Recompute positions and orientations from the present joint state. mj_step leaves
        them at the state before its integration, one step behind qpos (a phase lag of
        omega dt, 6.5 degrees at 2 kHz with dt = 9 us); the read-outs below use them."""
        mujoco.mj_kinematics(self.model, self.data)

    def run(self, duration: float) -> None:
        """Advance by ``duration`` seconds (rounded to whole steps)."""
        n = int(round(check_positive("duration", duration, "s") / self.timestep))
        self.step(max(n, 1))

    def check_finite(self) -> None:
        if diverged(self.data):
            raise self.divergence_error()

    def divergence_error(self) -> DivergenceError:
        """The error for a run that blew up by the present step: which scene, when, the
        timestep against its stability limit and the mode that sets it; a payload heavier than
        HEAVY_PAYLOAD beams (its unit) is named."""
        c = self.choice
        beam_mass = float(self.layout.link_mass.sum())
        heavy = self.payload is not None and self.payload.mass > HEAVY_PAYLOAD * beam_mass
        return DivergenceError(
            f"{self.actuator.id} ({self.representation}) diverged by step {self.step_count} "
            f"(t = {self.time:.6g} s): timestep {c.timestep:.4g} s, stability limit "
            f"{c.stability_limit:.4g} s set by the highest bending mode ({c.highest_frequency:.4g} Hz) "
            f"under {c.integrator}" + ("; the reference configuration is buckled under gravity"
                                      if c.buckled else "") +
            (f"; the payload, {self.payload.mass:.4g} kg, is {self.payload.mass / beam_mass:.3g} x the beam's mass: "
             "check its unit (SI is kg)" if heavy else "") + ". Reduce the timestep or the load.")

    def settle(self, tol: float = 1e-7, max_periods: int = 400) -> int:
        """Run to static equilibrium under the current loads with extra damping (first-mode
        damping ratio 0.3), returning the number of steps; the tip must move by less than
        ``tol`` x L over one first-mode period. Restores the scene's damping afterwards."""
        view = self.part.view
        saved = view.save_damping()
        view.scale_saved_damping(saved, SETTLING_DAMPING_RATIO / max(self.choice.damping_ratio, 1e-9))
        period = max(1, int(round(1.0 / self.choice.first_frequency / self.timestep)))
        steps, last = 0, self.tip_position()
        try:
            for _ in range(max_periods):
                self.step(period)
                steps += period
                now = self.tip_position()
                if np.linalg.norm(now - last) < tol * self.layout.length:
                    return steps
                last = now
        finally:
            view.restore_damping(saved)
        raise DivergenceError(f"{self.actuator.id}: did not settle within {max_periods} periods "
                              f"(tip still moving by {np.linalg.norm(now - last):.3g} m per period)")

    # ------------------------------------------------------------------ the actuator (its part)
    def __getattr__(self, name):
        # the per-actuator state and read-outs live in the scene's one ActuatorPart
        # (mjeap.simulation.part): hinge angles and rates, internal moments, stiffness, tip loads,
        # clamp-frame read-outs and the ids of the beam's bodies and joints
        if name == "part" or name.startswith("__"):
            raise AttributeError(name)
        return getattr(self.part, name)

    def native_model(self, drive):
        """This beam with ``drive`` (a :class:`mjeap.Drive` of this scene) compiled into the
        model as MuJoCo elements (:mod:`mjeap.drives.native`); built once per drive, parameters
        and hinge parameters (a compile and a stability check, ~10 ms), then reused."""
        from .native_model import NativeModel
        key = (drive.name, repr(sorted(drive.params.items())), self.part.revision)
        cache = self.__dict__.setdefault("_native_models", {})
        if key not in cache:
            cache[key] = NativeModel(self, drive)
        nat = cache[key]
        nat.drive = drive
        return nat

    # ------------------------------------------------------------------ output
    def to_xml(self) -> str:
        """The scene as MJCF text (internal units, as compiled)."""
        return self.spec.to_xml()

    def summary(self) -> dict:
        c = self.choice
        return {"actuator": self.actuator.id, "representation": self.representation,
                "segments": self.layout.segments, "orientation": self.orientation,
                "payload_kg": None if self.payload is None else self.payload.mass,
                "units": self.units.describe(), **c.as_dict()}


def as_scene(scene, name: str = "scene") -> Scene:
    """A Scene from what stands where one is expected: a Scene as it is; a catalog id, an
    actuator file's path or an :class:`~mjeap.model.catalog.Actuator`, its default Scene
    (``Scene(name)``); anything else refused naming ``name``."""
    from pathlib import Path
    if isinstance(scene, Scene):
        return scene
    if isinstance(scene, (str, Path, Actuator)):
        return Scene(scene)
    raise ParameterError(name, type(scene).__name__, "a Scene, a catalog id ('pedot-micro'), an actuator file's path "
                         "(.toml) or an Actuator")


def input_files(actuators=(), voltages=()) -> list:
    """The files a run reads, as (name, path) pairs (:func:`mjeap.io.outputs.check_inputs`:
    none may be an output of the run): the actuator files of ``actuators`` (Scenes,
    Actuators, catalog ids or paths) and the CSVs of ``voltages`` (``csv:PATH`` texts or
    Waveforms)."""
    from pathlib import Path
    from ..model.actuator_file import is_actuator_file
    out = []
    for a in actuators:
        a = getattr(a, "actuator", a)
        f = getattr(a, "source_file", None) if isinstance(a, Actuator) else (
            a if isinstance(a, (str, Path)) and is_actuator_file(a) else None)
        if f:
            out.append(("actuator file", str(f)))
    for v in voltages:
        text = v if isinstance(v, str) else getattr(v, "text", None)
        if isinstance(text, str) and text.strip().lower().startswith("csv:"):
            out.append(("voltage CSV", text.strip()[4:].strip()))
    return out
