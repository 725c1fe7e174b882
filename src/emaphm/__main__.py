"""``python -m emaphm``: the command line."""

from .cli import main

main()
