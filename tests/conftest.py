import os

os.environ.setdefault("MUJOCO_GL", "disable")

import pytest  # noqa: E402


def pytest_configure(config):
    config.addinivalue_line("markers", "cable: needs the cable representation (MuJoCo 3.x)")
    config.addinivalue_line("markers", "rod: needs the rod representation (MuJoCo 4.x)")
    config.addinivalue_line("markers", "dm_control: needs dm_control's Physics (MuJoCo 3.x with dm-control 1.0.50)")


def pytest_collection_modifyitems(config, items):
    """On MuJoCo 4.x the cable (removed there) and dm_control's Physics (fails there) are
    refused by mjeap, which tests/test_versions.py checks; the tests that need them are
    skipped with the reason: a test marked ``cable`` or ``dm_control``, or parametrised with
    the value 'cable'. Likewise the rod (mjeap.rod) on MuJoCo 3.x, with the reason mjeap gives."""
    from mjeap.model.mjcf import BUILDERS
    from mjeap.versions import MUJOCO_VERSION, cable_available, dm_control_problem
    no_cable = pytest.mark.skip(reason=f"the cable representation needs MuJoCo 3.x (here {MUJOCO_VERSION})")
    rod_problem = BUILDERS["rod"].unavailable_reason()
    no_rod = pytest.mark.skip(reason=f"the rod representation: {rod_problem}")
    no_dmc = pytest.mark.skip(reason=dm_control_problem() or "")
    def values(x):
        if isinstance(x, dict):
            x = list(x.values())
        if isinstance(x, (list, tuple)):
            return [w for v in x for w in values(v)]
        return [x]

    for item in items:
        params = getattr(getattr(item, "callspec", None), "params", {})
        if not cable_available() and ("cable" in item.keywords or any(isinstance(v, str) and v == "cable" for v in values(params))):
            item.add_marker(no_cable)
        if rod_problem and ("rod" in item.keywords or any(isinstance(v, str) and v == "rod" for v in values(params))):
            item.add_marker(no_rod)
        if dm_control_problem() and "dm_control" in item.keywords:
            item.add_marker(no_dmc)
