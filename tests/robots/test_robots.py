"""The robot registry (mjeap.robots): every robot builds from its name alone, its named
read-outs answer in SI on the built system, and ``mjeap robot`` reaches each experiment's
command line. The physics of each robot is tested in its own file (test_gripper,
test_hamr_leg_linkage, test_hamr_walk, test_robobee_wing)."""
import numpy as np
import pytest

from mjeap import robots
from mjeap.cli import main
from mjeap.errors import UnknownNameError
from mjeap.simulation.system import System


def test_the_registry_holds_the_four_robots_with_tags():
    assert robots.names() == ["gripper", "hamr-leg", "hamr-walk", "robobee-wing"]
    assert robots.names("piezo") == ["hamr-leg", "hamr-walk", "robobee-wing"]
    assert all(robots.get(n).summary for n in robots.names())


@pytest.mark.parametrize("name", ["gripper", "hamr-walk", "robobee-wing"])
def test_a_robot_builds_from_its_name_and_reads_out_at_rest(name):
    system = robots.load(name)
    assert isinstance(system, System)
    for readout in robots.get(name).readouts.values():
        assert np.all(np.isfinite(readout(system)))


def test_the_robobee_wing_rests_at_zero_stroke():
    """Before any step the stroke hinge is at its reference: 0 rad."""
    wing = robots.get("robobee-wing")
    assert wing.readouts["stroke_angle"](wing.build(bias=100.0)) == 0.0


def test_an_unknown_robot_is_named_with_the_known_ones(capsys):
    with pytest.raises(UnknownNameError, match="did you mean 'hamr-leg'"):
        robots.get("hamr_leg")
    assert main(["robot", "hamr_leg"]) == 2
    assert "gripper, hamr-leg, hamr-walk, robobee-wing" in capsys.readouterr().err


def test_mjeap_robot_passes_its_options_to_the_experiment(capsys):
    with pytest.raises(SystemExit) as e:
        main(["robot", "robobee-wing", "--help"])
    assert e.value.code == 0 and "--quick" in capsys.readouterr().out


def test_the_robot_commands_help_names_every_registered_robot():
    """The help of ``mjeap robot`` names the robots without importing them (a cold ``mjeap
    show`` would pay for their SciPy and MjSpec code): the text must follow the registry."""
    from mjeap.cli import build_parser
    from mjeap.robots import names
    sub = build_parser()._subparsers._group_actions[0]
    text = next(a.help for a in sub._choices_actions if a.dest == "robot")
    assert all(n in text for n in names()), (names(), text)
