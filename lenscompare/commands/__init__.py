"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import preview, render

COMMANDS = [render, preview]
