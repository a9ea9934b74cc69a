"""``python -m pendular <command> ...``: the ``pendular`` command."""

import sys

from pendular.cli import main

sys.exit(main())
