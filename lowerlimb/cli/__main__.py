"""``python -m lowerlimb.cli``: the ``lowerlimb`` command."""

import sys

from lowerlimb.cli import main

sys.exit(main())
