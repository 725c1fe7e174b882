"""Figures (matplotlib, Agg backend): the HF response and the LF calibration, like the paper's Fig. 4."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np

from .identification.signals import lowpass
from .results import SimResult

__all__ = ["plot_calibration", "plot_response"]


def _pyplot():  # type: ignore[no-untyped-def]
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def plot_response(runs: Mapping[str, SimResult], path: Path, title: str) -> Path:
    """Command and user position, phase currents (of the last run), i_q of every run (Fig. 4a)."""
    plt = _pyplot()
    fig, ax = plt.subplots(3, 1, figsize=(9, 8), sharex=True, layout="constrained")
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
    plt.close(fig)
    return path


def plot_calibration(
    cases: Mapping[str, tuple[SimResult, SimResult, SimResult]], path: Path, f_s: float = 1e4
) -> Path:
    """HF i_q vs LF current before and after calibration (filtered), one row per case (Fig. 4b)."""
    plt = _pyplot()
    fig, ax = plt.subplots(len(cases), 1, figsize=(9, 3.2 * len(cases)), sharex=True, layout="constrained")
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
    plt.close(fig)
    return path
