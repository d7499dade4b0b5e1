"""``python -m pkmlab.cli``."""

from . import main

main()
