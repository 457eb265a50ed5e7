import sys

from synthesis_manager.programs.cli import main

sys.exit(main())
