"""The interface every engine implements (:mod:`mjeap.engines`)."""
from __future__ import annotations

from typing import Any, List, Optional, Protocol, Sequence, runtime_checkable

__all__ = ["Engine", "CONTROLLER_REASON", "Target", "SceneTarget", "SystemTarget"]


@runtime_checkable
class Target(Protocol):
    """What an engine steps: a compiled ``model`` and its ``data`` (internal units), the
    ``timestep`` (s), a public ``step_count`` (steps since the last reset, which the engine
    advances) and a divergence check (raises :class:`mjeap.errors.DivergenceError`)."""

    model: Any
    data: Any
    step_count: int

    @property
    def timestep(self) -> float: ...

    def check_finite(self) -> None: ...


@runtime_checkable
class SceneTarget(Target, Protocol):
    """One actuator's scene (:class:`mjeap.Scene`): its part, beam builder and units, reset
    to an arc, kinematics, its divergence error and its native model (a drive compiled in)."""

    part: Any
    builder: Any
    units: Any

    @property
    def bend_dof(self) -> Any: ...

    def reset(self, curvature: float = 0.0) -> None: ...

    def update_kinematics(self) -> None: ...

    def divergence_error(self) -> Exception: ...

    def native_model(self, drive) -> Any: ...


@runtime_checkable
class SystemTarget(Target, Protocol):
    """Several actuators in one model (:class:`mjeap.System`): their parts, attached
    actuators and the ids of their MuJoCo actuators (-1: passive), its units; reset to arcs,
    a controller's voltages checked and held, the contact forces on its bodies
    (:class:`mjeap.engines.system_frame.SystemRun` steps it)."""

    parts: List[Any]
    actuators: List[Any]
    actuator_ids: List[int]
    units: Any

    def reset(self, initial_curvatures: Any = 0.0) -> None: ...

    def hold_voltages(self, voltages: Any, v_steps: Sequence, k: int, who: str) -> None: ...

    def contact_forces(self) -> Any: ...

#: why an engine that precomputes the run (native, threaded) cannot take a controller
CONTROLLER_REASON = "a controller closes the loop (its voltage depends on the state)"


class Engine:
    """One way of stepping a run (internal units, the model's timestep): of a scene
    (:meth:`run`, a :class:`SceneTarget`), of a system of actuators (:meth:`run_system`, a
    :class:`SystemTarget`) or of an environment, step by step (:meth:`advance`). It advances
    the target's public ``step_count``. An engine that offers only some says why not for the
    others."""

    #: registry name
    name: str = ""
    #: runs several rollouts in one call (``rollout_batch``)
    batched: bool = False

    def why_not(self, scene: SceneTarget, drive, controller=None) -> Optional[str]:
        """None where this engine applies to a run of ``scene`` with ``drive`` (and
        ``controller``); else the reason, in words."""
        return None

    def part(self, scene: SceneTarget, drive):
        """The actuator part (:class:`mjeap.simulation.part.ActuatorPart`) whose state the samples
        read: the scene's own unless the engine steps another model."""
        return scene.part

    def run(self, scene: SceneTarget, drives: Sequence, v_steps: Sequence, initial_curvatures: Sequence[float],
            sample_steps, samples: Sequence, *, nthread: int = 0, progress: Optional[bool] = None,
            check_every: int = 100, controller=None, meta: Optional[dict] = None) -> None:
        """Roll out one run per drive (its voltage per step, initial curvature 1/m and sample
        store), filling the stores; raises DivergenceError at the first diverged state and
        leaves the scene in the final state of the last run."""
        raise NotImplementedError

    def system_reason(self, system: SystemTarget, controller=None, on_sample=None) -> Optional[str]:
        """None where this engine runs ``system`` (a :class:`mjeap.System`: the drives
        compiled in, one ctrl per actuator); else why not."""
        return f"the {self.name} engine runs one actuator's scene, not a System"

    def run_system(self, system: SystemTarget, n_steps: int, sample_steps, before, sample, check) -> None:
        """Step ``system`` ``n_steps`` times: ``before(k)`` sets the ctrl held over step k,
        ``check(k + 1, k)`` raises on a diverged state, ``sample(i, k)`` samples after step k
        = ``sample_steps[i]`` (:func:`mjeap.engines.frame.lockstep`'s contract)."""
        raise NotImplementedError(self.system_reason(system))

    def advance(self, scene: SceneTarget, drive, voltage: float, nstep: int = 1) -> None:
        """``nstep`` steps of ``scene`` with ``drive`` at a held ``voltage`` (V): an
        environment's step. No divergence check, no kinematics update."""
        raise NotImplementedError(f"the {self.name} engine does not step environments")
