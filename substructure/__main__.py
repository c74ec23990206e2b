"""``python -m substructure``: the ``substructure`` command (:mod:`substructure.cli`)."""

import sys

from .cli import main

if __name__ == "__main__":  # not when a worker process of a study imports the main module (multiprocessing spawn)
    sys.exit(main())
