"""The ``mjeap`` command line: one module per kind of command (:mod:`mjeap.cli.actuators`,
:mod:`~mjeap.cli.runs`, :mod:`~mjeap.cli.studies`, :mod:`~mjeap.cli.identify`), each adding its
parsers (``add_parsers``); what they share in :mod:`mjeap.cli.common`. A new command is a
``cmd_NAME`` and its parser in the module of its kind."""
from __future__ import annotations

import argparse
import sys
from typing import List, Optional

from ..io.commandline import run_command
from . import actuators, identify, runs, studies
from .actuators import describe

__all__ = ["main", "build_parser", "describe"]

#: the commands' modules, in the order ``mjeap --help`` lists them
MODULES = (actuators, runs, studies, identify)


def build_parser() -> argparse.ArgumentParser:
    """The ``mjeap`` parser: every module's commands."""
    ap = argparse.ArgumentParser(prog="mjeap", description="The ``mjeap`` command line.")
    sub = ap.add_subparsers(dest="command", required=True)
    for module in MODULES:
        module.add_parsers(sub)
    return ap


def _told(func):
    """Run ``func`` with a material's range warnings (a layer's value, a field past its
    limit: :class:`mjeap.model.materials.RangeWarning`) told as one line each,
    ``mjeap: warning: ...``, once per text; other warnings as Python tells them."""
    import warnings
    from ..model.materials import RangeWarning
    told, plain = set(), warnings.showwarning

    def show(message, category, filename, lineno, file=None, line=None):
        if not issubclass(category, RangeWarning):
            return plain(message, category, filename, lineno, file, line)
        if str(message) not in told:
            told.add(str(message))
            print(f"mjeap: warning: {message}", file=sys.stderr)

    with warnings.catch_warnings():
        warnings.showwarning = show
        return func()


def main(argv: Optional[List[str]] = None) -> int:
    def command() -> int:
        args = build_parser().parse_args(argv)
        return _told(lambda: args.func(args))
    return run_command(command)
