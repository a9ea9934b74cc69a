"""``python -m pendular.cli <command> ...``: the ``pendular`` command."""

import sys

from pendular.cli import main

sys.exit(main())
