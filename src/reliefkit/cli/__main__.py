"""`python -m reliefkit.cli`."""

from . import run

run()
