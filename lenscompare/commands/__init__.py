"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import check, cost, export, figures, lens, measure, mitsuba, plan, povray, preview, render, report, sweep

COMMANDS = [render, povray, mitsuba, export, measure, report, cost, sweep, plan, check, figures, lens, preview]
