"""The package's layout tells its architecture (issues 24 and 35): the package is a stack of
floors, each a folder (or a few top-level modules) of ``mjeap``; a module imports only from
its own floor or those below, no module imports another that imports it back (directly or
round a circle, lazy imports and ``importlib.import_module`` strings included), every module
has a floor, no test imports a script by path, and only ``mjeap`` is installed at the top.

Floors, bottom up: the foundation (errors, units, versions), io, model, drives, engines,
simulation, analysis; then the applications: controllers, the studies (mjeap.studies: the
sweep package, optimize, the stability map), robots (a package each: model, experiments),
envs (the dm_env and Gymnasium environments: the tracking task and the robots as tasks, so
above the robots), validation (and the MJCF assets), cli, and last the package's top level
(``mjeap``: the names most programs need)."""
import ast
import re
import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
#: the floors, bottom up: (name, the modules or packages on it); ``mjeap`` alone is its top level
FLOORS = [
    ("foundation", ("mjeap.errors", "mjeap.units", "mjeap.versions", "mjeap.caching", "mjeap.lazy")),
    ("io", ("mjeap.io",)),
    ("model", ("mjeap.model",)),
    ("drives", ("mjeap.drives",)),
    ("engines", ("mjeap.engines",)),
    ("simulation", ("mjeap.simulation",)),
    ("analysis", ("mjeap.analysis",)),
    ("controllers", ("mjeap.controllers",)),
    ("studies", ("mjeap.studies",)),
    ("robots", ("mjeap.robots",)),
    ("envs", ("mjeap.envs",)),
    ("validation", ("mjeap.validation", "mjeap.assets")),
    ("cli", ("mjeap.cli",)),
    ("top level", ("mjeap",)),
]
FLOOR_NAMES = [name for name, _ in FLOORS]


def _modules():
    """Module name -> file, every module of the package (it is all under mjeap/)."""
    out = {}
    for p in (ROOT / "mjeap").rglob("*.py"):
        parts = list(p.relative_to(ROOT / "mjeap").with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(["mjeap", *parts])] = p
    return out


MODULES = _modules()


def _on(module: str, name: str) -> bool:
    """``module`` is ``name`` or inside it (the top level ``mjeap`` is only itself)."""
    return module == name or (name != "mjeap" and module.startswith(name + "."))


def layer(module: str):
    """The floor of ``module`` (its index in FLOORS), None where it has none."""
    for i, (_, names) in enumerate(FLOORS):
        if any(_on(module, n) for n in names):
            return i
    return None


#: a part of an f-string that is not ``__name__`` or ``__package__``: one dotted name's segment
_SEGMENT = r"[A-Za-z_][A-Za-z0-9_]*"


def _dynamic_import(node, module: str, package: str):
    """The modules an ``importlib.import_module(...)`` (or ``__import__(...)``) call names:
    a string (relative to its ``package`` argument or, given as ``__package__`` or
    ``__name__``, to this module's), or an f-string whose ``{__name__}`` and
    ``{__package__}`` are this module's and whose other fields stand for any one name each
    (``f"{__name__}.{m}"`` in a package: each of its submodules)."""
    f = node.func
    name = f.attr if isinstance(f, ast.Attribute) else f.id if isinstance(f, ast.Name) else None
    if name not in ("import_module", "__import__") or not node.args:
        return
    arg = node.args[0]
    if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
        target = arg.value
        if target.startswith(".") and len(node.args) > 1:
            anchor = node.args[1]
            base = (anchor.value if isinstance(anchor, ast.Constant) else
                    package if isinstance(anchor, ast.Name) and anchor.id == "__package__" else
                    module if isinstance(anchor, ast.Name) and anchor.id == "__name__" else None)
            if base is None:
                return
            dots = len(target) - len(target.lstrip("."))
            target = ".".join(base.split(".")[:len(base.split(".")) - (dots - 1)] + [target.lstrip(".")])
        if target in MODULES:
            yield target
    elif isinstance(arg, ast.JoinedStr):
        pattern = ""
        for part in arg.values:
            if isinstance(part, ast.Constant):
                pattern += re.escape(str(part.value))
            elif isinstance(part.value, ast.Name) and part.value.id in ("__name__", "__package__"):
                pattern += re.escape(module if part.value.id == "__name__" else package)
            else:
                pattern += _SEGMENT
        yield from (m for m in MODULES if re.fullmatch(pattern, m))


def _import_source(node: ast.ImportFrom, package: str) -> str:
    """The absolute module a ``from ... import`` names, relative levels resolved in ``package``."""
    if not node.level:
        return node.module or ""
    base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
    return ".".join(base + ([node.module] if node.module else []))


def _imports(module: str, path: Path, source: str = None):
    """The mjeap modules ``module`` imports anywhere in its file (lazy imports included, and
    the modules its ``importlib.import_module`` calls name)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text() if source is None else source)):
        if isinstance(node, ast.ImportFrom):
            src = _import_source(node, package)
            for a in node.names:
                if f"{src}.{a.name}" in MODULES:
                    yield f"{src}.{a.name}"
                elif src in MODULES:
                    yield src
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name in MODULES)
        elif isinstance(node, ast.Call):
            yield from _dynamic_import(node, module, package)


GRAPH = {m: sorted(set(_imports(m, p)) - {m}) for m, p in MODULES.items()}


def test_every_module_has_a_floor():
    assert not [m for m in MODULES if layer(m) is None]
    missing = [n for _, names in FLOORS for n in names if n not in MODULES]
    assert not missing, f"floors name what is not there: {missing}"


def _unresolved(module: str, path: Path):
    """The mjeap imports of ``module`` that name no module of the package (a relative import
    one level short, say: the graph above would not see it, and it fails only when it runs)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            src = _import_source(node, package)
            if src.split(".")[0] == "mjeap" and src not in MODULES:
                yield f"{module}: from {'.' * node.level}{node.module or ''} ({src})"
        elif isinstance(node, ast.Import):
            yield from (f"{module}: import {a.name}" for a in node.names
                        if a.name.split(".")[0] == "mjeap" and a.name not in MODULES)


def test_every_import_of_mjeap_names_one_of_its_modules():
    bad = [b for m, p in MODULES.items() for b in _unresolved(m, p)]
    assert not bad, "\n".join(bad)


def test_layers_import_only_downwards():
    """(A module without a floor is test_every_module_has_a_floor's.)"""
    floored = {m for m in GRAPH if layer(m) is not None}
    upward = [f"{m} ({FLOOR_NAMES[layer(m)]}) -> {t} ({FLOOR_NAMES[layer(t)]})"
              for m in floored for t in GRAPH[m] if t in floored and layer(t) > layer(m)]
    assert not upward, "\n".join(upward)


def _circles(graph):
    """Tarjan's strongly connected components of ``graph`` with more than one module."""
    index, low, stack, on, circles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in graph.get(v, ()):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                circles.append(sorted(comp))

    for v in graph:
        if v not in index:
            visit(v)
    return circles


def test_no_import_circles():
    """Tarjan's strongly connected components of the import graph: all of size one (the
    cli and the robots were one: the cli runs the robots, and the robots took their
    argument checks from the cli, through the registry's import_module)."""
    circles = _circles(GRAPH)
    assert not circles, circles


def test_the_graph_follows_import_module_strings():
    """``importlib.import_module`` counts as an import: a string names its module, an
    f-string in a package (``f"{__name__}.{m}"``) each submodule it can name; so the
    robots' registry imports every robot package, and a circle through it is found."""
    path = MODULES["mjeap.robots"]
    source = ('import importlib\nimportlib.import_module("mjeap.cli")\n'
              'importlib.import_module(".studies.sweep", "mjeap")\nimportlib.import_module(f"{__name__}.{m}")\n')
    found = set(_imports("mjeap.robots", path, source))
    assert {"mjeap.cli", "mjeap.studies.sweep", "mjeap.robots.gripper", "mjeap.robots.registry"} <= found
    assert not any(m.startswith("mjeap.robots.gripper.") for m in found)      # one name per field
    assert {"mjeap.robots.gripper", "mjeap.robots.hamr_walk"} <= set(GRAPH["mjeap.robots"])
    assert _circles({**GRAPH, "mjeap.robots.gripper.experiments": ["mjeap.cli"]})


def test_the_graph_sees_the_layers():
    """The checks above are not vacuous: the scene imports the model layer and is imported
    by rollouts, the floors come in their order, and they hold the modules they are meant to."""
    assert "mjeap.model.mjcf" in GRAPH["mjeap.simulation.scene"]
    assert "mjeap.simulation.scene" in GRAPH["mjeap.simulation.rollout"]
    assert "mjeap.robots" in GRAPH["mjeap.cli.runs"] and "mjeap.io.commandline" in GRAPH["mjeap.robots.hamr_leg.experiments"]
    order = [layer(m) for m in ("mjeap.engines.loop", "mjeap.simulation.system", "mjeap.analysis.frequency",
                                "mjeap.controllers.hamr_leg", "mjeap.studies.sweep.runner", "mjeap.robots.hamr_leg.model",
                                "mjeap.envs.gymnasium_env", "mjeap.validation.core", "mjeap.cli", "mjeap")]
    assert "mjeap.robots.hamr_walk.model" in GRAPH["mjeap.envs.hamr_walk"]      # a robot as a task
    assert order == sorted(order) and len(set(order)) == len(order)
    assert layer("mjeap.io.commandline") < layer("mjeap.model")
    assert len(MODULES) > 50


def test_each_robot_is_its_model_and_its_experiments():
    """A robot is a package: its model (builder and read-outs) imports none of the
    experiments (its own or another robot's), which import the model."""
    robots = sorted({m.split(".")[2] for m in MODULES if m.startswith("mjeap.robots.") and m.count(".") == 3})
    assert robots, "no robot packages"
    for r in robots:
        model, experiments = f"mjeap.robots.{r}.model", f"mjeap.robots.{r}.experiments"
        assert model in MODULES and experiments in MODULES, r
        seen, todo = set(), [model]
        while todo:
            for t in GRAPH[todo.pop()]:
                if t not in seen:
                    seen.add(t)
                    todo.append(t)
        assert not [t for t in seen if t.startswith("mjeap.robots.") and not t.endswith(".model")
                    and t != "mjeap.robots.registry"], (r, sorted(seen))
        assert model in GRAPH[experiments]


def test_no_test_imports_a_script_by_path():
    offenders = [p.name for p in (ROOT / "tests").rglob("*.py")
                 if p.name != Path(__file__).name and "spec_from_file_location" in p.read_text()]
    assert not offenders


def test_only_mjeap_is_installed_at_the_top():
    """Every package of code is a folder of mjeap/; the package-dir mappings install data,
    not mjeap's code: the model files of assets/mjcf as mjeap.mjcf_files (mjeap.assets.path,
    no Python module in it) and the examples as mjeap.examples_files (mjeap examples DIR)."""
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert all(p == "mjeap" or p.startswith("mjeap.") for p in cfg["packages"])
    data = cfg.get("package-dir", {})
    assert data == {"mjeap.mjcf_files": "assets/mjcf", "mjeap.examples_files": "examples"}
    assert not list((ROOT / "assets" / "mjcf").glob("*.py"))
    assert cfg["package-data"]["mjeap.mjcf_files"] == ["*.xml"]
    on_disk = {m for m, p in MODULES.items() if p.name == "__init__.py"}
    assert on_disk == set(cfg["packages"]) - set(data), on_disk ^ (set(cfg["packages"]) - set(data))
    assert not (ROOT / "controllers").exists()


def test_scenes_systems_and_environments_pick_their_engine_in_one_registry():
    """A new engine is one module that registers itself: rollout's, System's and the
    environments' engines all come from mjeap.engines' registry (the loop engine runs
    systems and steps environments; the native and threaded engines say why they do not)."""
    from mjeap import engines
    from mjeap.robots import load
    wing = load("robobee-wing", bias=100.0)
    r = wing.rollout(["sine:50V@100Hz,offset=50V"], 0.002)
    assert r.meta["engine"] == "loop" and "not native" in r.meta["engine_reason"]
    assert engines.stepper().name == "loop"
    assert "System" in engines.get_engine("threaded").system_reason(wing)


def test_moved_modules_import_under_their_earlier_names():
    """The documented aliases of modules that moved (issue 44): the same module objects,
    each keeping its own name and spec (pickling and reloading see the real module)."""
    import importlib
    import mjeap
    for old, new in mjeap.ALIASES.items():
        a, b = importlib.import_module(old), importlib.import_module(new)
        assert a is b and b.__name__ == new and b.__spec__.name == new
    from mjeap.sweep import run_sweep
    from mjeap.studies.sweep import run_sweep as real
    assert run_sweep is real and callable(mjeap.optimize)
