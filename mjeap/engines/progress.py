"""A run's progress on stderr, the same for every engine (:func:`mjeap.engines.run_checked`
follows the samples a run takes):

* ``progress=None`` (the default): a tqdm bar on a terminal, shown once the run has lasted
  :data:`DELAY` s (a short run shows nothing; a log file gets nothing);
* ``progress=True``: the bar at once; ``False``: nothing;
* ``progress="lines"`` (``mjeap rollout --progress``): one line per 10 % of the simulated
  time, for logs and batch jobs.
"""
from __future__ import annotations

import sys
import time
from typing import Optional, Union

__all__ = ["Progress", "LINES", "DELAY", "check_progress"]

#: the mode that prints one line per tenth of the run
LINES = "lines"
#: seconds a run lasts before its bar appears (progress=None, on a terminal)
DELAY = 2.0


def check_progress(progress) -> Union[bool, None, str]:
    """``progress`` as a run takes it: None, True, False or ``"lines"``."""
    from ..errors import ParameterError
    if progress is None or isinstance(progress, bool) or progress == LINES:
        return progress
    raise ParameterError("progress", progress, f"None (a bar on a terminal after {DELAY:g} s), True, False or "
                         f"'{LINES}' (one line per 10 %)")


class Progress:
    """Progress of a run of ``total`` simulated seconds, told as ``desc`` (context manager;
    :meth:`at` with the simulated time reached)."""

    def __init__(self, total: float, desc: str, progress: Union[bool, None, str] = None):
        self.total, self.desc = float(total), desc
        self.mode = check_progress(progress)
        self.bar, self.tenth, self.t0 = None, 1, time.perf_counter()
        if self.mode is True or (self.mode is None and _terminal()):
            try:
                from tqdm import tqdm
            except ImportError:  # pragma: no cover - tqdm is a dependency of the sweep extra
                return
            self.bar = tqdm(total=self.total, desc=desc, unit="s", unit_scale=False, leave=False,
                            delay=0.0 if self.mode is True else DELAY,
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| {n:.3g}/{total:.3g} s simulated "
                                       "[{elapsed}<{remaining}]")

    def at(self, t: float) -> None:
        """The run has reached ``t`` s of simulated time."""
        if self.bar is not None:
            self.bar.update(max(0.0, min(t, self.total) - self.bar.n))
        elif self.mode == LINES and self.total > 0:
            while self.tenth <= 10 and t >= self.tenth * self.total / 10 * (1 - 1e-9):
                print(f"{self.desc}: {10 * self.tenth}% ({self.tenth * self.total / 10:.4g} of {self.total:.4g} s "
                      f"simulated, {time.perf_counter() - self.t0:.1f} s wall)", file=sys.stderr, flush=True)
                self.tenth += 1

    def close(self) -> None:
        if self.bar is not None:
            self.bar.close()
            self.bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False


def _terminal() -> bool:
    try:
        return sys.stderr.isatty()
    except (AttributeError, ValueError):
        return False
