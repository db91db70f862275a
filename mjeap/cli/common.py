"""What the commands share: reading an actuator (its warnings told as one line), a scene from the
command line's options, drive parameters, repeated options refused, printable text."""
from __future__ import annotations

import argparse
import json
import sys


from ..errors import ParameterError, printable


def fmt(v: float) -> str:
    return f"{v:.4g}"


def told_actuator(name):
    """The actuator a command names (catalog id or file), read before any work; a layer value
    outside its material's range (RangeWarning) or a size outside a plausible one
    (GeometryWarning) is told as one line, ``mjeap: warning: ...``."""
    import warnings
    from ..model.actuator import GeometryWarning
    from ..model.catalog import get_actuator
    from ..model.materials import RangeWarning
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        act = get_actuator(name)
    for w in caught:
        if issubclass(w.category, (RangeWarning, GeometryWarning)):
            print(f"mjeap: warning: {printable(w.message)}", file=sys.stderr)
        else:
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return act


def actuator_file_of(a) -> str:
    """Where ``a`` comes from: its file, or the catalog's file of a catalog id."""
    from ..model.catalog import CATALOG_DIR
    return a.source_file or f"{CATALOG_DIR / (a.id + '.toml')} (catalog)"


def printable_tree(x):
    """``x`` (dicts, lists, tuples of values) with every string :func:`~mjeap.errors.printable`."""
    if isinstance(x, str):
        return printable(x)
    if isinstance(x, dict):
        return {printable(k): printable_tree(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return type(x)(printable_tree(v) for v in x)
    return x


def scene_from_args(args, units=None):
    from ..model.discretize import Payload
    from ..simulation.scene import Scene
    payload = Payload.parse(args.payload) if args.payload else None
    from ..simulation.scene import DEFAULT_SEGMENTS
    return Scene(told_actuator(args.name), representation=args.representation,
                 segments=DEFAULT_SEGMENTS if args.segments is None else args.segments,
                 orientation=args.orientation, payload=payload, timestep=args.timestep,
                 integrator=args.integrator, units=units)


def drive_params_from(pairs) -> dict:
    params = {}
    for kv in pairs or []:
        k, sep, v = kv.partition("=")
        if not sep or not k.strip() or not v.strip():
            raise ParameterError("--param", kv, "NAME=VALUE, e.g. --param gain=63")
        try:
            params[k] = json.loads(v)
        except json.JSONDecodeError:
            params[k] = v
    return params


def report_extra() -> bool:
    import importlib.util
    return importlib.util.find_spec("matplotlib") is not None


#: how a command's actuator argument reads
ACTUATOR_HELP = ("catalog id (mjeap list) or actuator file: a name ending in .toml or holding a path separator "
                 "is a file (./NAME for a file named like an id)")


def add_scene_args(p: argparse.ArgumentParser) -> None:
    from ..model.mjcf import REPRESENTATIONS
    from ..model.discretize import ORIENTATIONS
    from ..simulation.scene import DEFAULT_SEGMENTS, INTEGRATORS
    p.add_argument("name", help=ACTUATOR_HELP)
    p.add_argument("--segments", type=int, default=None,
                   help=f"number of segments (>= 2; default {DEFAULT_SEGMENTS}; chosen by --accuracy where given)")
    p.add_argument("--representation", choices=REPRESENTATIONS, default="hinge")
    p.add_argument("--payload", help="tip payload MASS@POSITION[,point|,r=RADIUS|,I=INERTIA], e.g. 12.6mg@6.27mm "
                   "(NdFeB sphere) or 12.6mg@6.27mm,point (no rotary inertia); gravity loads it in the bending "
                   "plane only with --orientation up or down")
    p.add_argument("--orientation", choices=ORIENTATIONS, default="horizontal",
                   help="horizontal (default: the bending plane horizontal, gravity across the width, out of the "
                        "bending plane), up (the beam against gravity) or down (hanging along it)")
    p.add_argument("--timestep", type=float, help="timestep in s (default: chosen from the model)")
    p.add_argument("--integrator", choices=list(INTEGRATORS), default=None,
                   help="default: the representation's own (implicitfast; the rod: discrete)")


def once(flag: str, specs, form: str = "NAME=VALUE") -> dict:
    """``NAME=VALUE`` options (``--set``, ``--vary``) as name -> value text, before any work:
    each NAME once (a repeated one would silently keep the last), none empty."""
    out = {}
    for spec in specs or []:
        name, sep, rhs = spec.partition("=")
        name = name.strip()
        if not sep or not name:
            raise ParameterError(flag, spec, form)
        if name in out:
            raise ParameterError(flag, spec, f"each NAME once ({name} is given twice: {flag} {name}={out[name]} "
                                 f"and {flag} {spec})")
        out[name] = rhs.strip()
    return out


def distinct(vary: dict, fixed: dict) -> None:
    """A name varied (--vary) is not also fixed (--set)."""
    both = [n for n in vary if n in fixed]
    if both:
        raise ParameterError("--set", f"{both[0]}={fixed[both[0]]}", f"a setting that is not also varied "
                             f"(--vary {both[0]}=...)")
