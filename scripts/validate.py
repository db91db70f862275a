"""Run every validation experiment and write the report (same as ``mjeap validate``).

    python scripts/validate.py [names...] [--out out/validation] [--quick]
"""
import sys

from mjeap.cli import main

if __name__ == "__main__":
    sys.exit(main(["validate", *sys.argv[1:]]))
