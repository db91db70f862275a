"""``python -m mjeap.robots.gripper``: the experiment's command line, as ``mjeap robot gripper``."""
import sys

from ...io.commandline import run_script
from .experiments import main

sys.exit(run_script(main))
