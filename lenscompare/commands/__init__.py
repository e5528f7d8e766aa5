"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import cost, lens, plan, povray, preview, render, report

COMMANDS = [render, povray, report, cost, plan, lens, preview]
