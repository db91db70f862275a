"""``python -m mjeap.robots.hamr_walk``: the experiment's command line, as ``mjeap robot hamr-walk``."""
import sys

from ...io.commandline import run_script
from .cli import main

sys.exit(run_script(main))
