"""Host models for the tests of systems (mjeap.simulation.system), in MuJoCo's internal units
(mm, mg, ms): a host from its bodies, and the two-finger grip on a bead."""
import mujoco

G = "0 0 -0.00980665"      # standard gravity in mm / ms^2

#: two sites facing each other 2.035 mm apart above a floor and a polystyrene bead (1.05 g/cm^3) of
#: radius 0.8 mm, wider than the fingers (1.37 mm), the fingers' faces 0.2 mm from it
GRIP = ('<site name="left" pos="0 -1.0175 0"/>'
        '<site name="right" pos="0 1.0175 0" quat="0 1 0 0"/>'
        '<geom name="floor" type="box" size="10 10 0.1" pos="4 0 -0.9" rgba="0.8 0.8 0.8 1"/>'
        '<body name="bead" pos="5 0 0"><freejoint/>'
        '<geom name="bead" type="sphere" size="0.8" mass="2.25" rgba="0.9 0.7 0.1 1"/></body>')


def host(body: str = "", extra: str = "", gravity: str = G) -> mujoco.MjSpec:
    """A host model of ``body`` (MJCF under the worldbody) and ``extra`` (after it)."""
    return mujoco.MjSpec.from_string(
        f'<mujoco><option gravity="{gravity}"/><worldbody>{body}</worldbody>{extra}</mujoco>')
