"""The package's layout tells its architecture (issue 24): layers import only downwards,
no module imports another that imports it back (directly or round a circle, lazy imports
included), no test imports a script by path, and only ``mjeap`` is installed at the top.

Layers, bottom up: the foundation (errors, units, versions), io, model, drives, engines,
simulation, analysis, then the applications (the package root, cli, sweep, the
environments, assets, the stability map, validation, robots, controllers)."""
import ast
import tomllib
from collections import defaultdict
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
LAYERS = [("mjeap.errors", "mjeap.units", "mjeap.versions"), ("mjeap.io",), ("mjeap.model",), ("mjeap.drives",),
          ("mjeap.engines",), ("mjeap.simulation",), ("mjeap.analysis",)]
APPLICATIONS = len(LAYERS)


def _modules():
    """Module name -> file, the controllers as installed (mjeap.controllers)."""
    out = {}
    for base, prefix in ((ROOT / "mjeap", "mjeap"), (ROOT / "controllers", "mjeap.controllers")):
        for p in base.rglob("*.py"):
            parts = list(p.relative_to(base).with_suffix("").parts)
            if parts[-1] == "__init__":
                parts = parts[:-1]
            out[".".join([prefix, *parts])] = p
    return out


MODULES = _modules()


def layer(module: str) -> int:
    for i, names in enumerate(LAYERS):
        if any(module == n or module.startswith(n + ".") for n in names):
            return i
    return APPLICATIONS


def _imports(module: str, path: Path):
    """The mjeap modules ``module`` imports anywhere in its file (lazy imports included)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")[:len(package.split(".")) - (node.level - 1)]
                src = ".".join(base + ([node.module] if node.module else []))
            else:
                src = node.module or ""
            for a in node.names:
                if f"{src}.{a.name}" in MODULES:
                    yield f"{src}.{a.name}"
                elif src in MODULES:
                    yield src
        elif isinstance(node, ast.Import):
            yield from (a.name for a in node.names if a.name in MODULES)


GRAPH = {m: sorted(set(_imports(m, p)) - {m}) for m, p in MODULES.items()}


def test_layers_import_only_downwards():
    upward = [f"{m} ({layer(m)}) -> {t} ({layer(t)})" for m, ts in GRAPH.items() for t in ts if layer(t) > layer(m)]
    assert not upward, "\n".join(upward)


def test_no_import_circles():
    """Tarjan's strongly connected components of the import graph: all of size one."""
    index, low, stack, on, circles, counter = {}, {}, [], set(), [], [0]

    def visit(v):
        index[v] = low[v] = counter[0]
        counter[0] += 1
        stack.append(v)
        on.add(v)
        for w in GRAPH.get(v, ()):
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

    for v in GRAPH:
        if v not in index:
            visit(v)
    assert not circles, circles


def test_the_graph_sees_the_layers():
    """The check above is not vacuous: the scene imports the model layer and is imported
    by rollouts, and the layers hold the modules they are meant to."""
    assert "mjeap.model.mjcf" in GRAPH["mjeap.simulation.scene"]
    assert "mjeap.simulation.scene" in GRAPH["mjeap.simulation.rollout"]
    assert layer("mjeap.engines.loop") < layer("mjeap.simulation.system") < layer("mjeap.robots.hamr_leg")
    assert len(MODULES) > 50


def test_no_test_imports_a_script_by_path():
    offenders = [p.name for p in (ROOT / "tests").glob("*.py")
                 if p.name != Path(__file__).name and "spec_from_file_location" in p.read_text()]
    assert not offenders


def test_only_mjeap_is_installed_at_the_top():
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    assert all(p == "mjeap" or p.startswith("mjeap.") for p in cfg["packages"])
    assert set(cfg.get("package-dir", {})) <= {p for p in cfg["packages"]}
    on_disk = {m for m, p in MODULES.items() if p.name == "__init__.py"}
    assert on_disk == set(cfg["packages"]), on_disk ^ set(cfg["packages"])


def test_the_flat_layout_s_module_names_still_import_as_the_moved_modules():
    import importlib
    import mjeap
    from mjeap import MOVED
    for old, new in MOVED.items():
        assert importlib.import_module(f"mjeap.{old}") is importlib.import_module(f"mjeap.{new}"), old
    from mjeap.scene import Scene
    from mjeap.rollout import rollout
    assert Scene is mjeap.Scene and rollout is mjeap.rollout and callable(mjeap.rollout)
    assert importlib.import_module("mjeap.scene").__spec__.name == "mjeap.simulation.scene"


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
