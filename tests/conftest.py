"""Shared fixtures: simulations are cached per session so the suite runs each case once."""

from __future__ import annotations

import dataclasses
from functools import cache

import numpy as np
import pytest

import emaphm
from emaphm import EmaParams, SensorParams

# ideal converters: tests of physical invariants should not see the ADC's quantisation
IDEAL = EmaParams(sensors=SensorParams(bits_current=0, bits_position=0))
RAMP = emaphm.Ramp(rate=0.1, t_0=0.0, duration=0.6)  # constant speed: 7.5 electrical revolutions


def faults(**changes: float) -> tuple[float, ...]:
    """The healthy vector with some entries changed, e.g. faults(k3=0.3)."""
    k = np.array(emaphm.HEALTHY)
    for name, value in changes.items():
        k[int(name[1:]) - 1] = value
    return tuple(k)


@cache
def _sim(k: tuple[float, ...], command: object, ideal: bool, params: EmaParams | None) -> emaphm.SimResult:
    p = params if params is not None else (IDEAL if ideal else EmaParams())
    return emaphm.simulate(np.array(k), noise=False, params=p, command=command)  # type: ignore[arg-type]


@pytest.fixture(scope="session")
def sim():
    """sim(k, command=None, ideal=True, params=None) -> SimResult, noise off, cached per session."""

    def run(k, command=None, ideal=True, params=None):  # type: ignore[no-untyped-def]
        return _sim(tuple(float(v) for v in k), command, ideal, params)

    return run


def frictionless(params: EmaParams = IDEAL) -> EmaParams:
    tr = dataclasses.replace(params.transmission, F_S0=0.0, F_D0=0.0, B0=0.0)
    return dataclasses.replace(params, transmission=tr)
