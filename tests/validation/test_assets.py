"""assets/mjcf is up to date, in seconds, found by mjeap.assets.path, and every model compiles,
stays at rest when unforced and, driven in plain MuJoCo, moves as mjeap's run."""
import mujoco
import numpy as np
import pytest

from mjeap import get_actuator, load_mjcf
from mjeap import Scene
from mjeap.assets import ASSET_DIR, asset_name, asset_xml, iter_assets, path
from mjeap.errors import ParameterError, UnknownNameError
from mjeap.model.fields import read_units
from mjeap.model.mjcf import arena_bytes

ASSETS = list(iter_assets())


@pytest.mark.parametrize("actuator_id,representation", ASSETS)
def test_asset_is_not_stale(actuator_id, representation):
    path = ASSET_DIR / asset_name(actuator_id, representation)
    assert path.exists(), f"missing {path}: run python scripts/generate_mjcf.py"
    assert path.read_text() == asset_xml(actuator_id, representation), \
        f"{path.name} is stale: run python scripts/generate_mjcf.py"


def in_plane_sag(act, g=9.80665):
    """Sag (m) at the tip site of the strip bent along its width by its own weight and its
    tip block's (a point load at the block's centre), by Castigliano with EI_w(x) =
    EI(x) (w(x)/t)^2: int_0^L M(x) (L + l - x) / EI_w(x) dx, scipy quad."""
    from scipy.integrate import quad
    L, l = act.length, act.planform.extension_length
    P = act.planform.tip_block_mass * g

    def moment(x):
        own = quad(lambda s: act.mass_per_length_at(s)[0] * g * (s - x), x, L)[0]
        return own + P * (L + 0.5 * l - x)

    def EI_w(x):
        return act.flexural_rigidity_at(x)[0] * (float(act.width_at(x)) / act.thickness) ** 2

    return quad(lambda x: moment(x) * (L + l - x) / EI_w(x), 0, L, limit=100)[0]


#: the slowest at rest (4 s: the micro rod's 0.2x real time) runs with the slow tests
AT_REST = [pytest.param(a, r, marks=pytest.mark.slow) if (a, r) == ("pedot-micro", "rod") else (a, r)
           for a, r in ASSETS]


@pytest.mark.parametrize("actuator_id,representation", AT_REST)
def test_asset_compiles_and_stays_at_rest_for_1s(actuator_id, representation):
    """Unforced and horizontal (gravity along the width, out of the bending plane), 1 s:
    no instability warning, no motion in the bending direction (< 1e-9 L), and along the
    width at most the Euler-Bernoulli sag of the strip's in-plane rigidity EI_w(x) =
    EI(x) (w(x)/t)^2 under its weight and its tip block's (x 2: the sudden onset of gravity
    overshoots once); the cable and the rod bend that way. The planar hinge chain cannot
    move along the width at all."""
    act = get_actuator(actuator_id)
    m = load_mjcf(ASSET_DIR / asset_name(actuator_id, representation))
    d = mujoco.MjData(m)
    rest = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "rest")   # a drive at rest off 0 V (piezo bias)
    if rest >= 0:
        mujoco.mj_resetDataKeyframe(m, d, rest)
    mujoco.mj_forward(m, d)
    tip = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, "tip")
    p0 = d.site_xpos[tip].copy()
    u = read_units(m)
    mujoco.mj_step(m, d, nstep=int(round(1.0 / u.time / m.opt.timestep)))
    assert d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number == 0
    dx = (d.site_xpos[tip] - p0) * u.length  # clamp frame = world (horizontal)
    L = act.length
    sag = in_plane_sag(act)
    if representation == "hinge":
        sag = 0.0
    assert abs(dx[1]) < 1e-9 * L
    assert abs(dx[0]) < 1e-9 * L + 2 * sag**2 / L  # the sag's geometric shortening
    assert abs(dx[2]) <= 2 * sag + 1e-12 * L


@pytest.mark.parametrize("representation,segments", [("hinge", 20), ("cable", 20), pytest.param("hinge", 150, marks=pytest.mark.slow),
                                                     pytest.param("cable", 60, marks=pytest.mark.slow)])
def test_arena_is_sized_to_the_beam(representation, segments):
    """The MjData arena is sized from the dofs (no contacts: the finite-difference
    linearisation is the largest need), not MuJoCo's ~14 MiB default: a 20-hinge scene
    holds about 1 MiB, and long beams still build (their linearisation fits) and step."""
    s = Scene("pedot-micro", representation=representation, segments=segments)
    assert s.data.narena == arena_bytes(s.model.nv)
    if segments == 20:
        assert s.data.narena < 2 * 2**20
    s.run(20 * s.timestep)
    assert s.data.maxuse_arena < s.data.narena


ROD_ASSETS = [a for a, r in ASSETS if r == "rod"]


@pytest.mark.rod
@pytest.mark.parametrize("actuator_id", ROD_ASSETS)
def test_rod_asset_steps_in_plain_mujoco(actuator_id):
    """A rod file is self-contained (the flex's own damping, no mjeap numeric to apply):
    plain MuJoCo loads it and steps it 2000 steps from rest, gravity on, finite and with no
    warning of any kind."""
    import numpy as np
    m = mujoco.MjModel.from_xml_path(str(ASSET_DIR / asset_name(actuator_id, "rod")))
    assert m.opt.integrator == mujoco.mjtIntegrator.mjINT_DISCRETE and m.flex_damping[0] > 0
    d = mujoco.MjData(m)
    mujoco.mj_step(m, d, nstep=2000)
    assert np.all(np.isfinite(d.qpos)) and np.all(np.isfinite(d.qvel))
    assert [w.number for w in d.warning] == [0] * len(d.warning)


def test_only_beams_of_one_section_have_rod_files():
    """The rod has one section and one modulus: the tapered piezo bimorphs have none."""
    assert sorted(ROD_ASSETS) == sorted(a for a in {a for a, _ in ASSETS} if not a.startswith("pzt"))


@pytest.mark.parametrize("actuator_id", ["pedot-micro", "pzt-hamr-small"])
def test_the_viewer_looks_at_the_bending_plane_with_a_light_and_a_floor_that_touches_nothing(actuator_id):
    """The beam bends in its clamp's x-y plane (the hinge axis is z): the viewer's free
    camera must look along z (within 25 deg), not along the deflection y; a light and a
    floor that collides with nothing."""
    m = mujoco.MjModel.from_xml_path(str(ASSET_DIR / asset_name(actuator_id, "hinge")))
    az, el = np.radians(m.vis.global_.azimuth), np.radians(m.vis.global_.elevation)
    forward = np.array([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), np.sin(el)])
    assert abs(forward[2]) > np.cos(np.radians(25))
    assert m.nlight >= 1
    floor = m.geom("floor")
    assert floor.type[0] == mujoco.mjtGeom.mjGEOM_PLANE and floor.contype[0] == 0 and floor.conaffinity[0] == 0


def plain_units(m):
    """(L, M, T) of the custom numeric 'mjeap_units', read with MuJoCo alone."""
    i = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_NUMERIC, "mjeap_units")
    assert i >= 0, "no mjeap_units"
    return tuple(m.numeric_data[m.numeric_adr[i]:m.numeric_adr[i] + 3])


@pytest.mark.parametrize("actuator_id,representation", ASSETS)
def test_asset_is_in_seconds_and_found_by_path(actuator_id, representation):
    """Every shipped file, opened in plain MuJoCo, declares the second as its time unit (so
    MuJoCo's viewer plays physical time) and mm, mg; mjeap.assets.path finds it."""
    p = path(actuator_id, representation)
    assert p == ASSET_DIR / asset_name(actuator_id, representation)
    m = mujoco.MjModel.from_xml_path(str(p))
    assert plain_units(m) == (1e-3, 1e-6, 1.0)


def test_path_refuses_unknown_names():
    with pytest.raises(UnknownNameError):
        path("pedot-mikro")
    with pytest.raises(ParameterError, match="representation"):
        path("pzt-robobee", "rod")          # tapered: no rod file


DRIVEN = [(a, r) for a, r in ASSETS if r == "hinge" and not a.startswith("pvdf")]


def plain_step_response(m, steps=400, every=10):
    """Tip curvature (1/m, arc through clamp and tip) every ``every`` steps of a step of the
    drive to 3/4 of its range from rest, stepped with MuJoCo alone."""
    L = plain_units(m)[0]
    a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, "drive")
    assert a >= 0
    lo, hi = m.actuator_ctrlrange[a]
    d = mujoco.MjData(m)
    rest = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_KEY, "rest")
    if rest >= 0:
        mujoco.mj_resetDataKeyframe(m, d, rest)
    d.ctrl[a] = 0.75 * hi + 0.25 * lo
    clamp, tip, kappa = m.body("clamp").id, m.site("tip").id, []
    for _ in range(steps // every):
        mujoco.mj_step(m, d, nstep=every)
        R = d.xmat[clamp].reshape(3, 3)
        x, y, _ = R.T @ (d.site_xpos[tip] - d.xpos[clamp]) * L
        kappa.append(2 * y / (x * x + y * y))
    return np.array(kappa)


@pytest.mark.parametrize("actuator_id,representation", DRIVEN)
def test_driven_asset_in_plain_mujoco_moves_as_mjeaps_model(actuator_id, representation):
    """The files with their drive compiled in (actuator 'drive', ctrl in V), in seconds: a
    step of the drive from rest, 400 steps in plain MuJoCo, against the same driven model
    built by mjeap in its default units (mm, mg, ms) and read back from its MJCF text (as
    the file was): the tip curvature within 1e-9 of the swing, so the unit change moved
    nothing beyond float rounding (scripts/unit_change_check.py: every engine and
    representation); and the file's timestep is the scene's."""
    from mjeap.simulation.model_file import model_file
    m = mujoco.MjModel.from_xml_path(str(path(actuator_id, representation)))
    s = Scene(actuator_id, representation=representation)
    assert s.units.time == 1e-3
    ms = mujoco.MjModel.from_xml_string(model_file(s).spec.to_xml())
    assert m.opt.timestep * plain_units(m)[2] == pytest.approx(s.timestep, rel=1e-12)
    kappa, ref = plain_step_response(m), plain_step_response(ms)
    assert np.ptp(ref) > 0.1 * np.abs(ref).max() > 0
    assert np.max(np.abs(kappa - ref)) <= 1e-9 * np.ptp(ref)


@pytest.mark.parametrize("file", [asset_name(a, r) for a, r in ASSETS])     # by file: the cable's runs on 4.x too
def test_every_file_assets_path_hands_out_loads_on_this_mujoco(file):
    """mjeap.assets.path hands out only what the installed MuJoCo loads, plain
    (MjModel.from_xml_path) and through load_mjcf; a representation it cannot build (the
    cable on 4.x) is refused with the reason, and its file indeed does not load here."""
    from mjeap.model.mjcf import BUILDERS
    actuator_id, representation = next((a, r) for a, r in ASSETS if asset_name(a, r) == file)
    why = BUILDERS[representation].unavailable_reason()
    if why is None:
        p = path(actuator_id, representation)
        assert mujoco.MjModel.from_xml_path(str(p)).nbody > 2
        assert load_mjcf(p).nbody > 2
        return
    with pytest.raises(ParameterError, match="does not load on this MuJoCo"):
        path(actuator_id, representation)
    with pytest.raises(Exception):
        mujoco.MjModel.from_xml_path(str(ASSET_DIR / asset_name(actuator_id, representation)))
