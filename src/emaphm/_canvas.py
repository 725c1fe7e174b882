"""A matplotlib figure drawn by an Agg canvas of its own, outside pyplot (`emaphm.plots`,
`emaphm.plots_rul`): the process's backend and pyplot's list of open figures are left alone."""

from __future__ import annotations

from typing import Any

__all__ = ["new_figure"]


def new_figure(figsize: tuple[float, float]) -> Any:
    """A new figure (constrained layout) drawn by an Agg canvas of its own, outside pyplot."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    fig = Figure(figsize=figsize, layout="constrained")
    FigureCanvasAgg(fig)
    return fig
