"""docs/architecture.md's map of the package, drawn from what is there: every floor bottom up
(tests/architecture/test_layers.py's FLOORS) with each of its modules and the first line of
the module's docstring, written between the page's ``floors`` markers (the rest of the page
is prose). tests/architecture/test_docs.py fails while the map is stale.

    python scripts/architecture_page.py           # rewrite the map in docs/architecture.md
    python scripts/architecture_page.py --check   # exit 1 where it is stale
"""
import argparse
import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "tests" / "architecture"))
import test_layers  # noqa: E402  (the floors and modules the test checks)

PAGE = ROOT / "docs" / "architecture.md"
BEGIN, END = "<!-- floors:begin (scripts/architecture_page.py) -->", "<!-- floors:end -->"


def first_line(path: Path) -> str:
    """The first sentence-line of a module's docstring ('' without one)."""
    doc = ast.get_docstring(ast.parse(path.read_text())) or ""
    line = " ".join(doc.strip().split("\n\n")[0].split())
    return line.replace("|", "\\|")


def floors_table() -> str:
    """The map: a row per module, floor by floor, bottom up."""
    rows = ["| floor | module | what |", "|---|---|---|"]
    for name, _ in test_layers.FLOORS:
        i = test_layers.FLOOR_NAMES.index(name)
        modules = sorted(m for m in test_layers.MODULES if test_layers.layer(m) == i)
        for k, m in enumerate(modules):
            rows.append(f"| {name if k == 0 else ''} | `{m}` | {first_line(test_layers.MODULES[m])} |")
    return "\n".join(rows)


def page_with_map(text: str) -> str:
    head, _, rest = text.partition(BEGIN)
    _, _, tail = rest.partition(END)
    return f"{head}{BEGIN}\n{floors_table()}\n{END}{tail}"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--check", action="store_true", help="exit 1 where the page's map is stale")
    a = ap.parse_args(argv)
    text = PAGE.read_text()
    if BEGIN not in text or END not in text:
        print(f"{PAGE} has no {BEGIN} ... {END} markers", file=sys.stderr)
        return 1
    new = page_with_map(text)
    if a.check:
        return 0 if new == text else 1
    if new != text:
        sys.path.insert(0, str(ROOT))
        from mjeap.io.outputs import write_text
        write_text(PAGE, new, "docs/architecture.md")
    return 0


if __name__ == "__main__":
    sys.exit(main())
