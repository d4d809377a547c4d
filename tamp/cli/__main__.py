"""``python -m tamp.cli``: the ``tamp`` command."""

import sys

from tamp.cli import main

sys.exit(main())
