"""Fault identification (paper §5, DESIGN §5): the fault vector whose LF current best fits a measurement.

The pipeline, one module per stage (`identifier.FaultIdentifier.fit` runs 1-5 in order, each
``stage(state, context) -> (state, record)``; `api.identify` adds 6 and 7):

    settings        IdentifySettings: every option, checked          settings.py
    limits          every tuned constant of the stages               limits.py
    the recording   the twin's, a trace or a rig's recording         recording.py
    prepare         grid, compared samples, weights, eq. 3           context.py (signals, weights, fitness)
    1 search        the global search over [0, 1]^8                  search.py (optimizers, gwo, cmaes, problem,
                    (its first population: the start table)            start_table, multistart)
    2 polish        the best point's and the runner-ups' polishes    polish.py (preconditioned, descents, lm)
    3 final checks  the shorts' phases, a trapped eccentricity       checks.py
      least squares the search's last polish; the fit measured       polish.py, search.py
    4 second search the search again from another seed on a poor fit second_search.py
    5 last stage    the monitor's bias corrected by a switching model last_stage.py
    6 uncertainty   90 % intervals per fault                         uncertainty/
    7 verdict       fits or not, warnings, the faults present        verdict.py (detection, coverage)
    the result      IdentificationResult and its record              result.py

The entry points are also re-exported by the top-level package (``emaphm.identify``,
``emaphm.FaultIdentifier``, ``emaphm.IdentifySettings``). Names load on first use (PEP 562).
"""

from __future__ import annotations

from .._lazy import lazy_names

__all__ = [
    "CUTOFF_HZ",
    "Comparison",
    "FaultIdentifier",
    "IdentificationResult",
    "IdentifySettings",
    "Uncertainty",
    "absolute_errors",
    "detect",
    "identify",
    "lowpass",
    "nrmse",
    "percent_error",
    "verdicts",
]

_WHERE = {
    "CUTOFF_HZ": "signals", "Comparison": "signals", "lowpass": "signals", "nrmse": "signals",
    "absolute_errors": "metrics", "percent_error": "metrics", "FaultIdentifier": "identifier",
    "IdentificationResult": "result", "IdentifySettings": "settings", "identify": "api",
    "detect": "detection", "Uncertainty": "uncertainty", "verdicts": "uncertainty",
}  # fmt: skip


__getattr__, __dir__ = lazy_names(__name__, _WHERE, globals())
