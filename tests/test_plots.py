"""The figures leave the user's matplotlib alone (review L6): no backend switch, no pyplot; the
prognosis figure is in physical units and stops at the physical limit (issue 35)."""

import json
import subprocess
import sys

import numpy as np
import pytest
from matplotlib.collections import PolyCollection

import emaphm.plots
from emaphm.actuator import load_params
from emaphm.campaign.store import RESULT_COLUMNS, ResultStore
from emaphm.faults import HEALTHY, N_MIN
from emaphm.params import EmaParams
from emaphm.plots import plot_rul
from emaphm.plots_rul import rul_figure, rul_panels
from emaphm.prognostics import rul_report

# a fresh interpreter: whether pyplot is loaded is the process's state, and other tests may load it
# (cma does). A "module://" backend name is accepted without importing it, so no display is needed.
CHECK = """
import sys, tempfile
from pathlib import Path
import matplotlib
matplotlib.use("module://an_interactive_backend")
from emaphm.plots import plot_convergence
with tempfile.TemporaryDirectory() as d:
    plot_convergence({"run": [3.0, 2.0, 1.0]}, Path(d) / "c.png")
    size = (Path(d) / "c.png").stat().st_size
print(matplotlib.rcParams["backend"], "matplotlib.pyplot" in sys.modules, size > 1000)
"""


def test_a_plot_keeps_the_users_backend_and_does_not_load_pyplot():
    res = subprocess.run([sys.executable, "-c", CHECK], capture_output=True, text=True, check=True)
    assert res.stdout.split() == ["module://an_interactive_backend", "False", "True"]


def test_every_public_plot_function_is_in_all():
    public = {n for n in vars(emaphm.plots) if n.startswith("plot_")}
    assert public == set(emaphm.plots.__all__)


# -- the prognosis figure (`plot_rul`) in physical units, its projections clipped to what is physical --


def _rows(flights, values, sd, present):
    """A results store's rows of actuator A1 (as tests/test_prognostics.py builds them): the fault
    columns `values` (column -> one value per flight), the others healthy, every standard deviation
    `sd`, the faults `present` detected at every flight."""
    rows = []
    for i, n in enumerate(flights):
        row = {c: None for c in RESULT_COLUMNS}
        k = {f"k{j + 1}": float(HEALTHY[j]) for j in range(8)}
        k.update({c: float(v[i]) for c, v in values.items()})
        row.update(
            job_key=f"A1-{n}", campaign="c", actuator="A1", flight=int(n), seed=1, identify_seed=1, verdict="fits",
            **k, **{f"std_k{j}": sd for j in range(1, 9)},
            fault_verdicts=json.dumps(dict.fromkeys(present, "present")), uq_flags=json.dumps([[] for _ in range(8)]),
        )  # fmt: skip
        rows.append(row)
    return rows


@pytest.fixture
def rul(tmp_path):
    """A prognosis of 20 flights: a coil short growing exponentially (its projection to the 95 %
    crossing of 0.9 passes k = 1), backlash growing linearly, the gain drifting down."""
    n = np.arange(1, 21)
    noise = 1 + 0.1 * np.random.default_rng(1).standard_normal(n.size)
    values = {"k3": 0.02 * np.exp(0.15 * n) * noise, "k2": 0.01 * n, "k8": 0.5 - 0.01 * n}
    ResultStore(tmp_path / "s").write("results", _rows(n, values, 0.01, ["short_a", "backlash", "kp_drift"]))
    return rul_report(tmp_path / "s", "A1", thresholds={"short_a": 0.9, "backlash": 0.25, "kp_drift": 0.3})


def test_the_rul_projection_stops_at_the_physical_limit(rul):
    trend, est = rul["_trends"]["short_a"], rul["_estimates"]["short_a"]
    assert trend.band(rul["at_flight"] + est.p95)[1] > 1.0  # drawn to the 95 % crossing, it would pass k = 1
    panels = rul_panels(rul)
    assert set(panels) == {"short_a", "backlash", "kp_drift"}
    short = panels["short_a"]
    most = 100.0 * (1.0 - N_MIN)  # [%] the model keeps N_MIN of a shorted coil's turns (DESIGN §3.6)
    assert max(short.trend.max(), short.band_high.max()) <= most + 1e-9
    # the trend is drawn up to the limit, not short of it, and stops there
    assert short.trend[-1] == pytest.approx(most, abs=0.01)
    assert short.grid[-1] < rul["at_flight"] + est.p95
    for p in panels.values():
        assert np.all(p.distance <= p.limit_distance + 1e-12)
        assert np.all((p.band_distance >= 0.0) & (p.band_distance <= p.limit_distance + 1e-12))
    drift = panels["kp_drift"]  # drifting down, k8 >= 0: K_P = K_P0·(0.5 + k8) is at least 50 % of K_P0
    assert drift.limit_distance == 0.5 and min(drift.trend.min(), drift.band_low.min()) >= -50.0 - 1e-9


def test_the_rul_threshold_and_axes_are_in_physical_units(rul, tmp_path):
    params = EmaParams()
    panels = rul_panels(rul, params)
    B0 = params.transmission.B0
    # DESIGN §2, B = B0·(1 + 99·k2), in mrad
    assert panels["backlash"].threshold == pytest.approx(1e3 * B0 * (1 + 99 * 0.25), rel=1e-12)
    assert panels["short_a"].threshold == pytest.approx(90.0)  # N_A = 1 − k3: 90 % of its turns shorted
    assert panels["kp_drift"].threshold == pytest.approx(-30.0)  # K_P = K_P0·(0.5 + k8), k8 = 0.5 − 0.3
    assert panels["kp_drift"].value[-1] == pytest.approx(-20.0)  # flight 20 measured k8 = 0.3, below healthy
    (tmp_path / "a.toml").write_text(f"[transmission]\nB0 = {2 * B0!r}\n")  # the actuator's params are used
    bigger = rul_panels(rul, load_params(tmp_path / "a.toml"))["backlash"]
    assert bigger.threshold == pytest.approx(2 * panels["backlash"].threshold, rel=1e-12)
    fig = rul_figure(rul, params)
    axes = fig.axes
    labels = [ax.get_ylabel() for ax in axes]
    assert {"backlash B [mrad]", "phase A shorted turns [%]", "K_P drift [% of K_P0]"} <= set(labels)
    short_ax = next(ax for ax in axes if ax.get_ylabel() == "phase A shorted turns [%]")
    drawn = [line.get_ydata() for line in short_ax.get_lines()]
    assert np.max(np.concatenate([np.atleast_1d(y) for y in drawn if len(y) > 2])) <= 95.0 + 1e-9
    assert any(np.allclose(y, 90.0) for y in drawn)  # the threshold line, at its physical value
    band = next(c for c in short_ax.collections if isinstance(c, PolyCollection))  # fill_between's
    assert band.get_paths()[0].vertices[:, 1].max() <= 95.0 + 1e-9
    assert next(ax for ax in axes if ax.get_xlabel()).get_xlabel() == "flights from flight 20"
    out = plot_rul(rul, tmp_path / "rul.png", params=tmp_path / "a.toml")
    assert out.stat().st_size > 10_000
