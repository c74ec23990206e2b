"""``python -m substructure``: the ``substructure`` command (:mod:`substructure.cli`)."""

import sys

from .cli import main

sys.exit(main())
