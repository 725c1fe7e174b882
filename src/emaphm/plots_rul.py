"""The prognosis figure of ``emaphm rul --plot`` (`plot_rul`), each fault in physical units.

A tracked fault's trend (`emaphm.prognostics.DegradationTrend`) is of its distance d from healthy
in fault units; the figure draws the fault value healthy + side·d (side: where the measurements
lie, `DegradationTrend.side`) in the actuator's physical units, by the DESIGN §2 mapping
(`emaphm.faults.fault_parameter_columns`, as the report's `emaphm.tables.physical_faults`):

| fault        | y axis                          | secondary axis  |
|--------------|---------------------------------|-----------------|
| friction     | static friction F_S [N·m]       | × nominal F_S0  |
| backlash     | backlash B [mrad]               | × nominal B0    |
| short_a/b/c  | shorted turns of the phase [%]  |                 |
| eccentricity | relative eccentricity ζ [%]     |                 |
| kp_drift     | K_P drift [% of K_P0]           | K_P [A/rad]     |

A projection stops at the edge of what is physical: the fault value in [0, 1] (a distance at most
1 − healthy above healthy, healthy below), and for a short the most turns the model can lose
(1 − `emaphm.faults.N_MIN`). `rul_panels` computes the plotted arrays, `plot_rul` draws them.
"""

from __future__ import annotations

import math
import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from ._canvas import new_figure
from .failure import FAULTS
from .faults import HEALTHY, N_MIN, fault_parameter_columns
from .params import EmaParams

__all__ = ["RulPanel", "physical_limit", "physical_values", "plot_rul", "rul_figure", "rul_panels"]

Z90 = 1.645  # a measurement's 90 % whisker is ± Z90 standard deviations
GRID = 200  # flights of a drawn trend

_Columns = dict[str, NDArray[np.float64]]
_Physical = Callable[[_Columns, EmaParams], NDArray[np.float64]]


def _shorted(phase: str) -> _Physical:
    """Phase `phase`'s shorted turns [%] from the mapped columns: 100·(1 − N)."""
    return lambda c, p: 100.0 * (1.0 - c[f"N_{phase}"])


# fault -> (y label, physical value from the mapped parameters' columns, `fault_parameter_columns`)
_PHYSICAL: dict[str, tuple[str, _Physical]] = {
    "friction": ("static friction F_S [N·m]", lambda c, p: c["F_S"]),
    "backlash": ("backlash B [mrad]", lambda c, p: 1e3 * c["B"]),
    **{f"short_{x.lower()}": (f"phase {x} shorted turns [%]", _shorted(x)) for x in "ABC"},
    "eccentricity": ("eccentricity ζ [%]", lambda c, p: 100.0 * c["zeta"]),
    "kp_drift": ("K_P drift [% of K_P0]", lambda c, p: 100.0 * (c["K_P"] / p.controller.K_P0 - 1.0)),
}  # fmt: skip


def physical_values(name: str, k: ArrayLike, params: EmaParams | None = None) -> NDArray[np.float64]:
    """Fault `name`'s values `k` (fault units, clipped to [0, 1]; the other faults healthy) in its
    physical unit (the module's table) for the actuator `params` (default: the nominal one)."""
    kk = np.clip(np.atleast_1d(np.asarray(k, dtype=np.float64)), 0.0, 1.0)
    K = np.tile(HEALTHY, (kk.size, 1))
    K[:, int(FAULTS[name][0][1:]) - 1] = kk
    params = params or EmaParams()
    return _PHYSICAL[name][1](fault_parameter_columns(K, params), params)


def physical_limit(name: str, side: float = 1.0) -> float:
    """The largest distance from healthy (fault units) that fault `name` can reach on `side` (+1
    above healthy, −1 below): 1 − healthy or healthy, and for a short 1 − `N_MIN` (the turns kept)."""
    healthy = FAULTS[name][2]
    limit = 1.0 - healthy if side > 0 else healthy
    return min(limit, 1.0 - N_MIN) if name.startswith("short_") else limit


def _secondary(name: str, params: EmaParams) -> tuple[str, Callable[..., Any], Callable[..., Any]] | None:
    """The panel's secondary y axis: its label and the maps physical → it and back (None: none)."""
    scale = {"friction": (params.transmission.F_S0, "× nominal F_S0"),
             "backlash": (1e3 * params.transmission.B0, "× nominal B0")}.get(name)  # fmt: skip
    if scale is not None and scale[0] > 0:
        s = scale[0]
        return scale[1], lambda v: np.asarray(v) / s, lambda x: np.asarray(x) * s
    if name == "kp_drift":
        K_P0 = params.controller.K_P0
        return ("K_P [A/rad]", lambda v: K_P0 * (1 + np.asarray(v) / 100),
                lambda x: 100 * (np.asarray(x) / K_P0 - 1))  # fmt: skip
    return None


@dataclass(frozen=True)
class RulPanel:
    """One tracked fault's panel of `plot_rul`, in physical units (`label`) unless named ``distance``.

    t, value, low, high : the measurements' flights, values and 90 % interval ends
    grid : flights of the trend: from the first measurement to the 95 % crossing of the threshold,
        or to where the trend reaches the physical limit, whichever comes first
    trend, band_low, band_high : the fitted trend and its 90 % band on `grid`
    distance, band_distance : the trend and its band (2, grid) as distances from healthy [fault units]
    threshold, threshold_distance : the failure threshold (physical; from healthy, fault units)
    limit_distance : the largest physical distance from healthy on the fault's side (`physical_limit`)
    """

    name: str
    label: str
    t: NDArray[np.float64]
    value: NDArray[np.float64]
    low: NDArray[np.float64]
    high: NDArray[np.float64]
    grid: NDArray[np.float64]
    trend: NDArray[np.float64]
    band_low: NDArray[np.float64]
    band_high: NDArray[np.float64]
    distance: NDArray[np.float64]
    band_distance: NDArray[np.float64]
    threshold: float
    threshold_distance: float
    limit_distance: float


def _grid_end(trend: Any, est: Any, t_now: float, limit: float) -> float:
    """The flight the drawn trend ends at: the 95 % crossing (beyond all draws: twice the history),
    or earlier where the fitted trend reaches the physical `limit` (a distance)."""
    t0 = float(np.min(trend.t))
    end = max(t_now + (est.p95 if math.isfinite(est.p95) else 2 * (t_now - t0 + 1)), t_now + 1)
    (phi, theta), _ = trend.fit()
    g = math.log(limit) if trend.law == "exponential" else limit
    reach = (g - phi) / theta if theta > 0 else math.inf  # as `prognostics.trend.crossings`
    return min(end, reach) if reach > t0 else end


def _panel(name: str, trend: Any, est: Any, threshold: float, t_now: float, params: EmaParams) -> RulPanel:
    """The arrays of one fault's panel (`RulPanel`)."""
    side, healthy = trend.side, trend.healthy
    limit = physical_limit(name, side)
    grid = np.linspace(float(np.min(trend.t)), _grid_end(trend, est, t_now, limit), GRID)
    d = np.clip(trend.value(grid), 0.0, limit)  # the ceiling guards rounding at the grid's end
    band = np.clip(np.vstack(trend.band(grid)), 0.0, limit)  # a band wider than physics stops at it
    k, sd = np.asarray(trend.k), np.asarray(trend.sd)

    def phys(dist: ArrayLike) -> NDArray[np.float64]:
        return physical_values(name, healthy + side * np.asarray(dist), params)

    ends = np.vstack([phys(k - Z90 * sd), phys(k + Z90 * sd)])  # below healthy, the nearer end is higher
    return RulPanel(
        name=name, label=_PHYSICAL[name][0], t=np.asarray(trend.t), value=phys(k),
        low=ends.min(axis=0), high=ends.max(axis=0), grid=grid, trend=phys(d),
        band_low=phys(band[0]), band_high=phys(band[1]), distance=d, band_distance=band,
        threshold=float(phys(threshold)[0]), threshold_distance=threshold, limit_distance=limit,
    )  # fmt: skip


def rul_panels(report: dict[str, Any], params: EmaParams | None = None) -> dict[str, RulPanel]:
    """The arrays `plot_rul` draws for each tracked fault of `report` (`prognostics.rul_report`),
    in the physical units of the actuator `params` (default: the nominal one)."""
    params = params or EmaParams()
    panels = {}
    for name, trend in report["_trends"].items():
        threshold = report["faults"][name]["threshold"]
        panels[name] = _panel(name, trend, report["_estimates"][name], threshold, report["at_flight"], params)
    return panels


def _draw_panel(
    ax: Any, p: RulPanel, f: dict[str, Any], est: Any, report: dict[str, Any], params: EmaParams
) -> None:
    """One fault's panel: measurements, trend and band, threshold, RUL range, axes."""
    t_now = report["at_flight"]
    yerr = np.vstack([p.value - p.low, p.high - p.value])
    ax.errorbar(p.t, p.value, yerr=yerr, fmt="o", ms=3, color="k", elinewidth=0.7,
                label="identified (90 % interval)")  # fmt: skip
    fitted = f"{f['law']} law" + (" (ProgPy UKF)" if report.get("estimator") == "ukf" else "")
    ax.plot(p.grid, p.trend, "C0", lw=1.2, label=fitted)
    ax.fill_between(p.grid, p.band_low, p.band_high, color="C0", alpha=0.15, lw=0)
    mark = " (placeholder)" if f["placeholder"] else ""
    unit = p.label[p.label.index("[") + 1 : -1]
    ax.axhline(p.threshold, color="C3", lw=1, ls="--",
               label=f"failure threshold {p.threshold:.3g} {unit} ({p.threshold_distance:g} from healthy in fault "
                     f"units){mark}")  # fmt: skip
    ax.axvline(t_now, color="0.5", lw=0.8)
    if math.isfinite(est.p05):
        right = t_now + est.p95 if math.isfinite(est.p95) else ax.get_xlim()[1]
        ax.axvspan(t_now + est.p05, right, color="C3", alpha=0.08, label="RUL 5-95 %")
    ax.set_title(f"{p.name} (k{FAULTS[p.name][0][1:]})", fontsize=9, loc="left")
    ax.set_ylabel(p.label)
    secondary = _secondary(p.name, params)
    if secondary is not None:
        ax.secondary_yaxis("right", functions=secondary[1:]).set_ylabel(secondary[0])
    ax.legend(fontsize=7, loc="best")
    ax.grid(alpha=0.3)


def rul_figure(report: dict[str, Any], params: EmaParams | None = None) -> Any:
    """The figure of `plot_rul` (a `matplotlib.figure.Figure`), not written."""
    params = params or EmaParams()
    panels = rul_panels(report, params)
    estimates = report["_estimates"]
    fig = new_figure((9, 2.6 * (len(panels) + 1)))
    axes = fig.subplots(len(panels) + 1, 1, squeeze=False)[:, 0]
    for ax, (name, p) in zip(axes[:-1], panels.items(), strict=True):
        _draw_panel(ax, p, report["faults"][name], estimates[name], report, params)
    ax = axes[-1]
    t_now = report["at_flight"]
    first = estimates.get("first failure")
    if first is not None:
        finite = first.samples[np.isfinite(first.samples)]
        if len(finite):
            ax.hist(finite, bins=50, color="C3", alpha=0.7)
        ax.set_title(f"flights to the first failure from flight {t_now:g}: median {first.median:.1f}, "
                     f"5-95 % {first.p05:.1f}-{first.p95:.1f}", fontsize=9)  # fmt: skip
    ax.set_xlabel(f"flights from flight {t_now:g}")
    ax.set_ylabel("draws")
    fig.suptitle(f"actuator {report['actuator']} ({report['campaign']})", fontsize=10)
    return fig


def plot_rul(
    report: dict[str, Any], path: Path, params: EmaParams | str | os.PathLike[str] | None = None
) -> Path:
    """An actuator's prognosis (`prognostics.rul_report`) written to `path`: per tracked fault, in
    the physical units of the actuator `params` (`EmaParams` or an actuator file; default: the
    nominal actuator), its measurements with 90 % whiskers, the fitted law with its band up to the
    threshold's 95 % crossing or the physical limit, the failure threshold and the RUL's 5-95 %
    range; below, the distribution of the flights to the first failure."""
    from .actuator import resolve_params

    rul_figure(report, resolve_params(params)).savefig(path, dpi=110)
    return path
