"""Quantities with units, as people write them in files: ``"10 mm"``, ``"40 GPa"``,
``"7500 kg/m^3"``, ``"32 Pa m/V"``, ``"1/(m s)"``; a bare number is SI.

A unit is a product of prefixed units with integer powers, ``/`` dividing by the next
factor (or a parenthesised group): ``kg/m^3``, ``m^2/V^2``, ``N m / rad``. Known units: m, g,
s, A, Hz, N, Pa, J, W, C, V, F, S (siemens), ohm (or Ω), rad, deg (or °), and ``-`` for
none; prefixes G, M, k, c, m, u (µ), n, p. A quantity is checked against the unit expected
(its dimension must match) and returned in SI. A CSV column's header ``name (unit)`` (or
``name [unit]``) is read the same way (:func:`column_scale`).
"""
from __future__ import annotations

import math
import re
from typing import Optional, Tuple

import numpy as np

from ..errors import ParameterError

__all__ = ["parse_unit", "to_si", "same_dimension", "split_header", "column_scale"]

# (factor to SI, dimension exponents of m, kg, s, A)
_BASE = {
    "m": (1.0, (1, 0, 0, 0)), "g": (1e-3, (0, 1, 0, 0)), "s": (1.0, (0, 0, 1, 0)), "A": (1.0, (0, 0, 0, 1)),
    "Hz": (1.0, (0, 0, -1, 0)), "N": (1.0, (1, 1, -2, 0)), "Pa": (1.0, (-1, 1, -2, 0)),
    "J": (1.0, (2, 1, -2, 0)), "W": (1.0, (2, 1, -3, 0)), "C": (1.0, (0, 0, 1, 1)),
    "V": (1.0, (2, 1, -3, -1)), "F": (1.0, (-2, -1, 4, 2)), "ohm": (1.0, (2, 1, -3, -2)),
    "Ω": (1.0, (2, 1, -3, -2)), "S": (1.0, (-2, -1, 3, 2)), "rad": (1.0, (0, 0, 0, 0)),
    "deg": (math.pi / 180.0, (0, 0, 0, 0)), "°": (math.pi / 180.0, (0, 0, 0, 0)),
}
_PREFIX = {"G": 1e9, "M": 1e6, "k": 1e3, "c": 1e-2, "m": 1e-3, "u": 1e-6, "µ": 1e-6, "n": 1e-9, "p": 1e-12}
_NONE = (1.0, (0, 0, 0, 0))
_TOKEN = re.compile(r"\s*(\(|\)|/|\*|\^-?\d+|[A-Za-zµΩ°]+|1|\s)")
_NUMBER = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?|[-+]?inf|nan)\s*(.*?)\s*$", re.IGNORECASE)


def _atom(word: str) -> Tuple[float, tuple]:
    if word in _BASE:
        return _BASE[word]
    if len(word) > 1 and word[0] in _PREFIX and word[1:] in _BASE:
        f, d = _BASE[word[1:]]
        return _PREFIX[word[0]] * f, d
    raise ValueError(word)


def parse_unit(text: str) -> Tuple[float, tuple]:
    """(factor to SI, dimension exponents (m, kg, s, A)) of a unit expression; ``""``, ``"-"``
    and ``"1"`` are dimensionless. Raises ValueError on what it cannot read."""
    text = text.strip()
    if text in ("", "-", "1"):
        return _NONE
    tokens = [t for t in _TOKEN.findall(text) if t.strip()]
    if "".join(tokens) != re.sub(r"\s+", "", text):
        raise ValueError(text)
    pos = 0

    def product():
        nonlocal pos
        factor, dim = 1.0, np.zeros(4)
        sign = 1
        while pos < len(tokens) and tokens[pos] != ")":
            t = tokens[pos]
            if t == "/":
                sign, pos = -1, pos + 1
                continue
            if t == "*":
                pos += 1
                continue
            if t == "(":
                pos += 1
                f, d = product()
                if pos >= len(tokens) or tokens[pos] != ")":
                    raise ValueError(text)
                pos += 1
            elif t == "1":
                f, d, pos = 1.0, np.zeros(4), pos + 1
            else:
                f, d = _atom(t)
                d, pos = np.array(d, float), pos + 1
            if pos < len(tokens) and tokens[pos].startswith("^"):
                p = int(tokens[pos][1:])
                f, d, pos = f ** p, d * p, pos + 1
            factor *= f ** sign
            dim = dim + sign * np.asarray(d, float)
            sign = 1
        return factor, dim

    factor, dim = product()
    if pos != len(tokens):
        raise ValueError(text)
    return factor, tuple(int(round(x)) for x in dim)


def same_dimension(a: str, b: str) -> bool:
    """Whether unit expressions ``a`` and ``b`` measure the same quantity."""
    return parse_unit(a)[1] == parse_unit(b)[1]


def to_si(value, unit: str, where: str) -> float:
    """``value`` in SI for the expected ``unit``: a bare number is SI already; a string is a
    number and a unit of the same dimension (``"10 mm"`` for ``m``). Refused with a
    ParameterError naming ``where`` (file and key) and the unit expected."""
    if isinstance(value, bool):
        raise ParameterError(where, value, f"a number in {unit} (SI) or a string with a unit, e.g. '1.5 {unit}'")
    if isinstance(value, (int, float)):
        try:
            v = float(value)
        except OverflowError:                      # an integer of hundreds of digits
            raise ParameterError(where, f"an integer of {len(str(abs(value)))} digits",
                                 f"a finite quantity in {unit}") from None
    elif isinstance(value, str):
        m = _NUMBER.match(value)
        if m is None:
            raise ParameterError(where, value, f"a number with a unit of {unit}, e.g. '1.5 {unit}'")
        try:
            f, d = parse_unit(m.group(2))
            _, want = parse_unit(unit)
        except ValueError:
            raise ParameterError(where, value, f"a unit of {unit} (known units: {', '.join(_BASE)}; prefixes "
                                 f"{', '.join(_PREFIX)})", "the unit does not parse") from None
        if m.group(2).strip() in ("", "-") and want != (0, 0, 0, 0):
            f, d = 1.0, want                                  # a bare number in a string: SI
        if d != want:
            raise ParameterError(where, value, f"a quantity in {unit}", f"'{m.group(2)}' is another dimension")
        try:
            v = float(m.group(1)) * f
        except OverflowError:  # pragma: no cover - float() of text gives inf, not this
            v = math.inf
    else:
        raise ParameterError(where, value, f"a number in {unit} (SI) or a string with a unit")
    if not math.isfinite(v):
        raise ParameterError(where, value, f"a finite quantity in {unit}")
    return v


_HEADER = re.compile(r"^\s*(.*?)\s*(?:\(([^()]*)\)|\[([^\[\]]*)\])\s*$")


def split_header(header: str) -> Tuple[str, str]:
    """(name, unit) of a CSV header ``name (unit)`` or ``name [unit]``; the unit '' where
    there is none ('time' -> ('time', ''))."""
    m = _HEADER.match(header)
    if m is None:
        return header.strip(), ""
    return m.group(1), (m.group(2) if m.group(2) is not None else m.group(3)).strip()


def column_scale(header: str, unit: Optional[str], where: str) -> float:
    """The factor that turns column ``header``'s numbers into SI ``unit`` (its dimension):
    1 for a header without a unit (read as SI), else the unit's factor, e.g. 1e-3 for
    'time (ms)' read as 's'. An unknown unit, or one of another dimension, is refused with a
    ParameterError naming the column (``where``: the file); ``unit`` None: any dimension."""
    name, text = split_header(header)
    if not text or text in ("-", "SI"):
        return 1.0
    try:
        f, d = parse_unit(text)
    except ValueError:
        raise ParameterError(f"column '{header}' of {where}", text, f"a unit{' of ' + unit if unit else ''} mjeap "
                             f"reads (units: {', '.join(_BASE)}; prefixes {', '.join(_PREFIX)})",
                             "an unknown unit; nothing was read") from None
    if unit is not None and d != parse_unit(unit)[1]:
        raise ParameterError(f"column '{header}' of {where}", text, f"a unit of {unit} (the column's quantity)",
                             f"'{text}' measures another quantity")
    return f
