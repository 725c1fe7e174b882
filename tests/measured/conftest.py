"""The twin, simulated once per session: the measured data of every test here is made from it."""

from __future__ import annotations

import dataclasses

import pytest

import emaphm
from emaphm import ControllerParams, EmaParams


@pytest.fixture(scope="session")
def twin() -> emaphm.SimResult:
    """HF twin, FDI chirp (1 s at 10 kHz), noise on: what a healthy rig would record."""
    return emaphm.simulate(noise=True, seed=7)


@pytest.fixture(scope="session")
def twin20() -> emaphm.SimResult:
    """The same twin with its controller and sensors at 20 kHz (dt = 1 µs divides 50 µs)."""
    params = dataclasses.replace(
        EmaParams(), controller=dataclasses.replace(ControllerParams(), f_s=20_000.0)
    )
    return emaphm.simulate(noise=True, seed=8, params=params)
