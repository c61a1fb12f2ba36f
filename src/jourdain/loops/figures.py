"""The figures of a loop model's report (:func:`jourdain.loops.report.run_report`), drawn by
Matplotlib in a worker process forked when the report starts (:class:`Painter`): the worker
imports Matplotlib (about a second on a loaded machine) while the command simulates and
linearizes; in this process where a second core or ``fork`` is missing."""

from __future__ import annotations

from concurrent.futures import Future, ProcessPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from ..io.workers import fork_workers


def _import_matplotlib() -> None:
    import matplotlib  # noqa: PLC0415 (heavy, optional: the report's figures only)

    matplotlib.use("Agg")
    import matplotlib.pyplot  # noqa: F401, PLC0415


#: the report's figures in the order the page shows them
FIGURES = ("coordinates.png", "constraint_residual.png", "reactions.png",
           "closing_joint_wrenches.png", "energy.png")


def draw_figures(out: Path, d: dict[str, Any]) -> list[str]:
    """Write PNG figures into ``out`` from the arrays ``d``; their file names. ``d`` holds
    ``t`` and the motion (``z``, ``names``, ``Phi``, ``Phi_dot``, ``lam``, ``labels``,
    ``E``: the coordinates, residuals, reactions and energy), or the closing joints'
    ``wrenches``, or both: what it holds is drawn."""
    _import_matplotlib()
    import matplotlib.pyplot as plt  # noqa: PLC0415

    t = d["t"]
    figs = []

    def lines(fname: str, ylabel: str, series: list[tuple[str, np.ndarray]],
              log: bool = False) -> None:
        """One figure of labelled curves over t."""
        fig, ax = plt.subplots(figsize=(7, 3.5))
        for label, v in series:
            if log:  # an exact zero has no logarithm: a gap in the curve, not a 1e-300 floor
                v = np.where(v > 0.0, v, np.nan)
                if np.all(np.isnan(v)):
                    label += ": exactly 0 throughout"
            (ax.semilogy if log else ax.plot)(t, v, label=label)
        ax.set_xlabel("t / s")
        ax.set_ylabel(ylabel)
        ax.legend()
        figs.append((fname, fig))

    if "z" in d:
        lines("coordinates.png", "tree coordinates",
              [(n, d["z"][:, i]) for i, n in enumerate(d["names"])])
        lines("constraint_residual.png", "constraint residual",
              [("max |Φ|", np.max(np.abs(d["Phi"]), axis=1)),
               ("max |Φ̇|", np.max(np.abs(d["Phi_dot"]), axis=1))], log=True)
        lines("reactions.png", "closing-joint reactions λ",
              [(r, d["lam"][:, i]) for i, r in enumerate(d["labels"])])
        fig, ax = plt.subplots(figsize=(7, 3.5))
        E = d["E"]
        ax.plot(t, E - E[0])
        ax.set_xlabel("t / s")
        ax.set_ylabel("E − E₀ / J")
        figs.append(("energy.png", fig))
    if d.get("wrenches"):  # force and torque of each closing joint in its body A's axes
        fig, axs = plt.subplots(1, 2, figsize=(9, 3.5))
        for name, w in d["wrenches"].items():
            for j, c in enumerate("xyz"):
                if np.any(w["F"][:, j]):
                    axs[0].plot(t, w["F"][:, j], label=f"{name} F{c}")
                if np.any(w["T"][:, j]):
                    axs[1].plot(t, w["T"][:, j], label=f"{name} T{c}")
        for a, what in zip(axs, ("force / N", "torque / N m"), strict=True):
            a.set_xlabel("t / s")
            a.set_ylabel(f"closing joint {what}")
            if a.get_legend_handles_labels()[0]:
                a.legend()
        figs.append(("closing_joint_wrenches.png", fig))
    for fname, fg in figs:
        fg.subplots_adjust(left=0.12, right=0.97, bottom=0.14, top=0.95, wspace=0.3)
        fg.savefig(out / fname, dpi=90)
        plt.close(fg)
    return [f for f, _ in figs]


class Painter:
    """A one-process pool forked at construction (Matplotlib imported there at once), or
    nothing where that cannot help; :meth:`draw` draws there or here."""

    def __init__(self, pool: ProcessPoolExecutor | None = None) -> None:
        """``pool``: a worker forked earlier (``jourdain run`` forks it before it reads the
        model, so that Matplotlib is imported meanwhile), used instead of a new one."""
        # else forked now, Matplotlib imported there at once; none on one core or without fork
        self.pool: ProcessPoolExecutor | None = (
            pool if pool is not None else fork_workers(_import_matplotlib))

    def draw(self, out: Path, d: dict[str, Any]) -> Future[list[str]]:
        """:func:`draw_figures` started in the worker (done here where there is none)."""
        if self.pool is None:
            done: Future[list[str]] = Future()
            done.set_result(draw_figures(out, d))
            return done
        return self.pool.submit(draw_figures, out, d)

    def close(self) -> None:
        """Let the worker go (after its last drawing)."""
        if self.pool is not None:
            self.pool.shutdown()
            self.pool = None


__all__ = ["FIGURES", "Painter", "draw_figures"]
