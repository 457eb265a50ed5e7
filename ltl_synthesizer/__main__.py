"""``python -m ltl_synthesizer`` runs the ``gr1synth`` command line."""

import sys

from ltl_synthesizer.cli import main

sys.exit(main())
