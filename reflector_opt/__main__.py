"""``python -m reflector_opt`` runs the command line."""

import sys

from reflector_opt.cli import main

sys.exit(main())
