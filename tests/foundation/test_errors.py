"""Bad input gets an error that names the parameter and the accepted range."""
from dataclasses import replace

import pytest

from mjeap import ParameterError, Payload, Scene, UnknownNameError, get_actuator
from mjeap.model.catalog import PEDOT_MICRO
from mjeap.cli import main


def test_unknown_actuator_suggests_closest():
    with pytest.raises(UnknownNameError, match="did you mean 'pedot-micro'"):
        get_actuator("pedot-mirco")
    with pytest.raises(UnknownNameError, match="'pzt-hamr-small'"):
        Scene("pzt-hamr-smal")


@pytest.mark.parametrize("kwargs,name", [
    (dict(segments=1), "segments"), (dict(segments=2.5), "segments"),
    (dict(orientation="sideways"), "orientation"), (dict(integrator="rk4"), "integrator"),
    (dict(damping_ratio=-0.1), "damping_ratio"),
])
def test_bad_scene_parameters(kwargs, name):
    with pytest.raises((ParameterError, UnknownNameError), match=name):
        Scene("pedot-micro", **kwargs)


def test_unknown_representation():
    with pytest.raises(UnknownNameError, match="representation"):
        Scene("pedot-micro", representation="rods")


@pytest.mark.parametrize("kwargs,name", [
    (dict(mass=0.0, position=5e-3), "payload.mass"), (dict(mass=-1e-6, position=5e-3), "payload.mass"),
    (dict(mass=1e-6, position=-1e-3), "payload.position"), (dict(mass=1e-6, position=0.0), "payload.position"),
])
def test_bad_payload(kwargs, name):
    with pytest.raises(ParameterError, match=name):
        Payload(**kwargs)


def test_payload_beyond_the_tip_names_the_range():
    with pytest.raises(ParameterError, match=r"payload.position.*\(0, 0.0075\] m"):
        Scene("pedot-micro", payload=Payload(1e-6, 8e-3))


def test_non_positive_size_in_a_user_actuator():
    bad = replace(PEDOT_MICRO, planform=replace(PEDOT_MICRO.planform, length=0.0))
    with pytest.raises(ParameterError, match="planform.length"):
        Scene(bad)
    bad = replace(PEDOT_MICRO, layers=(replace(PEDOT_MICRO.layers[0], thickness=-1e-6),))
    with pytest.raises(ParameterError, match="thickness"):
        Scene(bad)


def test_timestep_above_stability_limit_names_the_limit():
    limit = Scene("pedot-micro").choice.stability_limit
    with pytest.raises(ParameterError, match=r"timestep.*<= .* s.*stability limit.*highest bending mode"):
        Scene("pedot-micro", timestep=1.5 * limit)
    Scene("pedot-micro", timestep=0.9 * limit)  # below the limit: accepted


def test_cli_reports_errors_without_traceback(capsys):
    assert main(["show", "pedt"]) == 2
    assert "did you mean 'pedot-micro'" in capsys.readouterr().err
    assert main(["mjcf", "pedot-micro", "--payload", "1mg@9mm"]) == 2
    assert "payload.position" in capsys.readouterr().err
