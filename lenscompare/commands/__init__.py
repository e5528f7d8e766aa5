"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import lens, povray, preview, render, report

COMMANDS = [render, povray, report, lens, preview]
