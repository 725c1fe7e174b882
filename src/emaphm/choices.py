"""The names a user chooses among, with no numpy: the CLI's choice lists and the API's checks.

Imported by both sides, so that ``emaphm --help`` answers without loading numpy and no list of
choices is kept twice. Each name's meaning is in the module that implements it (named beside it).
"""

from __future__ import annotations

__all__ = [
    "COMMAND_NAMES",
    "HEALTHY_TEXT",
    "LAST_STAGES",
    "MONITORS",
    "OPTIMIZERS",
    "SLOPE_UNITS",
    "STARTS",
    "UQ_METHODS",
]

# the global search (`identification.search`): the paper's GA, DE, PSO, CMA-ES, grey wolf
OPTIMIZERS = ("ga", "de", "pso", "cmaes", "gwo", "multistart")
# the GA's first population (`identification.start_table`): "random" uniform (the paper's),
# "table" from the start table, "auto" (the default) the table for built-in commands and recordings of one
STARTS = ("random", "table", "auto")
# the 90 % intervals of each fault (`identification.uncertainty`)
UQ_METHODS = ("none", "laplace", "mcmc")
# the stage after the search (`identification.last_stage`): "auto" runs "switching" with the
# default monitor, "none" with the paper's
LAST_STAGES = ("auto", "switching", "none")
# the monitor model (`models.MonitorEma`): the calibrated one, or the paper's eqs. 1-2 alone
MONITORS = ("default", "paper")
# the time unit of the slope in eq. (3)'s weights (`identification.fitness.Fitness`)
SLOPE_UNITS = ("s", "ms")
# the position commands by name (`commands.COMMANDS`)
COMMAND_NAMES = ("chirp", "chirp-hold", "steps", "step", "ramp", "sine")
# the healthy fault vector k1..k8 (`faults.HEALTHY`) as the CLI prints it
HEALTHY_TEXT = "0,0,0,0,0,0,0,0.5"
