import os
from pathlib import Path

os.environ.setdefault("MUJOCO_GL", "disable")

import pytest  # noqa: E402

#: the test folders, one per floor of the package bottom up (docs/architecture.md), then
#: ``architecture`` (the layout itself: floors, encapsulation, sizes, docs) and ``contracts``
#: (the failure-behaviour classes that cut across the floors). A test file's folder is its
#: layer: it gets the marker ``layer_<folder>`` (``python -m pytest -m layer_drives``); adding
#: a test file is one edit, the file in its folder. tests/architecture/test_docs.py checks that
#: every folder is here and in docs/testing.md's table.
LAYERS = ("foundation", "io", "model", "drives", "engines", "simulation", "analysis", "controllers", "studies",
          "robots", "envs", "validation", "cli", "architecture", "contracts")
TESTS = Path(__file__).resolve().parent


def layer_of(path) -> str:
    """The layer of the test file at ``path``: its folder under tests/ (None where it has none)."""
    rel = Path(path).resolve().relative_to(TESTS)
    return rel.parts[0] if len(rel.parts) == 2 and rel.parts[0] in LAYERS else None


def pytest_configure(config):
    config.addinivalue_line("markers", "cable: needs the cable representation (MuJoCo 3.x)")
    config.addinivalue_line("markers", "rod: needs the rod representation (MuJoCo 4.x)")
    config.addinivalue_line("markers", "dm_control: needs dm_control's Physics (MuJoCo 3.x with dm-control 1.0.50)")
    for layer in LAYERS:
        config.addinivalue_line("markers", f"layer_{layer}: a test in tests/{layer}/ (tests/conftest.py LAYERS)")


@pytest.hookimpl(tryfirst=True)        # before -m selects: a test parametrised with 'cable' is marked cable
def pytest_collection_modifyitems(config, items):
    """On MuJoCo 4.x the cable (removed there) and dm_control's Physics (fails there) are
    refused by mjeap, which tests/foundation/test_versions.py checks; the tests that need them are
    skipped with the reason: a test marked ``cable`` or ``dm_control``, or parametrised with
    the value 'cable'. Likewise the rod (mjeap.rod) on MuJoCo 3.x, with the reason mjeap gives."""
    from mjeap.model.mjcf import BUILDERS
    from mjeap.versions import MUJOCO_VERSION, cable_available, dm_control_problem
    no_cable = pytest.mark.skip(reason=f"the cable representation needs MuJoCo 3.x (here {MUJOCO_VERSION})")
    rod_problem = BUILDERS["rod"].unavailable_reason()
    no_rod = pytest.mark.skip(reason=f"the rod representation: {rod_problem}")
    dmc_problem, has_cable = dm_control_problem(), cable_available()     # asked once, not per test
    no_dmc = pytest.mark.skip(reason=dmc_problem or "")
    def values(x):
        if isinstance(x, dict):
            x = list(x.values())
        if isinstance(x, (list, tuple)):
            return [w for v in x for w in values(v)]
        return [x]

    for item in items:
        layer = layer_of(item.path)
        if layer:
            item.add_marker(f"layer_{layer}")
        params = getattr(getattr(item, "callspec", None), "params", {})
        texts = {v for v in values(params) if isinstance(v, str)}
        for representation in ("cable", "rod"):      # parametrised with it: marked with it
            if representation in texts:
                item.add_marker(representation)
        if not has_cable and "cable" in item.keywords:
            item.add_marker(no_cable)
        if rod_problem and "rod" in item.keywords:
            item.add_marker(no_rod)
        if dmc_problem and "dm_control" in item.keywords:
            item.add_marker(no_dmc)
