"""Catalog of the actuators of the four source documents, in SI, with the source of every
number: actuator files shipped in the package (``mjeap/model/actuators/*.toml``, read by
:mod:`mjeap.model.actuator_file`), so that they read, review and copy as a user's own do.
``SEED_000`` etc. name the documents in ``shared/seeds``; "literature default" marks numbers
the sources do not give. :func:`get_actuator` takes a catalog id or a file's path.
"""
from __future__ import annotations

import dataclasses
import hashlib
import os
import warnings
from pathlib import Path
from typing import Dict, Optional

from ..caching import BoundedCache
from ..errors import ParameterError, UnknownNameError
from .actuator import Actuator, Layer, Planform, Sourced, validate_actuator  # noqa: F401  (the catalog's types)
from .actuator_file import is_actuator_file, read_actuator

SEED_000 = "Dadras et al. 2021, IEEE JMEMS 30(3)"
SEED_001 = "Mutlu, Alici, Li 2013, IEEE/ASME AIM"
SEED_002 = "Metello 2020, MSc thesis"
SEED_003 = "Jayaram et al. 2018, Smart Mater. Struct. 27 065028"


# =========================================================================================
# The catalog: the eight actuators of the four sources, as actuator files in the package
# (mjeap/model/actuators/*.toml, :mod:`mjeap.model.actuator_file`), every number with its
# source. tests/model/test_actuator_files.py checks them against the catalog as it was compiled
# here before (tests/golden/catalog_eaac59e.json).
# =========================================================================================
#: where the catalog's actuator files live (installed with the package)
CATALOG_DIR = Path(__file__).resolve().parent / "actuators"
#: alumina density, literature default (kg/m^3): the PZT bimorphs' tip blocks
ALUMINA_DENSITY = 3900.0
#: the catalog's order (the sources' order)
_ORDER = ("pedot-micro", "ppy-trilayer", "pvdf-60", "pvdf-60-half", "pvdf-130", "pzt-hamr-large", "pzt-hamr-small",
          "pzt-robobee")


def _load_catalog() -> Dict[str, Actuator]:
    found = {p.stem: p for p in CATALOG_DIR.glob("*.toml")}
    order = [k for k in _ORDER if k in found] + sorted(k for k in found if k not in _ORDER)
    out = {}
    for k in order:
        act = read_actuator(found[k])
        out[act.id] = dataclasses.replace(act, source_file=None)      # the catalog's own, by name
    return out


CATALOG: Dict[str, Actuator] = _load_catalog()
PEDOT_MICRO, PPY_TRILAYER = CATALOG["pedot-micro"], CATALOG["ppy-trilayer"]
PVDF_60, PVDF_60_HALF, PVDF_130 = CATALOG["pvdf-60"], CATALOG["pvdf-60-half"], CATALOG["pvdf-130"]
PZT_HAMR_LARGE, PZT_HAMR_SMALL, PZT_ROBOBEE = CATALOG["pzt-hamr-large"], CATALOG["pzt-hamr-small"], CATALOG["pzt-robobee"]


class ActuatorRef(str):
    """An actuator a study resolved once, at its edge: the name it was given (a catalog id or
    an actuator file's path; the text its points, their ids and its CSV carry, as before) and
    the :class:`Actuator` itself (``actuator``), with the SHA-1 of the file's bytes
    (``digest``, hex; None for a catalog id). Wherever an actuator is taken by name
    (:func:`get_actuator`) the object is used and the file is never read again; a point sent
    to a worker process carries it (pickled whole)."""

    def __new__(cls, name: str, actuator: Actuator, digest: Optional[str] = None):
        ref = str.__new__(cls, name)
        ref.actuator, ref.digest = actuator, digest
        return ref

    def __reduce__(self):
        return ActuatorRef, (str(self), self.actuator, self.digest)


def resolve_actuator(name):
    """``name`` (a catalog id or an actuator file's path) resolved once: an
    :class:`ActuatorRef` carrying the Actuator (an ActuatorRef or an Actuator itself is
    returned as it is). A file is read once here (its bytes for the digest and the object
    from them: the same object :func:`get_actuator` gives for the same content)."""
    if isinstance(name, (ActuatorRef, Actuator)) or not isinstance(name, (str, Path)):
        return name
    if is_actuator_file(name):
        data = _file_bytes(name)
        act = file_actuator(str(name), data)     # refused here, naming the file, where it is not one
        return ActuatorRef(str(name), act, None if data is None else hashlib.sha1(data).hexdigest())
    return ActuatorRef(str(name), get_actuator(name))


def get_actuator(name) -> Actuator:
    """An actuator by catalog id or from an actuator file: a name that ends in ``.toml`` or
    holds a path separator is a file (:meth:`Actuator.from_file`), anything else a catalog
    id (an unknown id raises with the closest ids suggested); a catalog id that is also an
    existing file here is refused naming both."""
    if isinstance(name, ActuatorRef):
        return name.actuator
    if isinstance(name, Actuator):
        return validate_actuator(name)
    if is_actuator_file(name):
        return file_actuator(name)
    if not isinstance(name, str):
        raise ParameterError("actuator", name, "a catalog id, an actuator file's path (.toml) or an Actuator")
    if os.path.exists(name):
        raise ParameterError("actuator", name, "a catalog id or an actuator file's path, unambiguous",
                             f"'{name}' is {'the catalog actuator ' + repr(name) + ' and ' if name in CATALOG else ''}"
                             f"a file here: write ./{name} for the file" + (f" or move it to use {name!r}"
                                                                              if name in CATALOG else ""))
    try:
        return CATALOG[name]
    except KeyError:
        raise UnknownNameError("actuator", str(name), CATALOG) from None


#: actuator files read, by the path given, the file it resolves to and a digest of its bytes:
#: the same file read again is the same Actuator object, so every cache keyed on the actuator
#: (layouts, analyses, shared scenes) hits for a file as it does for a catalog id
_FILES = BoundedCache("actuator files", max_entries=64, locked=True)


def file_actuator(path, data: Optional[bytes] = None) -> Actuator:
    """The Actuator of the actuator file ``path`` (:func:`read_actuator`), one object per
    file content: read again, an unchanged file gives the object it gave before (and the
    warnings its reading gave, again); a changed one is read anew. ``data``: the file's bytes
    where the caller has read them already."""
    p = Path(path)
    if data is None:
        data = _file_bytes(p)
    if data is None:                    # read_actuator says what is wrong with it
        return read_actuator(path)
    key = (str(path), os.path.realpath(p), hashlib.blake2b(data, digest_size=16).digest())

    def read():
        with warnings.catch_warnings(record=True) as told:
            warnings.simplefilter("always")
            act = read_actuator(path)
        return act, [(w.message, w.category) for w in told]
    act, told = _FILES.get_or_build(key, read)
    for message, category in told:      # what reading the file warns, every time it is read
        warnings.warn(message, category, stacklevel=3)
    return act


def _file_bytes(path) -> Optional[bytes]:
    """The bytes of the regular file ``path``; None where it is not one or cannot be read
    (:func:`read_actuator` then says why)."""
    p = Path(path)
    try:
        return p.read_bytes() if p.is_file() else None
    except OSError:
        return None


def check_actuator_files(names) -> None:
    """Read every actuator file among ``names`` once (catalog ids, Actuators and the
    :class:`ActuatorRef` of a study pass): a bad file raises, naming the file, the key and what
    is accepted, before any work (a sweep's)."""
    for n in dict.fromkeys(n for n in names if isinstance(n, (str, Path)) and not isinstance(n, ActuatorRef)
                           and is_actuator_file(n)):
        read_actuator(n)


def actuator_ids() -> list:
    return list(CATALOG)
