"""``python -m orthoscope``: the same command line as ``orthoscope``."""

import sys

from orthoscope.cli import main

sys.exit(main())
