"""``python -m jourdain.cli``: the ``jourdain`` command."""

import sys

from . import main

sys.exit(main())
