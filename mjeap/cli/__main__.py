"""``python -m mjeap.cli``: the ``mjeap`` command line."""
import sys

from . import main

sys.exit(main())
