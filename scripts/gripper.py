"""PEDOT micro-gripper: grip force, lift threshold and the hard-finger check.

The experiment lives in :mod:`mjeap.robots.gripper`; this is its command line, the same as
``mjeap robot gripper``:

    python scripts/gripper.py --help
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.gripper import main

if __name__ == "__main__":
    sys.exit(run_script(main))
