"""``python -m people_tracker``: the ``people-tracker`` command line."""

import sys

from people_tracker.tracker.cli import main

sys.exit(main())
