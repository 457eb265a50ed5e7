import sys

from sm_generation.cli import main

sys.exit(main())
