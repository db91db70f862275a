"""``python -m mjeap.robots.hamr_leg``: the experiment's command line, as ``mjeap robot hamr-leg``."""
import sys

from ...io.commandline import run_script
from .experiments import main

sys.exit(run_script(main))
