"""`python -m reliefkit.cli`."""

import sys

from . import main

sys.exit(main())
