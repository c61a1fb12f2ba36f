"""Plots of a study's dataset: stability map, Campbell diagram, histograms of Monte-Carlo
outputs (Matplotlib figures; :func:`study_plots` writes them as SVG and PNG; the pages and the
report's section that show them: :mod:`jourdain.study.report`)."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from ..io.interrupted import deferred_ctrl_c
from .spec import StudyError

__all__ = ["campbell_diagram", "histograms", "stability_map", "study_plots"]


def _label(ds: Any, name: str) -> str:
    from ..units import axis_label

    return axis_label(name, ds[name].attrs.get("units", ""))


def _grid_axes(ds: Any) -> list[str]:
    return [d for d in ds["max_real_part"].dims] if "max_real_part" in ds else []


def stability_map(ds: Any, ax: Any = None) -> Any:
    """The largest real part of the eigenvalues over the first two axes of a grid study
    (other axes at their first value), with the stability boundary (max Re λ = 0) drawn and
    the unstable region hatched. Returns the figure."""
    import matplotlib.pyplot as plt

    axes = _grid_axes(ds)
    if len(axes) < 2 or "case" in axes:
        raise StudyError("a stability map needs a grid study of two or more axes with "
                         "[compute.linearize]")
    a1, a2 = axes[0], axes[1]
    sel = {d: 0 for d in axes[2:]}
    z = ds["max_real_part"].isel(sel).transpose(a2, a1).values
    x, y = ds[a1].values, ds[a2].values
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
    else:
        fig = ax.figure
    lim = float(np.nanmax(np.abs(z))) if np.isfinite(z).any() else 1.0
    lim = lim or 1.0
    mesh = ax.pcolormesh(x, y, z, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="auto")
    fig.colorbar(mesh, ax=ax, label="max Re λ / (1/s)")
    if np.nanmin(z) < 0 < np.nanmax(z):
        ax.contour(x, y, z, levels=[0.0], colors="k", linewidths=1.5)
        ax.contourf(x, y, z, levels=[0.0, np.inf], colors="none", hatches=["//"])
    ax.set_xlabel(_label(ds, a1))
    ax.set_ylabel(_label(ds, a2))
    extra = ", ".join(f"{d} = {ds[d].values[0]:g}" for d in axes[2:])
    ax.set_title(f"stability map: {ds.attrs.get('model', '')} (hatched: unstable)"
                 + (f"\n{extra}" if extra else ""))
    return fig


def campbell_diagram(ds: Any, axis: str | None = None, ax: Any = None) -> Any:
    """Damped natural frequencies |Im λ| over one grid axis (the first by default; other axes
    at their first value), unstable points marked; the line |Im λ| = value when that axis is a
    speed in rad/s (the 1× excitation). Returns the figure."""
    import matplotlib.pyplot as plt

    if "eigenvalue_imag" not in ds:
        raise StudyError("a Campbell diagram needs a grid study with [compute.linearize]")
    axes = [d for d in ds["eigenvalue_imag"].dims if d != "mode"]
    if "case" in axes:
        raise StudyError("a Campbell diagram needs a grid study (its first axis the speed)")
    axis = axis or axes[0]
    sel = {d: 0 for d in axes if d != axis}
    im = np.abs(ds["eigenvalue_imag"].isel(sel).transpose(axis, "mode").values)
    re = ds["eigenvalue_real"].isel(sel).transpose(axis, "mode").values
    x = ds[axis].values
    if ax is None:
        fig, ax = plt.subplots(figsize=(6.4, 4.8))
    else:
        fig = ax.figure
    for k in range(im.shape[1]):
        ax.plot(x, im[:, k], "-", color="C0", lw=1)
    uns = re > 0
    ax.plot(np.broadcast_to(x[:, None], im.shape)[uns], im[uns], "o", ms=3, color="C3",
            label="Re λ > 0")
    if ds[axis].attrs.get("units") in ("rad/s", "1/s"):
        ax.plot(x, np.abs(x), "--", color="0.4", label=f"1× {axis}")
    ax.set_xlabel(_label(ds, axis))
    ax.set_ylabel("|Im λ| / (1/s)")
    extra = ", ".join(f"{d} = {ds[d].values[0]:g}" for d in sel)
    ax.set_title("Campbell diagram" + (f" ({extra})" if extra else ""))
    ax.legend(loc="best")
    return fig


def histograms(ds: Any) -> list[tuple[str, Any]]:
    """A histogram of every scalar output over the cases (largest values, critical values,
    largest real part), failed cases left out: ``[(name, figure), ...]``."""
    import matplotlib.pyplot as plt

    out = []
    for name in ds.data_vars:
        v = ds[name]
        if v.dtype.kind != "f" or name.startswith(("evaluate_", "eigenvalue_")):
            continue
        if v.ndim != len(ds["error"].dims):
            continue
        vals = v.values.reshape(-1)
        vals = vals[np.isfinite(vals)]
        if not vals.size:
            continue
        fig, ax = plt.subplots(figsize=(6.4, 4.0))
        ax.hist(vals, bins=max(10, min(60, int(np.sqrt(vals.size)))), color="C0")
        ax.set_xlabel(_label(ds, name))
        ax.set_ylabel("cases")
        ax.set_title(f"{v.attrs.get('long_name', name)}: {vals.size} cases, mean "
                     f"{vals.mean():.4g}, std {vals.std(ddof=1) if vals.size > 1 else 0:.3g}")
        out.append((name, fig))
    return out


def study_plots(ds: Any, folder: str | Path, prefix: str = "") -> list[Path]:
    """Write the plots that suit the study (stability map for grids of 2+ axes, Campbell
    diagram for grids with eigenvalues, histograms for list and random designs) to ``folder``
    as ``<prefix><name>.svg`` and ``.png``; returns the paths."""
    with deferred_ctrl_c():  # Ctrl-C after Matplotlib's C extensions are initialized
        import matplotlib

        matplotlib.use("Agg", force=False)
        import matplotlib.pyplot as plt

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    figs: list[tuple[str, Any]] = []
    grid = ds.attrs.get("design") == "grid" and "case" not in ds.dims
    if grid and "max_real_part" in ds and ds["max_real_part"].ndim >= 2:
        figs.append(("stability_map", stability_map(ds)))
    if grid and "eigenvalue_imag" in ds:
        figs.append(("campbell", campbell_diagram(ds)))
    if not grid:
        figs.extend((f"histogram_{n}", fig) for n, fig in histograms(ds))
    paths = []
    for name, fig in figs:
        for ext in ("svg", "png"):
            p = folder / f"{prefix}{name}.{ext}"
            fig.savefig(p, dpi=110 if ext == "png" else None, bbox_inches="tight")
            paths.append(p)
        plt.close(fig)
    return paths
