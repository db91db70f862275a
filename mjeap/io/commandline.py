"""Command lines of mjeap and its scripts: a command run with mjeap's exit codes and
one-line errors (:func:`run_command`, :func:`run_script`), and argparse checks that refuse a
bad argument at parse time, before any work (:func:`arg_integer`, :func:`arg_number`,
:func:`arg_output`, :func:`parse_args`). ``mjeap``'s own commands (:mod:`mjeap.cli`), the
robots' experiments, the environments' episodes, the stability map and the scripts all use
them; they import nothing above the io layer."""
from __future__ import annotations

import argparse
import errno
import os
import sys
from pathlib import Path
from typing import Callable, List, Optional

from ..errors import MjeapError, ParameterError, printable

#: the errors of a disk or system refusing a write: a command says them in one line
DISK_ERRORS = frozenset({errno.ENOSPC, errno.EDQUOT, errno.EROFS, errno.EPERM, errno.EACCES, errno.EIO, errno.EFBIG})


# ---------------------------------------------------------------- running a command
#: exit codes of an interrupted command: 128 + the signal's number, as a shell reports it
EXIT_CTRL_C, EXIT_SIGTERM = 130, 143
#: exit code when stdout's reader went away (128 + SIGPIPE, as a shell reports it)
EXIT_BROKEN_PIPE = 141


def run_command(call: Callable[[], Optional[int]], prog: str = "mjeap") -> int:
    """Run ``call()`` as a command and return its exit code (None: 0). mjeap's own errors
    print one line, ``PROG: error: ...``, and exit 2. Ctrl-C or SIGTERM, anywhere in the
    command (:class:`~mjeap.errors.sigterm_as_interrupt`), print one line and exit 130 /
    143, without a traceback; what was written stays (a rollout writes its recording and
    CSV on its way out, a sweep has its finished rows)."""
    from ..errors import Terminated, sigterm_as_interrupt
    try:
        with sigterm_as_interrupt():
            code = call()
            sys.stdout.flush()              # a closed pipe is told here, not at the interpreter's exit
    except MjeapError as e:
        print(f"{prog}: error: {printable(e)}", file=sys.stderr)
        for note in getattr(e, "__notes__", ()):      # e.g. an output that could not be written too
            print(f"{prog}: error: {printable(note)}", file=sys.stderr)
        return 2
    except BrokenPipeError:                 # an OSError: caught before the clause below
        # the reader of stdout went away (``mjeap ... | head``): say once on stderr that the rest
        # of stdout is dropped (an output sent to stdout included), and point stdout at
        # /dev/null so that Python's exit flush is quiet
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        print(f"{prog}: stdout was closed by its reader; the rest of what was to go there is dropped",
              file=sys.stderr)
        return EXIT_BROKEN_PIPE
    except OSError as e:
        # a disk or system refusing a write outside mjeap's writer: one line, never a traceback
        if e.errno not in DISK_ERRORS:
            raise
        print(f"{prog}: error: {printable(e.filename or '')}{': ' if e.filename else ''}"
              f"{e.strerror or e}", file=sys.stderr)
        return 2
    except KeyboardInterrupt as e:
        term = isinstance(e, Terminated)
        print(f"{prog}: interrupted ({'SIGTERM' if term else 'Ctrl-C'}); stopped, outputs written so far are kept",
              file=sys.stderr)
        for note in getattr(e, "__notes__", ()):
            print(f"{prog}: error: {printable(note)}", file=sys.stderr)
        return EXIT_SIGTERM if term else EXIT_CTRL_C
    return 0 if code is None else int(code)


def run_script(main: Callable[[Optional[List[str]]], Optional[int]], argv: Optional[List[str]] = None) -> int:
    """A script's ``main(argv)`` as a command (:func:`run_command`), named after the script:
    ``sys.exit(run_script(main))``."""
    return run_command(lambda: main(argv), Path(sys.argv[0]).name or "mjeap")


# ---------------------------------------------------------------- argparse checks for scripts
def _argument_type(check: Callable[[str], object]) -> Callable[[str], object]:
    """An argparse ``type=``: ``check(text)``, its ParameterError told the argparse way
    (usage, ``argument --NAME: 'TEXT' is not accepted: expected ...``, exit 2), at parse
    time, so before any work."""
    def convert(text: str):
        try:
            return check(text)
        except ParameterError as e:
            raise argparse.ArgumentTypeError(f"{text!r} is not accepted: expected {e.accepted}"
                                             + (f" ({e.why})" if e.why else "")) from None
    convert.__name__ = getattr(check, "__name__", "value")
    return convert


def arg_integer(lo: int, hi: Optional[int] = None, why: str = ""):
    """argparse ``type=``: an integer in [lo, hi] (:func:`mjeap.errors.check_integer`)."""
    from ..errors import check_integer
    return _argument_type(lambda text: check_integer("", text, lo, hi, why))


def arg_number(lo: float, hi: float, unit: str = "", lo_open: bool = False, hi_open: bool = False):
    """argparse ``type=``: a number in the interval (:func:`mjeap.errors.check_range`)."""
    from ..errors import check_range
    return _argument_type(lambda text: check_range("", text, lo, hi, unit, lo_open, hi_open))


def arg_output(inside: Optional[str] = None):
    """argparse ``type=``: an output path that can be written (its folder made now), or,
    with ``inside``, a folder in which the file ``inside`` can be written
    (:func:`mjeap.io.outputs.check_outputs`). Returns the text."""
    from .outputs import check_outputs

    def check(text: str) -> str:
        check_outputs(out=Path(text) / inside if inside else text)
        return text
    return _argument_type(check)


def parse_args(ap: argparse.ArgumentParser, argv: Optional[List[str]] = None,
               check: Optional[Callable[[argparse.Namespace], None]] = None) -> argparse.Namespace:
    """``ap.parse_args(argv)``, then ``check(args)``: checks across arguments that raise
    ParameterError, refused as argparse refuses a bad argument (usage, one line, exit 2)."""
    args = ap.parse_args(argv)
    if check is not None:
        try:
            check(args)
        except ParameterError as e:
            ap.error(str(e))
    return args
