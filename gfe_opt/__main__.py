"""``python -m gfe_opt ...``: the same as the ``gfe-opt`` command."""

import sys

from .entry import main

sys.exit(main())
