"""``python -m mjeap.robots.robobee_wing``: the experiment's command line, as ``mjeap robot robobee-wing``."""
import sys

from ...io.commandline import run_script
from .experiments import main

sys.exit(run_script(main))
