"""Figures drawn off screen: the one place where oceanmc sets up matplotlib and draws the pieces
its figures share. Used by `oceanmc plot` (results.py), the validation report's cases and the
benchmark report."""
from __future__ import annotations

from pathlib import Path

import numpy as np

DPI = 110


def pyplot():
    """matplotlib.pyplot on the Agg backend: PNG files, no screen needed."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def panels(n: int, ncols: int, panel_size: tuple[float, float], **subplot_kw):
    """A figure with n panels on a grid of at most ncols columns, each panel_size (inches);
    subplot_kw as for matplotlib (e.g. projection="polar"). Returns (figure, list of n axes);
    the grid's unused cells are removed. The layout is matplotlib's constrained one, so that the
    PNG has the figure's size (panel_size times the grid, at DPI) and nothing overlaps."""
    plt = pyplot()
    ncols = min(ncols, n)
    nrows = -(-n // ncols)
    fig, axes = plt.subplots(nrows, ncols, figsize=(panel_size[0] * ncols, panel_size[1] * nrows),
                             squeeze=False, subplot_kw=subplot_kw or None, layout="constrained")
    for ax in axes.flat[n:]:
        fig.delaxes(ax)
    return fig, list(axes.flat[:n])


def save(fig, path: str | Path, crop: bool = False) -> Path:
    """Writes the figure as PNG and frees it; crop: to the drawn area (the PNG's size then
    depends on the contents), else at the figure's size."""
    path = Path(path)
    fig.savefig(path, dpi=DPI, bbox_inches="tight" if crop else None)
    close(fig)
    return path


def close(fig) -> None:
    pyplot().close(fig)


def log_norm(values: np.ndarray, dynamic_range: float = 1e3):
    """A logarithmic colour scale over the positive, finite values, spanning at most
    dynamic_range below the largest (so that one bright quad, e.g. the sun's, does not wash out
    the rest); None where no value is positive."""
    from matplotlib.colors import LogNorm
    values = np.asarray(values, dtype=np.float64)
    positive = values[np.isfinite(values) & (values > 0)]
    if positive.size == 0:
        return None
    top = float(positive.max())
    return LogNorm(vmin=max(float(positive.min()), top / dynamic_range), vmax=top)


def polar_quads(ax, theta_edges_deg, phi_edges_deg, values, norm, cmap: str = "viridis"):
    """Quad values (rows: polar-angle bands, columns: azimuth bands) as annular sectors of a
    polar axes: azimuth phi, radius the polar angle (deg) of theta_edges_deg. Non-positive
    values are left blank on a logarithmic scale."""
    values = np.where(np.asarray(values) > 0, values, np.nan)
    return ax.pcolormesh(np.radians(np.asarray(phi_edges_deg)), np.asarray(theta_edges_deg),
                         values, norm=norm, cmap=cmap, shading="flat")


def fit_title(text: str, width_in: float, fontsize: float, max_lines: int = 3) -> str:
    """The text wrapped to lines that fit width_in inches at fontsize points (a character of
    DejaVu Sans is at most about 0.6 em wide on average), at most max_lines of them, the last
    shortened with '...' if the text is longer: a long scene name in a title stays inside the
    figure."""
    import textwrap
    chars = max(10, int(width_in * 72.0 / (0.6 * fontsize)))
    lines = []
    for paragraph in text.split("\n"):
        lines += textwrap.wrap(paragraph, chars, break_long_words=True) or [""]
    if len(lines) > max_lines:
        lines = lines[:max_lines]
        cut = lines[-1][:chars - 4]
        lines[-1] = (cut.rsplit(" ", 1)[0] if " " in cut else cut).rstrip() + " ..."
    return "\n".join(lines)


def half_polar(ax, title: str) -> None:
    """A polar axes as the upper half-plane of a plane of incidence: angle 0 up (the normal),
    positive clockwise, -90 to 90 deg."""
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    ax.set_thetamin(-90)
    ax.set_thetamax(90)
    ax.tick_params(labelsize=7)
    ax.set_title(title, fontsize=9)
