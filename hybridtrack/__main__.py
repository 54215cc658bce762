"""``python -m hybridtrack``: the same as the ``hybridtrack`` command."""

import sys

from .launch import main

sys.exit(main())
