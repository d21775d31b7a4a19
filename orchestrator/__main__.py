"""``python -m orchestrator`` is ``rover-cosim``."""

import sys

from .cli import main

sys.exit(main())
