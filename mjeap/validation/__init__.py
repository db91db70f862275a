"""``mjeap validate``: every validation experiment, headless, with a table, JSON, a Markdown
report with figures and one Rerun recording per experiment.

Each experiment module holds the experiments of one source; a check compares the simulator
with a named, independent reference (closed form, scipy solution of a model, a paper's table).
"""
from __future__ import annotations

import time
from contextlib import ExitStack
from pathlib import Path
from typing import Iterable, List, Optional

from .core import REGISTRY, Check, Curve, Experiment, experiment
from . import mechanics, dadras2021, mutlu2013, metello2020, jayaram2018  # noqa: F401  (register)
from . import report
from ..io.outputs import run_guard

__all__ = ["REGISTRY", "Check", "Curve", "Experiment", "experiment", "run_validation", "report"]


def select(names: Optional[Iterable[str]] = None) -> List[str]:
    from ..errors import UnknownNameError
    if not names:
        return list(REGISTRY)
    out = []
    for n in names:
        hits = [k for k in REGISTRY if k == n or k.startswith(n)]
        if not hits:
            raise UnknownNameError("experiment", n, list(REGISTRY))
        out += [h for h in hits if h not in out]
    return out


def run_validation(names: Optional[Iterable[str]] = None, out: Optional[Path] = None, quick: bool = False,
                   progress: bool = True) -> List[Experiment]:
    """Run the named experiments (prefixes allowed; all by default) and, with ``out``, write
    ``validation.json``, ``report.md``, a PNG per experiment (with matplotlib) and a ``.rrd``
    per experiment there. Files are written after each experiment, so an interrupted run keeps
    what finished."""
    names = select(names)
    try:
        from tqdm import tqdm
        import sys
        bar = tqdm(names, desc="validate", unit="exp", disable=not (progress and sys.stderr.isatty()))
    except ImportError:  # pragma: no cover
        bar = names
    done: List[Experiment] = []
    guard = ExitStack()
    figures = report.have_matplotlib()
    if out is not None:
        out = Path(out)
        # every file it will write, named by mjeap itself, checked and locked before any work
        # (regular files or none, never a link); until the last experiment has run the summaries
        # say which have not (an interrupted run's report is marked incomplete, never passed)
        files = {"--out (validation.json)": out / "validation.json", "--out (report.md)": out / "report.md"}
        for name in names:
            files[f"--out ({name}.rrd)"] = out / f"{name}.rrd"
            if figures:
                files[f"--out ({name}.png)"] = out / f"{name}.png"
        guard.enter_context(run_guard(picked=files, **files))
    with guard:
        if out is not None:
            report.write_json(done, out / "validation.json", pending=names)
            report.write_markdown(done, out / "report.md", figures, pending=names)
        for i, name in enumerate(bar):
            if hasattr(bar, "set_postfix_str"):
                bar.set_postfix_str(name)
            t0 = time.perf_counter()
            ex = REGISTRY[name](quick=quick)
            ex.seconds = time.perf_counter() - t0
            done.append(ex)
            if out is not None:
                if figures:
                    report.write_figure(ex, out / f"{ex.name}.png")
                png = out / f"{ex.name}.png"
                report.write_recording(ex, out / f"{ex.name}.rrd", figure=png if figures and png.is_file() else None)
                report.write_json(done, out / "validation.json", pending=names[i + 1:])
                report.write_markdown(done, out / "report.md", figures, pending=names[i + 1:])
    return done
