import os

os.environ.setdefault("MUJOCO_GL", "disable")

import pytest  # noqa: E402

#: the tests grouped by layer of the package (docs/testing.md), bottom up; each test gets the
#: marker ``layer_<name>`` of its file (``python -m pytest -m layer_drives``). The layers of
#: the package are tests/test_layers.py's; ``contracts`` holds the failure-behaviour classes that
#: cut across them. tests/test_docs.py checks that every test file is here and in the docs' table.
LAYER_FILES = {
    "foundation": ("test_layers", "test_encapsulation", "test_errors", "test_units", "test_versions", "test_docs"),
    "io": ("test_output_paths", "test_output_safety", "test_recordings"),
    "model": ("test_section", "test_analytical", "test_lti", "test_statics", "test_dynamics", "test_axial",
              "test_rod", "test_assets", "test_actuator_files"),
    "drives": ("test_drive_ionic", "test_drive_electrostatic", "test_drive_allocation", "test_piezo_moment",
               "test_piezo_power", "test_pvdf_fidelity"),
    "engines": ("test_threaded", "test_native", "test_warp"),
    "simulation": ("test_rollout", "test_system", "test_pipeline", "test_accuracy", "test_periodic", "test_golden",
                   "test_viewer"),
    "analysis": ("test_identify", "test_self_sensing", "test_stability_map"),
    "applications": ("test_sweep", "test_metric_accuracy", "test_design_sweeps", "test_optimize", "test_actuator_cli",
                     "test_validation",
                     "test_controllers", "test_hamr_leg", "test_environment", "test_gymnasium_env"),
    "robots": ("test_robots", "test_gripper", "test_hamr_leg_linkage", "test_robobee_wing", "test_hamr_walk",
               "test_hamr_walk_rest", "test_hamr_walk_loops", "test_hamr_walk_study", "test_hamr_walk_contact",
               "test_gym_robots"),
    "contracts": ("test_contracts", "test_early_errors", "test_silent_answers", "test_reliability", "test_registries"),
}
#: test file (stem) -> its layer
LAYERS = {f: layer for layer, files in LAYER_FILES.items() for f in files}


def pytest_configure(config):
    config.addinivalue_line("markers", "cable: needs the cable representation (MuJoCo 3.x)")
    config.addinivalue_line("markers", "rod: needs the rod representation (MuJoCo 4.x)")
    config.addinivalue_line("markers", "dm_control: needs dm_control's Physics (MuJoCo 3.x with dm-control 1.0.50)")
    for layer in LAYER_FILES:
        config.addinivalue_line("markers", f"layer_{layer}: a test of the {layer} layer (tests/conftest.py LAYER_FILES)")


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
        layer = LAYERS.get(item.path.stem)
        if layer:
            item.add_marker(f"layer_{layer}")
        params = getattr(getattr(item, "callspec", None), "params", {})
        if not cable_available() and ("cable" in item.keywords or any(isinstance(v, str) and v == "cable" for v in values(params))):
            item.add_marker(no_cable)
        if rod_problem and ("rod" in item.keywords or any(isinstance(v, str) and v == "rod" for v in values(params))):
            item.add_marker(no_rod)
        if dm_control_problem() and "dm_control" in item.keywords:
            item.add_marker(no_dmc)
