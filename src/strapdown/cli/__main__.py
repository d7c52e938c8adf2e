"""``python -m strapdown.cli``: the ``strapdown`` command."""

import sys

from . import main

sys.exit(main())
