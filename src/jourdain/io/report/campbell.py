"""The Campbell diagram of a report: natural frequencies and stability over a rotor's speed.

Where a model has one *speed parameter* — a parameter that only prescribed joint motions use,
together with t (``Omega*t`` of a spinning disc or shaft), and nothing else — the linearization
about each time-invariant nominal motion is evaluated over that parameter from 0 to twice its
value (:func:`jourdain.analysis.sweep.sweep`): the damped natural frequencies |Im λ| against
the speed with the 1× line (their crossings are the critical speeds, each to 1e-10 by
Brent's method on the frequency branch), unstable points marked, and the stable speed range
(boundaries by :func:`jourdain.stability_boundary`). Numbers in ``campbell-<nominal>.csv``.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.optimize import brentq

from ...analysis.modes import UNSTABLE
from ...analysis.sweep import sweep
from ...errors import JourdainError
from ...model.validation import force_expressions
from .figures import plot_axes, svg
from .html import esc, note, numstr
from .rolling import _names, _stable_range
from .state import Run

#: speeds of the diagram
POINTS = 121


def speed_parameter(system: Any) -> str | None:
    """The one parameter used only by prescribed joint motions (with t), or None."""
    moving: set[str] = set()
    other: set[str] = set()
    for b in system.bodies:
        j = b.joint
        other |= _names([b.mass, *b.com, *(v for r in b.inertia for v in r), *j.position,
                         *(v for r in j.orientation for v in r)])
        for step in j.steps:
            exprs = [step.angle] if hasattr(step, "angle") else list(step.vector)
            names = _names(exprs)
            (moving if "t" in names else other).update(names)
    for f in system.forces:
        other |= _names(force_expressions(f))
    only = sorted((moving - other) & set(system.parameter_values))
    return only[0] if len(only) == 1 else None


def campbell_plot(values: np.ndarray, freqs: np.ndarray, unstable: np.ndarray, name: str,
                  critical: list[float], title: str) -> str:
    fig, ax = plot_axes(7.5, 3.8)
    for k in range(freqs.shape[1]):
        ax.plot(values, freqs[:, k], "-", color="C0", linewidth=1.0)
    xs, ys = np.nonzero(unstable)
    if len(xs):
        ax.plot(values[xs], freqs[xs, ys], "x", color="C3", markersize=4, label="unstable")
        ax.legend(loc="upper left", fontsize=8)
    ax.plot(values, values, "--", color="0.4", linewidth=0.9)
    for c in critical:
        ax.axvline(c, color="C2", linewidth=0.8, linestyle=":")
    top = float(np.nanmax(freqs)) if freqs.size else 1.0
    # the frequencies that matter for the speeds shown: up to 2.5× the top speed (the rest,
    # of stiff modes far above, would squeeze the crossings into the bottom of the plot)
    if values[-1] > 0:
        top = min(top, 2.5 * float(values[-1]))
    ax.set_ylim(0.0, 1.05 * max(top, 1e-12))
    ax.set_xlabel(f"{name} / (rad/s)")
    ax.set_ylabel("|Im λ| / (rad/s)")
    ax.set_title(title)
    return svg(fig)


def _oscillating(row: np.ndarray) -> np.ndarray:
    """The eigenvalues of one speed with Im λ > 0 (one per oscillating pair), by Im λ."""
    osc = row[row.imag > 1e-9 * max(1.0, float(np.abs(row).max()))]
    return osc[np.argsort(osc.imag)]


def _frequencies(lam: np.ndarray) -> np.ndarray:
    """|Im λ| of the oscillating eigenvalues (Im λ > 0), ascending, one row per speed; NaN
    where a speed has fewer."""
    rows = [_oscillating(row).imag for row in lam]
    n = max((len(r) for r in rows), default=0)
    out = np.full((len(rows), n), np.nan)
    for i, r in enumerate(rows):
        out[i, :len(r)] = r
    return out


def _critical(lin: Any, name: str, values: np.ndarray, freqs: np.ndarray,
              params: dict[str, float]) -> list[float]:
    """Speeds where a frequency branch (k-th ascending) crosses the 1× line."""
    out: list[float] = []

    def branch(v: float, k: int) -> float:
        f = _frequencies(sweep(lin, name, [v], parameters=params).eigenvalues)[0]
        return float(f[k] - v) if k < len(f) else float("nan")

    for k in range(freqs.shape[1]):
        d = freqs[:, k] - values
        for i in np.nonzero(np.sign(d[:-1]) * np.sign(d[1:]) < 0)[0]:
            try:
                out.append(float(brentq(branch, values[i], values[i + 1], args=(k,),
                                        xtol=1e-12, rtol=1e-10)))
            except ValueError:  # the branch's order changed within the bracket
                continue
    merged: list[float] = []
    for c in sorted(out):  # two branches through one point (a double root): one speed
        if not merged or c - merged[-1] > 1e-9 * max(1.0, abs(c)):
            merged.append(c)
    return merged


def campbell_section(run: Run, nominal: str, lin: Any) -> str:
    """The Campbell diagram about ``nominal`` (``lin`` its symbolic linearization), or ""."""
    system = run.model.system
    name = speed_parameter(system)
    if name is None:
        return ""
    value = float(run.params.get(name, system.parameter_values[name]))
    top = 2.0 * abs(value) or 1.0
    values = np.linspace(0.0, top, POINTS)
    params = {k: float(v) for k, v in run.params.items() if k != name}
    try:
        sw = sweep(lin, name, values, parameters=params)
        freqs = _frequencies(sw.eigenvalues)
        critical = _critical(lin, name, values, freqs, params)
        bounds = _stable_range(lin, name, values, sw.verdicts, params)
    except JourdainError as exc:
        run.info.notes.append(f"Campbell diagram about {nominal}: {exc}")
        return note(f"the Campbell diagram over {name} is not available: {exc}")
    unstable = np.zeros_like(freqs, dtype=bool)
    for i, row in enumerate(sw.eigenvalues):
        osc = _oscillating(row)
        unstable[i, :len(osc)] = osc.real > 0
    fn = run.out / f"campbell-{nominal}.csv"
    n = freqs.shape[1]
    np.savetxt(fn, np.column_stack([values, freqs, sw.max_real_part]), delimiter=",",
               header=",".join([name, *(f"omega_d{k + 1}" for k in range(n)), "max_re"]),
               comments="")
    run.info.files.append(fn)
    fig = run.figures.add(campbell_plot, values, freqs, unstable, name, critical,
                          f"Campbell diagram about {nominal}")
    stable = [(a, b) for a, b in zip([0.0, *bounds], [*bounds, top], strict=True)
              if sw.verdicts[int(np.searchsorted(values, 0.5 * (a + b)))] != UNSTABLE]
    text = "; ".join(f"{a:.6g} – {b:.6g}" for a, b in stable) if stable else "none"
    crit = ", ".join(f"{c:.8g}" for c in critical) or "none in the range"
    run.info.summary_lines.append(f"  critical {name} about {nominal}: {crit}; "
                                  f"stable {name}: {text}")
    return (f"<h4>Campbell diagram over {esc(name)} (0 … {numstr(top)} rad/s)</h4>" + fig
            + f"<p>Critical speeds (a natural frequency equal to {esc(name)}): <b>{esc(crit)}"
            f"</b>. Stable for {esc(name)} in: <b>{esc(text)}</b>"
            + (f" (boundaries {', '.join(f'{b:.10g}' for b in bounds)} by "
               "jourdain.stability_boundary)" if bounds else "") + ".</p>")
