"""``python -m rover_cosim`` is ``rover-cosim``."""

import sys

from .cli import main

sys.exit(main())
