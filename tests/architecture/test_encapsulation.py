"""No private attribute is read or written across modules (issue 35): in ``mjeap/`` an
access ``x._name`` (a single leading underscore, not a dunder) is allowed only where ``x``
is ``self``, ``cls`` or ``super()``, or ``_name`` belongs to the module itself (an attribute
its own classes define, assign on ``self`` or declare, or a module-level name of it: the
module's own objects may see each other's insides). A module that reaches into another's
object (``scene._step_count`` written by an engine) goes through a public name instead.

Allowed by name: the public API of the standard library that starts with an underscore
(namedtuple's ``_replace``/``_asdict``/``_fields``, ``sys._getframe``)."""
import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: underscore names that are a library's public API
PUBLIC_UNDERSCORED = {"_replace", "_asdict", "_fields", "_make", "_field_defaults", "_getframe"}
#: the accesses issue 35 named: never on another object, whatever the module
NAMED = {"_step_count", "_fixed_rotation", "_stiffness_scale"}


def _private(name: str) -> bool:
    return name.startswith("_") and not name.startswith("__") and name not in PUBLIC_UNDERSCORED


def _own_names(tree, strings: bool = True) -> set:
    """The private names a module defines: its top-level names, its classes' methods and
    class attributes, and the attributes it assigns on ``self``/``cls`` (or, ``strings``,
    names in its text: ``__slots__``, ``getattr(self, "_x")``)."""
    own = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            own.add(node.name)
        elif isinstance(node, ast.Name) and isinstance(node.ctx, ast.Store):
            own.add(node.id)
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Store) and \
                isinstance(node.value, ast.Name) and node.value.id in ("self", "cls"):
            own.add(node.attr)
        elif isinstance(node, ast.alias):
            own.add(node.asname or node.name.split(".")[0])
        elif strings and isinstance(node, ast.Constant) and isinstance(node.value, str) and _private(node.value):
            own.add(node.value)             # __slots__, __dict__["_x"], getattr(self, "_x")
    return {n for n in own if _private(n)}


def _receiver_is_own(value) -> bool:
    if isinstance(value, ast.Name) and value.id in ("self", "cls"):
        return True
    return isinstance(value, ast.Call) and isinstance(value.func, ast.Name) and value.func.id == "super"


def _module_names(tree) -> set:
    """Names bound at a module's top level (its imports included: ``_x._y`` on an imported
    private module is that module's business, caught where ``_y`` is not its own)."""
    out = set()
    for node in tree.body:
        for sub in ast.walk(node) if isinstance(node, (ast.Import, ast.ImportFrom)) else ():
            if isinstance(sub, ast.alias):
                out.add(sub.asname or sub.name.split(".")[0])
    return out


#: by-name accesses (``getattr(x, "_name")``) allowed, (file, name): a library's private
#: state that has no public way in
LIBRARY_PRIVATE = {("mjeap/studies/sweep/runner.py", "_processes")}     # concurrent.futures' worker processes


def _by_name(node, own_attrs: set):
    """``getattr``/``hasattr``/``setattr(x, "_name", ...)`` or ``x.__dict__["_name"]`` (and
    ``.get``) on another object: the name, else None."""
    if isinstance(node, ast.Call) and isinstance(node.func, ast.Name) and \
            node.func.id in ("getattr", "hasattr", "setattr") and len(node.args) >= 2:
        obj, key = node.args[0], node.args[1]
    elif isinstance(node, ast.Subscript) and isinstance(node.value, ast.Attribute) and node.value.attr == "__dict__":
        obj, key = node.value.value, node.slice
    elif isinstance(node, ast.Call) and isinstance(node.func, ast.Attribute) and node.func.attr == "get" and \
            isinstance(node.func.value, ast.Attribute) and node.func.value.attr == "__dict__" and node.args:
        obj, key = node.func.value.value, node.args[0]
    else:
        return None
    if not (isinstance(key, ast.Constant) and isinstance(key.value, str) and _private(key.value)):
        return None
    if _receiver_is_own(obj) or key.value in own_attrs and key.value not in NAMED:
        return None
    return key.value


def crossings(path: Path, rel: str = ""):
    """(line, text) of every access in ``path`` to another module's private attribute."""
    tree = ast.parse(path.read_text(), str(path))
    own, imported, own_attrs = _own_names(tree), _module_names(tree), _own_names(tree, strings=False)
    out = []
    for node in ast.walk(tree):
        name = _by_name(node, own_attrs)
        if name is not None and (rel, name) not in LIBRARY_PRIVATE:
            out.append((node.lineno, ast.unparse(node)))
        if not isinstance(node, ast.Attribute) or not _private(node.attr):
            continue
        if _receiver_is_own(node.value):
            continue
        if isinstance(node.value, ast.Name) and node.value.id in imported and node.attr not in NAMED:
            continue            # a module's own private name, read through its module (mujoco._functions)
        if node.attr in own and node.attr not in NAMED:
            continue
        out.append((node.lineno, ast.unparse(node)))
    return out


def test_no_private_attribute_crosses_a_module():
    found = {rel: c for p in sorted((ROOT / "mjeap").rglob("*.py"))
             if (c := crossings(p, rel := p.relative_to(ROOT).as_posix()))}
    assert not found, "private attributes read or written across modules (make them public or add a method):\n" + \
        "\n".join(f"{p}:{line}: {text}" for p, c in found.items() for line, text in c)


def test_the_check_finds_a_crossing(tmp_path):
    """The check can fail: an engine writing a scene's private step counter, a module reading
    another's private attribute, are found; the module's own, ``self``'s and a library's
    public underscore names are not."""
    f = tmp_path / "m.py"
    f.write_text("class A:\n    def __init__(self):\n        self._mine = 0\n"
                 "    def f(self, other):\n        return other._mine + self._mine\n"
                 "def g(scene, part, p):\n    scene._step_count = 3\n    p._replace(a=1)\n"
                 "    getattr(self, '_mine')\n    return part._theirs, getattr(p, '_hidden', 0), p.__dict__['_x']\n")
    assert sorted(t for _, t in crossings(f)) == ["getattr(p, '_hidden', 0)", "p.__dict__['_x']", "part._theirs",
                                                  "scene._step_count"]


def test_no_module_imports_another_modules_private_name():
    """``from .x import _name`` reaches into another module as an attribute access does
    (issue 44: rod.py took mjcf's helpers, the optimiser the sweep's CSV store): what modules
    share is public in the module that defines it."""
    import ast as _ast
    found = []
    for p in sorted((ROOT / "mjeap").rglob("*.py")):
        for node in _ast.walk(_ast.parse(p.read_text())):
            if isinstance(node, _ast.ImportFrom) and node.level:
                found += [f"{p.relative_to(ROOT)}:{node.lineno} {a.name}" for a in node.names
                          if a.name.startswith("_") and not a.name.startswith("__")]
    assert not found, found
