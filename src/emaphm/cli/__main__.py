"""``python -m emaphm.cli``: the command line (as ``python -m emaphm``)."""

from . import main

main()
