"""The package's import graph, floor by floor, from the sources (the graph
tests/architecture/test_layers.py builds and checks: lazy imports and import_module strings
included): prints how many module-to-module imports go from each floor to each floor, and
with --png draws the floors bottom up with an arrow for every pair that imports, its count
on it. An arrow back up would be a floor importing one above it; there is none
(the test fails on one).

    python scripts/import_graph.py [--png docs/import-graph.png]
"""
import argparse
import sys
from collections import Counter
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "architecture"))
import test_layers  # noqa: E402  (the graph and the floors the test checks)


def floor_edges() -> Counter:
    """(importer's floor, imported's floor) -> how many module imports (within a floor too)."""
    edges = Counter()
    for module, targets in test_layers.GRAPH.items():
        for target in targets:
            edges[test_layers.layer(module), test_layers.layer(target)] += 1
    return edges


def draw(edges: Counter, path: Path) -> None:
    """The floor-to-floor import counts as a matrix, importers down the side, the floors they
    import along the top, both bottom floor first: every count sits on or below the diagonal
    (a floor imports its own and those below); above it, shaded, is where an import up would be."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    import numpy as np
    names = test_layers.FLOOR_NAMES
    n = len(names)
    counts = np.zeros((n, n))
    for (a, b), k in edges.items():
        counts[a, b] = k
    fig, ax = plt.subplots(figsize=(9.5, 8))
    ax.imshow(np.where(counts > 0, np.log1p(counts), np.nan), cmap="Blues", vmin=0, origin="lower")
    ax.imshow(np.where(np.triu(np.ones((n, n)), 1) > 0, 1.0, np.nan), cmap="Reds", vmin=0, vmax=6, alpha=0.35,
              origin="lower")
    for a in range(n):
        for b in range(n):
            if counts[a, b]:
                ax.text(b, a, f"{counts[a, b]:.0f}", ha="center", va="center", fontsize=8,
                        color="white" if counts[a, b] > 12 else "black")
    ax.set_xticks(range(n), names, rotation=60, ha="right")
    ax.set_yticks(range(n), [f"{name} ({', '.join(m.replace('mjeap.', '') for m in dict(test_layers.FLOORS)[name])})"
                             if name not in ("top level",) else "top level (mjeap)" for name in names], fontsize=8)
    ax.set_xlabel("floor imported")
    ax.set_ylabel("importing floor")
    up = sum(k for (a, b), k in edges.items() if b > a)
    ax.set_title(f"mjeap's import graph by floor: {sum(edges.values())} imports between modules, {up} upwards\n"
                 "(counts of module imports; the shaded triangle is where an import up a floor would be)")
    fig.tight_layout()
    fig.savefig(path, dpi=110)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--png", type=Path, help="draw the floors and their imports to this PNG (needs matplotlib)")
    a = ap.parse_args(argv)
    edges = floor_edges()
    names = test_layers.FLOOR_NAMES
    width = max(map(len, names))
    print(f"{'imports':>{width}}  " + " ".join(f"{n[:5]:>5}" for n in names))
    for i, name in enumerate(names):
        print(f"{name:>{width}}  " + " ".join(f"{edges.get((i, j), 0) or '.':>5}" for j in range(len(names))))
    up = {(names[a], names[b]): n for (a, b), n in edges.items() if b > a}
    print("imports up a floor:", up or "none")
    if a.png is not None:
        draw(edges, a.png)
        print("wrote", a.png)
    return 1 if up else 0


if __name__ == "__main__":
    sys.exit(main())
