"""``python -m manakov``: the ``manakov`` command line (see :mod:`manakov.cli`)."""

import sys

from .cli import main

sys.exit(main())
