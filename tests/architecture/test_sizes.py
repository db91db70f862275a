"""Modules stay readable (issue 44): no module of the package or its scripts over
MODULE_LINES lines, no function body over FUNCTION_LINES lines (its docstring not counted),
no function taking more than POSITIONAL parameters positionally (self and cls not counted:
the rest keyword-only, as MuJoCo's rollout puts ``*`` after its heads), and no module
shadowed by a same-named attribute of its package (``import mjeap.x as m`` gives the module)."""
import ast
import importlib
import pkgutil
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
MODULE_LINES, FUNCTION_LINES, POSITIONAL = 600, 100, 8
FILES = sorted([*(ROOT / "mjeap").rglob("*.py"), *(ROOT / "scripts").rglob("*.py"), *(ROOT / "benchmarks").rglob("*.py")])
#: nothing is over a limit: an entry here would be an exception granted by name (none is)
KNOWN: set = set()


def _functions(tree):
    return [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))]


def body_lines(fn) -> int:
    """Lines of ``fn``'s body below its docstring."""
    body = fn.body[1:] if ast.get_docstring(fn) is not None and len(fn.body) > 1 else fn.body
    return body[-1].end_lineno - body[0].lineno + 1


def positional(fn) -> int:
    """Parameters ``fn`` takes positionally (self and cls not counted)."""
    args = fn.args.posonlyargs + fn.args.args
    return len(args) - (1 if args and args[0].arg in ("self", "cls") else 0)


def test_modules_are_at_most_600_lines():
    long = {str(p.relative_to(ROOT)): n for p in FILES if (n := len(p.read_text().splitlines())) > MODULE_LINES}
    assert set(long) <= KNOWN, long


def test_function_bodies_are_at_most_100_lines_and_take_at_most_8_positionally():
    long, wide = {}, {}
    for p in FILES:
        for fn in _functions(ast.parse(p.read_text())):
            where = f"{p.relative_to(ROOT)}:{fn.lineno} {fn.name}"
            if body_lines(fn) > FUNCTION_LINES:
                long[where] = body_lines(fn)
            if positional(fn) > POSITIONAL:
                wide[where] = positional(fn)
    assert set(long) <= KNOWN, long
    assert set(wide) <= KNOWN, wide


def test_the_measures_can_fail():
    tree = ast.parse("def f(a, b, c, d, e, f, g, h, i):\n    '''Doc.'''\n" + "    x = 1\n" * 101)
    (fn,) = _functions(tree)
    assert positional(fn) == 9 and body_lines(fn) == 101
    (m,) = _functions(ast.parse("class C:\n    def m(self, a, *, b):\n        return a\n"))
    assert positional(m) == 1 and body_lines(m) == 1


def _packages():
    import mjeap
    yield mjeap
    for info in pkgutil.walk_packages(mjeap.__path__, "mjeap."):
        if info.ispkg and info.name != "mjeap.mjcf_files":
            yield importlib.import_module(info.name)


@pytest.mark.parametrize("package", list(_packages()), ids=lambda p: p.__name__)
def test_no_module_is_shadowed_by_a_same_named_attribute(package):
    shadowed = []
    for info in pkgutil.iter_modules(package.__path__):
        full = f"{package.__name__}.{info.name}"
        if full == "mjeap.mjcf_files" or info.name == "__main__":
            continue
        importlib.import_module(full)
        value = getattr(package, info.name, None)
        if value is not None and not (hasattr(value, "__name__") and getattr(value, "__spec__", None) is not None
                                      and value.__name__ == full):
            shadowed.append(f"{full} is {type(value).__name__} {getattr(value, '__qualname__', value)!r}")
    assert not shadowed, shadowed
