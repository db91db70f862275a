"""Every kind of recording opens laid out with every signal readable (issue: recordings a
reviewer can read at a glance). Read back from the .rrd: the entities, the default
blueprint's views (mjeap.io.recording.read_blueprint) and the images. What they look like was
checked by rendering them (scripts/render_recording.py) and looking at the PNGs."""
import re

import mujoco
import numpy as np
import pytest

from mjeap import Scene, rollout
from mjeap.io.recording import deformation_scale, read_blueprint, read_recording, scale_bar_length

UNIT = re.compile(r"\(([^)]+)\)\s*$")


def covered(entity, views):
    return any(entity == v["origin"] or entity.startswith(v["origin"].rstrip("/") + "/") for v in views)


def series_names(rec, entity):
    out = []
    for b in rec[entity]:
        if "SeriesLines:names" in b.schema.names:
            out += [x for v in b.column(b.schema.names.index("SeriesLines:names")).to_pylist() for x in (v or [])]
    return out


@pytest.mark.parametrize("actuator,wave,duration,params", [
    ("pedot-micro", "square:1V@0.5Hz", 2.0, {}),                       # native rc-relaxation
    ("pzt-hamr-small", "sine:50V@200Hz,offset=100V", 0.01, {}),        # tiny motion: magnified
    ("ppy-trilayer", "square:0.5V@0.5Hz", 2.0, {}),
    ("pvdf-60", "step:600V", 0.1, {"stiffening": True}),               # loop, field stiffening
])
def test_rollout_recording_lays_out_every_signal(tmp_path, actuator, wave, duration, params):
    path = tmp_path / "r.rrd"
    r = rollout(Scene(actuator), wave, duration, drive_params=params, rrd=path)
    rec, views = read_recording(path), read_blueprint(path)
    plots = [e for e in rec if e.startswith("/plots/")]
    assert plots and all(covered(e, views) for e in plots)
    kinds = {(v["kind"], v["origin"]) for v in views}
    assert ("TextDocument", "/meta") in kinds and ("TimeSeries", "/plots/tip_angle") in kinds
    assert ("3D", "/beam") in kinds
    # every series says its unit; one view per drive unit
    for e in plots:
        names = series_names(rec, e)
        assert names and all(UNIT.search(n) for n in names), (e, names)
    units = {UNIT.search(k).group(1) for k in r.signals}
    drive_views = [v for v in views if v["origin"] == "/plots/drive"]
    assert {UNIT.search(v["name"]).group(1) for v in drive_views} == units
    # the 3D view states a magnified deformation exactly where the motion is below 1 % of L
    beam = next(v for v in views if v["kind"] == "3D")
    scale = deformation_scale(r, Scene(actuator).layout.length)
    assert ("deformation shown" in beam["name"]) == (scale != 1)
    small = np.abs(r.centreline[..., 1:]).max() < 0.01 * Scene(actuator).layout.length
    assert (scale > 1) == small
    if small:   # magnified to about a fifth of L, never more
        assert 0.08 < scale * np.abs(r.centreline[..., 1:]).max() / Scene(actuator).layout.length <= 0.2
    assert "/beam/scale_bar" in rec and "/beam/clamp" in rec


def test_deformation_scale_and_scale_bar_are_1_2_5_steps():
    class R:
        time = np.zeros(2)
        centreline = np.zeros((2, 3, 3))
    R.centreline[1, 2, 1] = 36e-6                          # the piezo's +-36 um on 9.2 mm
    assert deformation_scale(R, 9.2e-3) == 50.0            # 36 um x 50 = 1.8 mm, about 0.2 L
    R.centreline[1, 2, 1] = 1e-3
    assert deformation_scale(R, 6e-3) == 1.0
    assert scale_bar_length(6e-3) == 1e-3 and scale_bar_length(52e-3) == 1e-2


@pytest.mark.slow
def test_validation_recordings_show_checks_figure_and_beams(tmp_path):
    pytest.importorskip("matplotlib")
    from mjeap.validation import run_validation
    run_validation(["mechanics-section", "mutlu2013-identify", "mechanics-buckling"], out=tmp_path, progress=False)
    for name, beams in (("mechanics-section", True), ("mutlu2013-identify", False), ("mechanics-buckling", True)):
        path = tmp_path / f"{name}.rrd"
        rec, views = read_recording(path), read_blueprint(path)
        kinds = [v["kind"] for v in views]
        assert ("TextDocument", "/checks") in {(v["kind"], v["origin"]) for v in views}
        # the checks table starts with the verdict (a narrow view still shows it)
        doc = str(rec["/checks"][0].column(rec["/checks"][0].schema.names.index("TextDocument:text")).to_pylist())
        assert "| verdict | quantity |" in doc
        # curves against other quantities than time: the report's figure, not a bare 2D scene
        assert all(v["origin"] == "/figure" for v in views if v["kind"] == "2D")
        if (tmp_path / f"{name}.png").exists():
            assert "/figure" in rec and ("2D", "/figure") in {(v["kind"], v["origin"]) for v in views}
        assert ("3D" in kinds) == beams
        assert "Spatial2D" not in kinds and len(views) >= 2 or name == "mechanics-section"


def test_system_recording_has_a_group_per_actuator_and_every_body(tmp_path):
    from mjeap.simulation.system import System, attach
    spec = mujoco.MjSpec.from_string(
        '<mujoco><option gravity="0 0 -0.00980665"/><worldbody><site name="a"/><site name="b" pos="0 3 0"/>'
        '<body name="ball" pos="3 1.5 0"><freejoint/><geom type="sphere" size="0.3" mass="1"/></body>'
        '<geom name="floor" type="box" size="8 8 0.1" pos="3 0 -1"/></worldbody></mujoco>')
    acts = [attach(spec, "pedot-micro", site=n, prefix=n) for n in ("a", "b")]
    s = System(spec, acts)
    s.rollout(["step:1V", None], 0.05, rrd=tmp_path / "sys.rrd")
    rec, views = read_recording(tmp_path / "sys.rrd"), read_blueprint(tmp_path / "sys.rrd")
    origins = {v["origin"] for v in views}
    for n in ("a", "b"):
        assert f"/plots/{n}/tip_curvature" in origins and f"/plots/{n}/voltage" in origins
        assert f"/world/{n}/centreline" in rec
    assert "/world" in origins
    assert any(e.startswith("/world/bodies/ball/") for e in rec) and any(e.startswith("/world/bodies/world/") for e in rec)


def test_environment_episode_recording_is_laid_out(tmp_path):
    from mjeap.envs.environment import make_environment, run_episode
    env = make_environment("pedot-micro", time_limit=0.2, seed=0)
    run_episode(env, policy=lambda ts: [0.5], rrd=tmp_path / "ep.rrd")
    views = read_blueprint(tmp_path / "ep.rrd")
    rec = read_recording(tmp_path / "ep.rrd")
    assert all(covered(e, views) for e in rec if e.startswith("/plots/"))
    assert {("TextDocument", "/meta"), ("3D", "/beam")} <= {(v["kind"], v["origin"]) for v in views}
