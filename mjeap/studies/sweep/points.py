"""The points of a sweep (its design of experiments): :data:`PARAMETERS` and their defaults,
:func:`grid` and :func:`random_design`, each point's key (:func:`point_id`), the checks of a
study's names, sizes and fixed settings before any point runs (:func:`check_settings`), and
the Scene and waveform a point's parameters make.

A point is a dict of :data:`PARAMETERS` (scene, waveform and rollout settings, SI) plus
``drive.NAME`` entries for drive parameters and ``actuator.X`` entries for the actuator's
geometry and materials (:mod:`mjeap.model.variants` builds the point's actuator from the base one).
"""
from __future__ import annotations

import hashlib
import itertools
import json
import math
import os
from pathlib import Path
from typing import Dict, Iterable, List, Optional, Sequence

import numpy as np

from ...errors import MjeapError, ParameterError, UnknownNameError

#: the most points one sweep design may have (each is a rollout, and the design is held in
#: memory): a larger design is refused before it is built, naming its count; split it into
#: several sweeps on the same CSV (each resumes past what is there)
MAX_POINTS = 1_000_000
#: the waveforms a sweep point runs: KIND:AMPLITUDE[@FREQUENCY],offset=OFFSET (a chirp needs two
#: frequencies, a csv: waveform a file: both are for mjeap rollout)
SWEEP_WAVEFORMS = ("step", "square", "sine", "triangle")

#: point parameters and their defaults (SI); ``drive.NAME`` entries go to the drive
PARAMETERS: Dict[str, object] = {
    "actuator": "pedot-micro", "representation": "hinge", "segments": 20, "orientation": "horizontal",
    "payload_mass": 0.0, "payload_position": None, "waveform": "square", "amplitude": 1.0, "frequency": 0.1,
    "offset": 0.0, "duration": None, "initial_curvature": 0.0, "damping_ratio": None, "engine": "auto",
    "accuracy": None, "stop_when_periodic": None,
}


def check_names(names: Iterable[str]) -> None:
    for n in names:
        if n not in PARAMETERS and not n.startswith("drive.") and not n.startswith("actuator."):
            raise ParameterError("sweep parameter", n, f"one of {', '.join(PARAMETERS)}, drive.NAME or actuator.NAME "
                                 "(mjeap.model.variants: actuator.length, actuator.layers.LAYER.thickness, ...)")


def check_design_size(count: int, name: str = "design", how: str = "") -> int:
    """``count`` points, refused beyond MAX_POINTS before any of them is built (a ParameterError
    naming the count and the limit; ``how`` says where the count comes from)."""
    if count > MAX_POINTS:
        raise ParameterError(name, f"{count:,} points", f"at most MAX_POINTS = {MAX_POINTS:,} points per sweep "
                             "(split the design into several sweeps on the same CSV)", how)
    return count


def grid(**values: Sequence) -> List[dict]:
    """Full factorial design: every combination of the given values (at most MAX_POINTS,
    refused before the combinations are built)."""
    check_names(values)
    names = list(values)
    lists = [list(values[n]) for n in names]
    check_design_size(math.prod(map(len, lists)), "grid", " x ".join(f"{n}: {len(v)}" for n, v in zip(names, lists)))
    return [dict(zip(names, combo)) for combo in itertools.product(*lists)]


def random_design(n: int, seed: int = 0, **ranges) -> List[dict]:
    """``n`` points, each parameter drawn uniformly from a (low, high) range or a list of
    choices, with numpy's generator seeded by ``seed``."""
    check_names(ranges)
    if int(n) < 1:
        raise ParameterError("n", n, "a positive number of points")
    check_design_size(int(n), "n", "random points")
    rng = np.random.default_rng(seed)
    cols = {}
    for k, v in ranges.items():
        if isinstance(v, tuple) and len(v) == 2 and all(isinstance(x, (int, float)) for x in v):
            cols[k] = rng.uniform(v[0], v[1], int(n)).tolist()
        else:
            choices = list(v)
            cols[k] = [choices[i] for i in rng.integers(0, len(choices), int(n))]
    return [{k: cols[k][i] for k in ranges} for i in range(int(n))]


def settings(base: Optional[dict] = None, metrics: Sequence[str] = ()) -> dict:
    """Everything besides a point's own parameters that changes its row: the fixed
    parameters (``base`` over the defaults), the metrics and the package version."""
    from ...versions import MJEAP_VERSION
    return {"base": {**PARAMETERS, **(base or {})}, "metrics": sorted(metrics), "mjeap": MJEAP_VERSION}


def point_id(point: dict, base: Optional[dict] = None, metrics: Sequence[str] = ()) -> str:
    """Stable key of a point: hash of its parameters and of the sweep's :func:`settings`
    (JSON, sorted keys), so that a rerun with other fixed settings computes its points."""
    key = {"point": point, "settings": settings(base, metrics)}
    digest = _actuator_file_digest({**PARAMETERS, **(base or {}), **point}["actuator"])
    if digest is not None:              # a file's content, not only its name (catalog ids: as before)
        key["actuator_file"] = digest
    return hashlib.sha1(json.dumps(key, sort_keys=True, default=float).encode()).hexdigest()[:12]


_FILE_DIGESTS: Dict[tuple, str] = {}


def _actuator_file_digest(actuator) -> Optional[str]:
    """SHA-1 of an actuator file's bytes (None: a catalog id, an Actuator or no such file),
    so that a point of an edited file is computed again; cached by path, size and mtime."""
    from ...model.actuator_file import is_actuator_file
    from ...model.catalog import ActuatorRef
    if isinstance(actuator, ActuatorRef):           # resolved at the study's edge: its digest, no read
        return None if actuator.digest is None else actuator.digest[:16]
    if not isinstance(actuator, (str, Path)) or not is_actuator_file(actuator):
        return None
    try:
        st = os.stat(actuator)
    except OSError:
        return None
    k = (os.path.realpath(actuator), st.st_size, st.st_mtime_ns)
    if k not in _FILE_DIGESTS:
        try:
            _FILE_DIGESTS[k] = hashlib.sha1(Path(actuator).read_bytes()).hexdigest()[:16]
        except OSError:
            return None
    return _FILE_DIGESTS[k]


def resolve_actuators(points: Sequence[dict], base: Optional[dict]):
    """(points, base) with every ``actuator`` resolved once (:func:`mjeap.model.catalog.resolve_actuator`:
    the name kept, the Actuator carried): each file is read here, once, and never again by the
    points, their scenes, variants or ids, in this process or a worker's. An actuator that
    does not resolve (an unknown id) stays as given: the checks or its points report it."""
    from ...model.catalog import resolve_actuator
    done: Dict[object, object] = {}

    def resolved(name):
        key = name if isinstance(name, (str, Path)) else id(name)
        if key not in done:
            try:
                done[key] = resolve_actuator(name)
            except MjeapError:
                done[key] = name
        return done[key]
    if base is not None and "actuator" in base:
        base = {**base, "actuator": resolved(base["actuator"])}
    return [{**p, "actuator": resolved(p["actuator"])} if "actuator" in p else p for p in points], base


def check_settings(points: Sequence[dict], base: Optional[dict]) -> None:
    """Every name in ``base`` is a sweep parameter, and every ``drive.NAME`` (in base or the
    points) a parameter of the actuator's drive; else UnknownNameError with the closest."""
    from ...drives import default_drive_name, get_drive_class
    base = base or {}
    for n in base:
        if n not in PARAMETERS and not n.startswith("drive.") and not n.startswith("actuator."):
            raise UnknownNameError("fixed sweep setting (--set / base)", n,
                                   [*PARAMETERS, "drive.NAME", "actuator.NAME"])
    from ...model.catalog import check_actuator_files      # a bad actuator file: refused before any point
    check_actuator_files({**PARAMETERS, **base, **p}["actuator"] for p in points or [{}])
    _check_designs(points, base)
    _check_fixed(points, base)
    for p in points:
        full = {**PARAMETERS, **base, **p}
        if full["stop_when_periodic"] not in (None, ""):      # refused once, not in every row
            _check_stop(full)
        names = [k[6:] for k in full if k.startswith("drive.")]
        if not names:
            continue
        act = str(full["actuator"])
        try:
            from ...model.actuator_file import is_actuator_file
            from ...model.catalog import get_actuator
            cls = get_drive_class(default_drive_name(get_actuator(act) if is_actuator_file(act) else act))
        except MjeapError:
            continue              # a user actuator or an unknown one: the point reports it
        known = list(cls.parameter_units()) + list(cls.extra_parameters(None))
        for n in names:
            if n not in known:
                raise UnknownNameError(f"{cls.name} drive parameter (drive.NAME)", n, known)


def _check_designs(points: Sequence[dict], base: dict) -> None:
    """The ``actuator.X`` parameters of a study (:mod:`mjeap.model.variants`), checked before any
    point runs: each name against its point's base actuator, every value against its range,
    and the actuator of each base actuator's first point built (its sizes and its drive's
    layer stack)."""
    from ...model import variants
    by_actuator: Dict[str, Dict[str, list]] = {}
    firsts: Dict[str, dict] = {}
    for p in points or [{}]:
        full = {**PARAMETERS, **base, **p}
        names = [k for k in full if variants.is_design_parameter(k)]
        if not names:
            continue
        act = full["actuator"]
        key = act if isinstance(act, str) else repr(act)
        vals = by_actuator.setdefault(key, {})
        firsts.setdefault(key, {"actuator": act, **{k: full[k] for k in names}})
        for k in names:
            vals.setdefault(k, []).append(full[k])
    for key, vals in by_actuator.items():
        act = firsts[key]["actuator"]
        try:
            variants.get_base(act)
        except MjeapError:
            continue                # an unknown actuator: each point reports it
        variants.check_design(act, {name: list(dict.fromkeys(values)) for name, values in vals.items()})
        variants.design_actuator(act, {k: v for k, v in firsts[key].items() if k != "actuator"})


def _check_fixed(points: Sequence[dict], base: dict) -> None:
    """The fixed settings (``base``, ``--set``) every point shares, checked once before any
    point runs, as each point would check them (each would fail the same way): ``accuracy``
    a target in the accepted range (or None), ``waveform`` one of SWEEP_WAVEFORMS,
    ``duration`` finite and > 0 s and, where no point varies it (and without an accuracy
    target, which chooses the step), at most MAX_STEPS steps of the first point's scene."""
    from ...engines.frame import MAX_STEPS
    from ...errors import check_positive
    from ...simulation.accuracy import check_accuracy
    fixed = "a fixed sweep setting (--set / base): every point would fail with it"
    try:
        if base.get("accuracy") not in (None, ""):
            check_accuracy(base["accuracy"])
        if "waveform" in base and str(base["waveform"]).strip().lower() not in SWEEP_WAVEFORMS:
            raise ParameterError("waveform", base["waveform"], f"one of {', '.join(SWEEP_WAVEFORMS)} (a point's "
                                 "waveform is KIND:amplitude@frequency,offset=offset from its parameters; a csv: or "
                                 "chirp waveform is for mjeap rollout --voltage)")
        if base.get("duration") not in (None, ""):
            duration = check_positive("duration", base["duration"], "s")
            if points and not any("duration" in p for p in points) and \
                    {**PARAMETERS, **base, **points[0]}["accuracy"] in (None, ""):
                try:
                    scene = point_scene({**PARAMETERS, **base, **points[0]})
                except MjeapError:
                    scene = None               # the point reports its own scene's error
                if scene is not None:
                    dt = scene.timestep
                    if not dt <= duration <= MAX_STEPS * dt:       # check_work's bounds, without --max-steps
                        raise ParameterError("duration", f"{duration:g} s", f"one step to {MAX_STEPS:,} steps of "
                                             f"{dt:.4g} s ({dt:.4g} s to {MAX_STEPS * dt:.4g} s) for the first "
                                             "point's scene", f"{duration / dt:,.0f} steps")
    except ParameterError as e:
        raise ParameterError(f"{e.name} (--set / base)", e.value, e.accepted,
                             f"{e.why}; {fixed}" if e.why else fixed) from None


#: the parameters a point's scene is built from (with the design parameters, ``actuator.*``);
#: the others are its drive's and its run's
SCENE_PARAMETERS = ("actuator", "representation", "segments", "orientation", "payload_mass", "payload_position",
                    "damping_ratio", "accuracy")


def scene_key(p: dict) -> str:
    """What a point's scene is built from (its full parameters ``p``), as text: points with
    the same key share a scene (:func:`point_scene`)."""
    from ...model.variants import is_design_parameter
    return json.dumps({k: v for k, v in p.items() if k in SCENE_PARAMETERS or is_design_parameter(k)},
                      sort_keys=True, default=str)


def point_scene(p: dict):
    """The Scene of a point's full parameters (``base`` and the defaults filled in), shared
    with the earlier points of the same scene in this thread (:meth:`Scene.shared`)."""
    from ...model.discretize import Payload
    from ...simulation.scene import Scene
    payload = None
    if p["payload_mass"]:
        pos = p["payload_position"]
        if pos is None:
            raise ParameterError("payload_position", None, "a position in m when payload_mass > 0")
        payload = Payload(float(p["payload_mass"]), float(pos))
    from ...model.variants import design_actuator, is_design_parameter
    act = p["actuator"]
    if any(is_design_parameter(k) for k in p):
        act = design_actuator(act, p)
    return Scene.shared(act, representation=p["representation"], segments=int(p["segments"]),
                        orientation=p["orientation"], payload=payload, damping_ratio=p["damping_ratio"],
                        accuracy=None if p["accuracy"] in (None, "") else float(p["accuracy"]))


def wave_text(p: dict) -> str:
    """The waveform text of a point's parameters (mjeap.drives.waveforms)."""
    f, a = float(p["frequency"]), float(p["amplitude"])
    return f"step:{a!r}V" if p["waveform"] == "step" else \
        f"{p['waveform']}:{a!r}V@{f!r}Hz,offset={float(p['offset'])!r}V"


def point_duration(p: dict) -> float:
    """A point's duration (s): its own, else two drive periods."""
    return float(p["duration"]) if p["duration"] not in (None, "") else 2.0 / float(p["frequency"])


def _check_stop(p: dict) -> None:
    """A point's periodic stop, as its rollout will check it (mjeap.simulation.rollout.check_stop)."""
    from ...drives.waveforms import parse_waveform
    from ...simulation.rollout import check_stop
    check_stop(float(p["stop_when_periodic"]), parse_waveform(wave_text(p)), point_duration(p),
               at_accuracy=p["accuracy"] not in (None, ""))
