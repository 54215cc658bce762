"""``python -m hybridtrack``: the same as the ``hybridtrack`` command."""

import sys

from .cli import main

sys.exit(main())
