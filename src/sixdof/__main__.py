"""``python -m sixdof``: the ``sixdof`` command."""

import sys

from sixdof.cli import main

sys.exit(main())
