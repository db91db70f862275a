"""RoboBee wing (Jayaram et al. 2018, section 6.1): stroke against frequency and the self-sensed stroke.

The experiment lives in :mod:`mjeap.robots.robobee_wing`; this is its command line, the same as
``mjeap robot robobee-wing``:

    python scripts/robobee_wing.py --help
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.robobee_wing import main

if __name__ == "__main__":
    sys.exit(run_script(main))
