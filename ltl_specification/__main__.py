"""``python -m ltl_specification --system atlas --goals look_down``: same as ``behavior-synthesis compile``."""

import sys

from ltl_specification.cli import main

sys.exit(main())
