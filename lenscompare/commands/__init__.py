"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import check, cost, figures, lens, mitsuba, plan, povray, preview, render, report

COMMANDS = [render, povray, mitsuba, report, cost, plan, check, figures, lens, preview]
