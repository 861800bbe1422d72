"""``python -m sixdof``: the ``sixdof`` command."""

import sys

from sixdof._entry import main

sys.exit(main())
