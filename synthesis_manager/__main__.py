import sys

from synthesis_manager.cli import main

sys.exit(main())
