"""``python -m skmotion`` runs the ``skmotion`` command."""

import sys

from skmotion.cli import main

if __name__ == "__main__":
    sys.exit(main())
