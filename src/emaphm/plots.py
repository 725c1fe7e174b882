"""Figures (matplotlib, Agg backend): the HF response, the LF calibration (like the paper's Fig. 4), fits, convergence, fault vectors.

The prognosis figure (`plot_rul`) lives in `emaphm.plots_rul` and is re-exported here.

Each figure is a `matplotlib.figure.Figure` drawn by its own Agg canvas and written to a file: no
pyplot, so the process's backend (an interactive user's, a notebook's) and pyplot's list of open
figures are left alone.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from pathlib import Path

import numpy as np

from ._canvas import new_figure as _figure
from .identification.signals import lowpass
from .plots_rul import plot_rul  # re-exported: the prognosis figure
from .results import SimResult

__all__ = [
    "plot_calibration",
    "plot_convergence",
    "plot_faults",
    "plot_fit",
    "plot_fit_curves",
    "plot_response",
    "plot_rul",
    "plot_vectors",
]


def plot_response(runs: Mapping[str, SimResult], path: Path, title: str) -> Path:
    """Command and user position, phase currents (of the last run), i_q of every run (Fig. 4a)."""
    fig = _figure((9, 8))
    ax = fig.subplots(3, 1, sharex=True)
    last = list(runs.values())[-1]
    ax[0].plot(last.t, last.theta_cmd, "k--", lw=1, label=r"$\theta_{cmd}$")
    for label, r in runs.items():
        ax[0].plot(r.t, r.theta_u, lw=1.2, label=rf"$\theta_u$ {label}")
        ax[2].plot(r.t, r.i_q, lw=0.6, label=rf"$i_q$ {label}")
    ax[0].set_ylabel("user position [rad]")
    for name in ("i_a", "i_b", "i_c"):
        if name in last.signals:
            ax[1].plot(last.t, last[name], lw=0.6, label=name)
    ax[1].set_ylabel("phase current [A]")
    ax[2].set_ylabel(r"$i_q$ [A]")
    ax[2].set_xlabel("time [s]")
    for a in ax:
        a.legend(loc="upper right", fontsize=8, ncols=3)
        a.grid(alpha=0.3)
    fig.suptitle(title)
    fig.savefig(path, dpi=110)
    return path


def plot_calibration(
    cases: Mapping[str, tuple[SimResult, SimResult, SimResult]], path: Path, f_s: float = 1e4
) -> Path:
    """HF i_q vs LF current before and after calibration (filtered), one row per case (Fig. 4b)."""
    fig = _figure((9, 3.2 * len(cases)))
    ax = fig.subplots(len(cases), 1, sharex=True)
    for a, (name, (hf, before, after)) in zip(np.atleast_1d(ax), cases.items(), strict=True):
        ref = lowpass(hf.i_q, f_s)
        for label, r, style in (("LF before calibration", before, ":"), ("LF calibrated", after, "-")):
            y = lowpass(r.i_q, f_s)
            e = np.linalg.norm(y - ref) / np.linalg.norm(ref - ref.mean())
            a.plot(r.t, y, style, lw=1.0, label=f"{label} (NRMSE {100 * e:.1f} %)")
        a.plot(hf.t, ref, "k", lw=0.8, alpha=0.7, label="HF $i_q$")
        a.set_title(name, fontsize=10)
        a.set_ylabel("filtered current [A]")
        a.legend(loc="upper right", fontsize=8)
        a.grid(alpha=0.3)
    np.atleast_1d(ax)[-1].set_xlabel("time [s]")
    fig.savefig(path, dpi=110)
    return path


def plot_fit(
    t: np.ndarray, measured: np.ndarray, identified: np.ndarray, path: Path, f_s: float = 1e4
) -> Path:
    """Measured (raw and filtered) vs identified current (filtered) and their residual."""
    curves = {"t": t, "measured": lowpass(measured, f_s), "fitted": lowpass(identified, f_s)}
    return plot_fit_curves(curves, path, raw=measured)


def plot_fit_curves(
    curves: Mapping[str, np.ndarray],
    path: Path,
    title: str = "",
    raw: np.ndarray | None = None,
    model: str = "LF model",
    fitted: str = "at the identified faults",
) -> Path:
    """An identification's fit (`FaultIdentifier.curves`): the filtered measured current, the
    `model`'s current at the estimate (the LF model's, or the switching model's after the last
    stage; `fitted` says what the estimate is) and their residual; samples the fitness left out (a
    rest in a hold, motion faster than the monitor was fitted on) shaded, and the unfiltered
    measurement `raw` behind when given."""
    t, m, f = curves["t"], curves["measured"], curves["fitted"]
    fig = _figure((9, 6))
    ax = fig.subplots(2, 1, sharex=True, height_ratios=[3, 1])
    if raw is not None:
        ax[0].plot(t, raw, color="0.8", lw=0.5, label="measured $i_q$ (raw)")
    ax[0].plot(t, m, "k", lw=1.0, label="measured $i_q$, filtered")
    ax[0].plot(t, f, "C1", lw=1.0, label=f"{model} {fitted}")
    ax[0].set_ylabel("current [A]")
    ax[0].legend(loc="upper right", fontsize=8)
    ax[1].plot(t, m - f, "C3", lw=0.8)
    ax[1].set_ylabel("residual [A]")
    ax[1].set_xlabel("time [s]")
    left_out = np.asarray(curves.get("compared", np.ones_like(t))) <= 0
    for a in ax:
        a.grid(alpha=0.3)
        if left_out.any():
            a.fill_between(t, 0, 1, where=left_out, color="0.9", transform=a.get_xaxis_transform(),
                           label="not compared")  # fmt: skip
    if title:
        fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    return path


def plot_convergence(histories: Mapping[str, list[float]], path: Path, title: str = "") -> Path:
    """Best fitness per generation of each run (log scale)."""
    fig = _figure((7, 4))
    ax = fig.subplots()
    for label, h in histories.items():
        ax.semilogy(np.arange(1, len(h) + 1), h, lw=1.2, label=label)
    ax.set_xlabel("generation (global search, then polish)")
    ax.set_ylabel("best fitness, eq. (3) [A²]")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=8)
    if title:
        ax.set_title(title, fontsize=10)
    fig.savefig(path, dpi=110)
    return path


def plot_faults(
    distance: Mapping[str, float],
    path: Path,
    *,
    intervals: Mapping[str, tuple[float, float]] | None = None,
    truth: Mapping[str, float] | None = None,
    thresholds: Mapping[str, Mapping[str, float] | None] | None = None,
    labels: Mapping[str, str] | None = None,
    verdicts: Mapping[str, str] | None = None,
    signed: Collection[str] = (),
    note: str = "",
    title: str = "",
) -> Path:
    """A diagnosis's faults as distances from healthy (fault units), one bar per fault of `distance`
    (name → k − healthy) coloured by its verdict, with its 90 % interval (name → (low, high) as
    distances) as a whisker, the true distance as a black diamond, each of `thresholds` (its label,
    e.g. "detection threshold" → name → distance; the first dashed black, the next solid purple) as a
    tick across the bar (at ± for the faults in `signed`), `labels` under the bars and `note` (the
    eccentricity's direction, which is not a distance) as text."""
    from matplotlib.patches import Patch

    fig = _figure((9, 4.8))
    ax = fig.subplots()
    names = list(distance)
    x = np.arange(len(names))
    y = np.array([distance[n] for n in names])
    colours = {"present": "C3", "cannot tell": "C1", "absent": "0.65"}
    shown = {(verdicts or {}).get(n) for n in names}
    ax.bar(x, y, 0.6, color=[colours.get((verdicts or {}).get(n, ""), "C0") for n in names])
    handles = [Patch(color=c, label=v) for v, c in colours.items() if v in shown]
    if intervals:
        lo, hi = (np.array([intervals[n][j] for n in names]) for j in (0, 1))
        handles.append(ax.errorbar(x, y, yerr=np.vstack([np.clip(y - lo, 0, None), np.clip(hi - y, 0, None)]),
                                   fmt="none", ecolor="0.2", elinewidth=0.8, capsize=2, label="90 % interval"))  # fmt: skip
    if truth is not None:
        handles += ax.plot(x, [truth[n] for n in names], "kD", ms=4, label="true")
    for (label, limits), style in zip((thresholds or {}).items(), (("k", "--"), ("C4", "-")), strict=False):
        at = [(j, s * limits[n]) for j, n in enumerate(names) if limits and n in limits for s in (1, -1)
              if s > 0 or n in signed]  # fmt: skip
        if at:
            j, v = np.array(at).T
            handles.append(ax.hlines(v, j - 0.4, j + 0.4, colors=style[0], linestyles=style[1], lw=1.6,
                                     zorder=3, label=label))  # fmt: skip
    ax.axhline(0.0, color="k", lw=0.6)
    ax.set_xticks(x, [(labels or {}).get(n, n) for n in names], fontsize=7)
    ax.set_xlabel(note, fontsize=8)
    ax.set_ylabel("distance from healthy [fault units]")
    ax.legend(handles=handles, fontsize=7, ncols=3, loc="upper right")
    ax.grid(alpha=0.3, axis="y")
    if title:
        ax.set_title(title, fontsize=10)
    fig.savefig(path, dpi=110)
    return path


def plot_vectors(
    truth: np.ndarray | None,
    estimates: Mapping[str, np.ndarray],
    names: tuple[str, ...],
    path: Path,
    intervals: Mapping[str, tuple[np.ndarray, np.ndarray]] | None = None,
    phase_undefined: Collection[str] = (),
) -> Path:
    """Identified vs true fault vector (None: unknown, not drawn), one group of bars per fault.

    `intervals` (label → (ci90_low, ci90_high)) draws each estimate's 90 % interval as an error
    bar (k7 only when its arc does not wrap through 0). The k7 bar of each label in
    `phase_undefined` is greyed out: its eccentricity is too small for its direction to mean anything.
    """
    fig = _figure((9, 4))
    ax = fig.subplots()
    first = 0 if truth is None else 1
    n = len(estimates) + first
    width = 0.8 / n
    x = np.arange(len(names))
    if truth is not None:
        ax.bar(x - 0.4 + width / 2, truth, width, color="k", label="true")
    for j, (label, k) in enumerate(estimates.items(), start=first):
        pos = x - 0.4 + width / 2 + j * width
        bars = ax.bar(pos, k, width, label=label)
        undefined = label in phase_undefined
        if undefined:
            bars[6].set_color("0.8")
        if intervals is not None and label in intervals:
            lo, hi = (np.asarray(v, dtype=float) for v in intervals[label])
            ok = np.ones(len(k), dtype=bool)
            ok[6] = (not undefined) and lo[6] <= k[6] <= hi[6]
            err = np.vstack([np.clip(k - lo, 0, None), np.clip(hi - k, 0, None)])
            ax.errorbar(pos[ok], np.asarray(k)[ok], yerr=err[:, ok], fmt="none", ecolor="0.2", elinewidth=0.8,
                        capsize=1.5)  # fmt: skip
    if phase_undefined:
        ax.annotate("direction\nundefined", (x[6], 0.02), ha="center", fontsize=7, color="0.4")
    ax.set_xticks(x, [f"k{i + 1}\n{nm}" for i, nm in enumerate(names)], fontsize=7)
    ax.set_ylabel("fault value [-]" + ("; whiskers: 90 % intervals" if intervals else ""))
    ax.legend(fontsize=7, ncols=3)
    ax.grid(alpha=0.3, axis="y")
    fig.savefig(path, dpi=110)
    return path
