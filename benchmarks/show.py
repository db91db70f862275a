"""mjeap show's time per file (the catalog and examples/actuators): the first describe() of
each file in one process (the designer's first numbers from closed forms and the linearised
model, the scene built) and the best of three more; and the whole command in a fresh
process, beside importing the package alone (what a cold start costs)."""
from __future__ import annotations

import sys
import time
from pathlib import Path




def bench_show(repeats=3):
    """mjeap show per file (module text): seconds of describe() first and warm, and of the
    command in a fresh process beside the import alone."""
    import subprocess
    from mjeap.cli import describe
    from mjeap.model.catalog import CATALOG
    root = Path(__file__).resolve().parent.parent
    files = list(CATALOG) + sorted(str(p.relative_to(root)) for p in (root / "examples" / "actuators").rglob("*.toml"))
    rows = []
    for f in files:
        t0 = time.perf_counter()
        describe(str(root / f) if f.endswith(".toml") else f)
        first = time.perf_counter() - t0
        again = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            describe(str(root / f) if f.endswith(".toml") else f)
            again.append(time.perf_counter() - t0)
        rows.append({"file": f, "first_s": first, "again_s": min(again)})
    cold = {}
    for what, argv in (("import_s", [sys.executable, "-c", "import mjeap.cli"]),
                       ("command_s", [sys.executable, "-m", "mjeap.cli", "show", "pzt-hamr-small"])):
        best = []
        for _ in range(repeats):
            t0 = time.perf_counter()
            subprocess.run(argv, cwd=root, check=True, capture_output=True)
            best.append(time.perf_counter() - t0)
        cold[what] = min(best)
    return {"files": rows, "fresh_process": {"file": "pzt-hamr-small", **cold}}


def run(args) -> dict:
    """The benchmark's section of the JSON."""
    return bench_show()
