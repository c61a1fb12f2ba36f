"""The report's figures: Matplotlib plots rendered to inline SVG (without pyplot), drawn in
this process or, for ``jourdain run``, in a worker process forked for them (:class:`Figures`),
while this one goes on with the numbers."""

from __future__ import annotations

import io
import signal
from collections.abc import Callable, Mapping
from concurrent.futures import Future, ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from typing import Any

import numpy as np

from .motion import Motion, closing_segments, frame_geometry, segments


def new_figure(**kw: Any) -> Any:
    """A Matplotlib figure drawn by the SVG backend, without pyplot: no GUI backend is looked
    for and nothing is registered with pyplot's figure manager (half the import time)."""
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure

    fig = Figure(**kw)
    FigureCanvasSVG(fig)
    return fig


#: margins of the report's plots in inches (left, bottom, right, top): room for tick labels of
#: at most 6 characters (see :func:`plot_axes`), the axis labels and a title
PLOT_MARGINS = (0.85, 0.5, 0.15, 0.32)


def plot_axes(width: float, height: float) -> tuple[Any, Any]:
    """A figure of ``width`` × ``height`` inches with one axes in fixed margins
    (:data:`PLOT_MARGINS`). Constrained layout fitted the margins to the labels but laid all
    text out twice: 45 of the 85 ms of a plot. Tick labels are kept short instead: scientific
    notation with an offset outside 1e-3 … 1e4."""
    fig = new_figure(figsize=(width, height))
    left, bottom, right, top = PLOT_MARGINS
    fig.subplots_adjust(left=left / width, bottom=bottom / height, right=1 - right / width,
                        top=1 - top / height)
    ax = fig.add_subplot()
    ax.ticklabel_format(style="sci", scilimits=(-3, 4), useOffset=True)
    return fig, ax


def svg(fig: Any) -> str:
    """The figure as an SVG element, the same bytes for the same figure: element ids from a
    fixed salt (Matplotlib's default is random) and no date in the metadata."""
    import matplotlib

    buf = io.StringIO()
    # text as SVG text, not glyph outlines: the browser sets it, in a third of the time and
    # with smaller files
    with matplotlib.rc_context({"svg.fonttype": "none", "svg.hashsalt": "jourdain"}):
        fig.savefig(buf, format="svg", metadata={"Date": None})
    text = buf.getvalue()
    return text[text.index("<svg"):]


def time_plot(t: np.ndarray, series: Mapping[str, np.ndarray], ylabel: str,
               title: str) -> str:
    fig, ax = plot_axes(7.5, 3.0)
    for name, v in series.items():
        ax.plot(t, v, label=name, linewidth=1.2)
    ax.set_xlabel("t / s")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if 1 < len(series) <= 12:
        ax.legend(fontsize=8, loc="best", ncol=2 if len(series) > 4 else 1)
    return svg(fig)


def eigen_plot(eigenvalues: np.ndarray, title: str) -> str:
    fig, ax = plot_axes(4.5, 3.2)
    ax.axvline(0, color="0.5", linewidth=0.8)
    ax.axhline(0, color="0.5", linewidth=0.8)
    ax.plot(eigenvalues.real, eigenvalues.imag, "x", markersize=8, color="C3")
    ax.set_xlabel("Re λ / (1/s)")
    ax.set_ylabel("Im λ / (rad/s)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    return svg(fig)


def multiplier_plot(multipliers: np.ndarray, title: str) -> str:
    """Floquet multipliers in the complex plane against the unit circle (stable inside)."""
    fig, ax = plot_axes(4.0, 3.6)
    phi = np.linspace(0.0, 2 * np.pi, 361)
    ax.plot(np.cos(phi), np.sin(phi), color="0.4", linewidth=1.0, label="|μ| = 1")
    ax.axvline(0, color="0.7", linewidth=0.6)
    ax.axhline(0, color="0.7", linewidth=0.6)
    ax.plot(multipliers.real, multipliers.imag, "x", markersize=9, color="C3", label="μ")
    r = max(1.2, 1.1 * float(np.abs(multipliers).max(initial=0.0)))
    ax.set_xlim(-r, r)
    ax.set_ylim(-r, r)
    ax.set_aspect("equal")
    ax.set_xlabel("Re μ")
    ax.set_ylabel("Im μ")
    ax.set_title(title, fontsize=10)
    ax.legend(loc="upper right", fontsize=8)
    ax.grid(True, alpha=0.3)
    return svg(fig)


def snapshot_strip(m: Motion, view: str | None, frames: int = 8) -> str:
    from matplotlib.collections import LineCollection

    proj, lo, hi = frame_geometry(m, view)
    idx = np.linspace(0, len(m.t) - 1, frames).round().astype(int)
    # no ticks, so fixed margins (constrained layout of 8 axes costs more than their drawing)
    fig = new_figure(figsize=(1.6 * frames, 2.0))
    axs = fig.subplots(1, frames)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.02, top=0.86, wspace=0.08)
    mmax = max(max(m.mass.values(), default=1.0), 1e-12)
    sizes = np.array([12 + 40 * m.mass[name] / mmax for name in m.com])
    for ax, k in zip(np.atleast_1d(axs), idx, strict=True):
        segs = [(proj(a), proj(b)) for a, b in segments(m, int(k))]
        if segs:  # one collection per frame: a Line2D per segment cost 40 ms a frame
            ax.add_collection(LineCollection(segs, colors="0.25", linewidths=1.5))
        closing = [(proj(a), proj(b)) for a, b in closing_segments(m, int(k))]
        if closing:  # a closed system's closing joints, in red
            ax.add_collection(LineCollection(closing, colors="#d62728", linewidths=1.5))
        pc = np.array([proj(c[k]) for c in m.com.values()]).reshape(-1, 2)
        ax.scatter(pc[:, 0], pc[:, 1], s=sizes, color="C0", zorder=3)
        p0 = proj(np.zeros(3))
        ax.plot(p0[0], p0[1], "^", color="k", markersize=5)
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_aspect("equal")
        ax.set_xticks([])
        ax.set_yticks([])
        ax.set_title(f"t = {m.t[k]:.2f} s", fontsize=8)
    return svg(fig)



# ------------------------------------------------------------------------------------------
# drawing here or in a worker
# ------------------------------------------------------------------------------------------

def prepare_worker() -> None:
    """A figure worker: Ctrl-C is the parent's to handle (it waits for the figures of the
    sections it finished), and Matplotlib is imported once, while the parent computes."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    import matplotlib.backends.backend_svg  # noqa: F401
    import matplotlib.collections  # noqa: F401
    import matplotlib.figure  # noqa: F401


class Figures:
    """The figures of one report. :meth:`add` returns a placeholder for the page; the figure
    is drawn at once in this process, or, given a worker ``pool``, there while this process
    goes on; :meth:`fill` puts the SVGs in place of their placeholders."""

    def __init__(self, pool: ProcessPoolExecutor | None = None) -> None:
        self.pool = pool
        self.items: list[tuple[str | Future[str], Callable[..., str], tuple[Any, ...]]] = []

    def add(self, draw: Callable[..., str], *args: Any) -> str:
        """A placeholder for ``draw(*args)`` (a module-level function of this module, so that
        a worker can be sent it)."""
        key = f"<!--jourdain-figure-{len(self.items)}-->"
        item: str | Future[str]
        try:
            item = self.pool.submit(draw, *args) if self.pool is not None else draw(*args)
        except BrokenProcessPool:  # the worker's process was lost: drawn here
            item = draw(*args)
        self.items.append((item, draw, args))
        return key

    def abandon(self) -> None:
        """Stop waiting for the worker (Ctrl-C): the figures it has not delivered yet are
        left out of the page with a note."""
        for k, (item, draw, args) in enumerate(self.items):
            if not isinstance(item, str) and not item.done():
                item.cancel()
                self.items[k] = ("<p class='note'>figure not drawn (interrupted)</p>", draw,
                                 args)

    def fill(self, page: str) -> str:
        """``page`` with every placeholder replaced by its figure (waiting for the worker; a
        figure that the worker could not deliver, its process lost, is drawn here)."""
        for k, (item, draw, args) in enumerate(self.items):
            if isinstance(item, str):
                text = item
            else:
                try:
                    text = item.result()
                except BrokenProcessPool:
                    text = draw(*args)
            page = page.replace(f"<!--jourdain-figure-{k}-->", text, 1)
        return page
