"""Shared test helpers (plain imports, not fixtures): `from tests.helpers import faults, IDEAL, ...`."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import emaphm
from emaphm import EmaParams, SensorParams

__all__ = ["EXIT_OF_VERDICT", "IDEAL", "RAMP", "faults", "frictionless", "run_cli"]

# ideal converters: tests of physical invariants should not see the ADC's quantisation
IDEAL = EmaParams(sensors=SensorParams(bits_current=0, bits_position=0))
RAMP = emaphm.Ramp(rate=0.1, t_0=0.0, duration=0.6)  # constant speed: 7.5 electrical revolutions


def faults(**changes: float) -> tuple[float, ...]:
    """The healthy vector with some entries changed, e.g. faults(k3=0.3)."""
    k = np.array(emaphm.HEALTHY)
    for name, value in changes.items():
        k[int(name[1:]) - 1] = value
    return tuple(float(v) for v in k)


def frictionless(params: EmaParams = IDEAL) -> EmaParams:
    """`params` with the healthy friction (static, dynamic) and backlash set to zero."""
    tr = dataclasses.replace(params.transmission, F_S0=0.0, F_D0=0.0, B0=0.0)
    return dataclasses.replace(params, transmission=tr)


def run_cli(args, capsys):  # type: ignore[no-untyped-def]
    """Run ``emaphm ARGS`` in-process: (exit status, stdout, stderr)."""
    from emaphm.cli import main

    with pytest.raises(SystemExit) as exc:
        main(args)
        raise SystemExit(0)
    out = capsys.readouterr()
    return exc.value.code, out.out, out.err


# `emaphm identify`'s exit status by verdict (emaphm/cli/__init__.py): a tiny search may end in any
EXIT_OF_VERDICT = {"fits": 0, "doubtful": 4, "does not fit": 3}
