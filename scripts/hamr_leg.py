"""HAMR single leg (Jayaram et al. 2018, section 6.2): resonances, foot ellipse, phase loops.

The experiment lives in :mod:`mjeap.robots.hamr_leg`; this is its command line, the same as
``mjeap robot hamr-leg``:

    python scripts/hamr_leg.py --help
"""
import sys

from mjeap.io.commandline import run_script
from mjeap.robots.hamr_leg import main

if __name__ == "__main__":
    sys.exit(run_script(main))
