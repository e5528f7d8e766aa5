"""Sub-commands of the command line, in the order ``--help`` lists them."""

from . import check, cost, figures, lens, plan, povray, preview, render, report, sweep

COMMANDS = [render, povray, report, cost, plan, check, figures, lens, preview, sweep]
