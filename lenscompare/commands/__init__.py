"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import lens, preview, render

COMMANDS = [render, lens, preview]
