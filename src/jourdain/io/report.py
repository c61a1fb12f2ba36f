"""The report of ``jourdain run``: one self-contained HTML file plus the data files.

Equations are MathML (browsers render it natively, no script, no network), matrices at the
initial state are tables, plots are inline SVG, the motion is a strip of snapshots and an SVG
animation (SMIL). Every part that a stage cannot deliver (a capability missing, a singular
position, ...) becomes a note in the report instead of stopping the others.
"""

from __future__ import annotations

import datetime as _dt
import html
import io
import json
import shutil
import time
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from ..errors import JourdainError
from ..symbolic import to_sympy
from ..units import (
    axis_label,
    force_unit,
    model_units,
    reactions_label,
    shared_label,
    torque_unit,
    value_units,
)
from . import export
from .modelfile import ModelFile

#: Matrices with more rows than this are summarized in the equations section.
MAX_DISPLAY_ROWS = 12


@dataclass
class ReportInfo:
    """What :func:`write_report` wrote: the HTML file, all files, and a short summary;
    ``status`` "complete", "interrupted" (Ctrl-C: what was computed is written) or "failed"
    (the simulation failed: the motion up to the failure is written), ``message`` why."""

    html: Path
    files: list[Path] = field(default_factory=list)
    summary_lines: list[str] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)
    status: str = "complete"
    message: str = ""


#: the format tag of run.json, the manifest of a report folder
RUN_FORMAT = "jourdain-run/1"


def model_copy(model: ModelFile) -> str:
    """The name of the report's copy of the model: ``model.urdf`` for a URDF robot, else
    ``model.toml``."""
    return "model.urdf" if str(model.path).lower().endswith(".urdf") else "model.toml"


def report_files(model: ModelFile) -> list[str]:
    """The names of the files :func:`write_report` writes for ``model`` (the command line
    refuses to overwrite them without ``--force``)."""
    return ["report.html", "run.json", model_copy(model), "equations.tex", "equations.json",
            "values.json", *(f"linearization-{n.name}.json" for n in model.nominal),
            "simulation.csv", *(f"wrench-{b.joint.name}.csv" for b in model.system.bodies)]


# ------------------------------------------------------------------------------------------
# small HTML helpers
# ------------------------------------------------------------------------------------------

def _e(s: object) -> str:
    return html.escape(str(s), quote=True)


def _num(x: float) -> str:
    if not np.isfinite(x):
        return "—"
    if x == 0:
        return "0"
    a = abs(x)
    return f"{x:.5g}" if 1e-3 <= a < 1e5 else f"{x:.4e}"


def _table(rows: Sequence[Sequence[object]], header: Sequence[str] | None = None,
           cls: str = "") -> str:
    out = [f'<table class="{cls}">' if cls else "<table>"]
    if header:
        out.append("<tr>" + "".join(f"<th>{h}</th>" for h in header) + "</tr>")
    for r in rows:
        out.append("<tr>" + "".join(f"<td>{c}</td>" for c in r) + "</tr>")
    out.append("</table>")
    return "".join(out)


def _snap(a: np.ndarray, rel: float = 1e-12) -> np.ndarray:
    """Round-off (relative to the largest entry) shown as 0."""
    a = np.array(a, dtype=complex if np.iscomplexobj(a) else float)
    finite = np.isfinite(a)
    scale = float(np.abs(a[finite]).max(initial=0.0))
    if np.iscomplexobj(a):
        a.real[np.abs(a.real) <= rel * scale] = 0.0
        a.imag[np.abs(a.imag) <= rel * scale] = 0.0
    else:
        a[finite & (np.abs(a) <= rel * scale)] = 0.0
    return a


def _matrix_table(a: np.ndarray, rows: Sequence[str] | None = None,
                  cols: Sequence[str] | None = None) -> str:
    a = _snap(np.atleast_2d(np.asarray(a, float)))
    if a.shape[0] == 1 and rows is not None and len(rows) > 1:
        a = a.T
    body = []
    for i in range(a.shape[0]):
        label = f"<th>{_e(rows[i])}</th>" if rows is not None and i < len(rows) else ""
        body.append("<tr>" + label + "".join(f"<td>{_num(v)}</td>" for v in a[i]) + "</tr>")
    head = ""
    if cols is not None:
        head = "<tr>" + ("<th></th>" if rows is not None else "") + "".join(
            f"<th>{_e(c)}</th>" for c in cols) + "</tr>"
    return f'<table class="matrix">{head}{"".join(body)}</table>'


def _math(inner: str, block: bool = True) -> str:
    disp = ' display="block"' if block else ""
    return f'<math xmlns="http://www.w3.org/1998/Math/MathML"{disp}>{inner}</math>'


_SYM = {
    "M_bar": export.symbol_mathml("M", bar=True), "J_bar": export.symbol_mathml("J", bar=True),
    "q_c": export.symbol_mathml("q", bar=True, sup="c"),
    "q_e": export.symbol_mathml("q", bar=True, sup="e"),
    "Q_bar": export.symbol_mathml("Q", bar=True), "M": "<mi>M</mi>", "k": "<mi>k</mi>",
    "q": "<mi>q</mi>", "g": "<mi>g</mi>", "N_hat": export.symbol_mathml("N", hat=True),
    "k_hat": export.symbol_mathml("k", hat=True), "q_hat": export.symbol_mathml("q", hat=True),
    "M_tilde": export.symbol_mathml("M", tilde=True), "P": "<mi>P</mi>", "Q": "<mi>Q</mi>",
    "h": "<mi>h</mi>", "D": "<mi>D</mi>", "G": "<mi>G</mi>", "K": "<mi>K</mi>",
    "N": "<mi>N</mi>", "B": "<mi>B</mi>",
}
_DOT_Y = '<mover accent="true"><mi>y</mi><mo>˙</mo></mover>'
_DDOT_Y = '<mover accent="true"><mi>y</mi><mo>¨</mo></mover>'
_ETA = "<mi>η</mi>"
_DETA = '<mover accent="true"><mi>η</mi><mo>˙</mo></mover>'
_DDETA = '<mover accent="true"><mi>η</mi><mo>¨</mo></mover>'


def _headline_ne() -> str:
    return _math(f"<mrow>{_SYM['M_bar']}<mo>⋅</mo>{_SYM['J_bar']}<mo>⋅</mo>{_DDOT_Y}<mo>+</mo>"
                 f"{_SYM['q_c']}<mo>=</mo>{_SYM['q_e']}<mo>+</mo>{_SYM['Q_bar']}<mo>⋅</mo>"
                 f"<mi>g</mi></mrow>")


def _headline_eom() -> str:
    return _math(f"<mrow><mi>M</mi><mo>⋅</mo>{_DDOT_Y}<mo>+</mo><mi>k</mi><mo>=</mo><mi>q</mi>"
                 f"<mo>,</mo><mspace width='1em'/><mi>M</mi><mo>=</mo><msup>{_SYM['J_bar']}"
                 f"<mi>T</mi></msup>{_SYM['M_bar']}{_SYM['J_bar']}<mo>,</mo><mspace width='1em'/>"
                 f"<mi>k</mi><mo>=</mo><msup>{_SYM['J_bar']}<mi>T</mi></msup>{_SYM['q_c']}"
                 f"<mo>,</mo><mspace width='1em'/><mi>q</mi><mo>=</mo><msup>{_SYM['J_bar']}"
                 f"<mi>T</mi></msup>{_SYM['q_e']}</mrow>")


def _headline_reactions() -> str:
    return _math(f"<mrow>{_SYM['N_hat']}<mo>⋅</mo><mi>g</mi><mo>=</mo>{_SYM['k_hat']}<mo>−</mo>"
                 f"{_SYM['q_hat']}<mo>,</mo><mspace width='1em'/>{_SYM['N_hat']}<mo>=</mo>"
                 f"<msup>{_SYM['Q_bar']}<mi>T</mi></msup><msup>{_SYM['M_bar']}<mrow><mo>−</mo>"
                 f"<mn>1</mn></mrow></msup>{_SYM['Q_bar']}</mrow>")


def _headline_lin() -> str:
    return _math(f"<mrow>{_SYM['M_tilde']}<mo>⋅</mo>{_DDETA}<mo>+</mo><mo>(</mo><mi>D</mi>"
                 f"<mo>+</mo><mi>G</mi><mo>)</mo><mo>⋅</mo>{_DETA}<mo>+</mo><mo>(</mo><mi>K</mi>"
                 f"<mo>+</mo><mi>N</mi><mo>)</mo><mo>⋅</mo>{_ETA}<mo>=</mo><mi>h</mi></mrow>")


# ------------------------------------------------------------------------------------------
# plots
# ------------------------------------------------------------------------------------------

def _figure(**kw: Any) -> Any:
    """A Matplotlib figure drawn by the SVG backend, without pyplot: no GUI backend is looked
    for and nothing is registered with pyplot's figure manager (half the import time)."""
    from matplotlib.backends.backend_svg import FigureCanvasSVG
    from matplotlib.figure import Figure

    fig = Figure(**kw)
    FigureCanvasSVG(fig)
    return fig


#: margins of the report's plots in inches (left, bottom, right, top): room for tick labels of
#: at most 6 characters (see :func:`_axes`), the axis labels and a title
PLOT_MARGINS = (0.85, 0.5, 0.15, 0.32)


def _axes(width: float, height: float) -> tuple[Any, Any]:
    """A figure of ``width`` × ``height`` inches with one axes in fixed margins
    (:data:`PLOT_MARGINS`). Constrained layout fitted the margins to the labels but laid all
    text out twice: 45 of the 85 ms of a plot. Tick labels are kept short instead: scientific
    notation with an offset outside 1e-3 … 1e4."""
    fig = _figure(figsize=(width, height))
    left, bottom, right, top = PLOT_MARGINS
    fig.subplots_adjust(left=left / width, bottom=bottom / height, right=1 - right / width,
                        top=1 - top / height)
    ax = fig.add_subplot()
    ax.ticklabel_format(style="sci", scilimits=(-3, 4), useOffset=True)
    return fig, ax


def _svg(fig: Any) -> str:
    import matplotlib

    buf = io.StringIO()
    # text as SVG text, not glyph outlines: the browser sets it, in a third of the time and
    # with smaller files
    with matplotlib.rc_context({"svg.fonttype": "none"}):
        fig.savefig(buf, format="svg")
    text = buf.getvalue()
    return text[text.index("<svg"):]


def _time_plot(t: np.ndarray, series: Mapping[str, np.ndarray], ylabel: str,
               title: str) -> str:
    fig, ax = _axes(7.5, 3.0)
    for name, v in series.items():
        ax.plot(t, v, label=name, linewidth=1.2)
    ax.set_xlabel("t / s")
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    if 1 < len(series) <= 12:
        ax.legend(fontsize=8, loc="best", ncol=2 if len(series) > 4 else 1)
    return _svg(fig)


def _eigen_plot(eigenvalues: np.ndarray, title: str) -> str:
    fig, ax = _axes(4.5, 3.2)
    ax.axvline(0, color="0.5", linewidth=0.8)
    ax.axhline(0, color="0.5", linewidth=0.8)
    ax.plot(eigenvalues.real, eigenvalues.imag, "x", markersize=8, color="C3")
    ax.set_xlabel("Re λ / (1/s)")
    ax.set_ylabel("Im λ / (rad/s)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    return _svg(fig)


def _multiplier_plot(multipliers: np.ndarray, title: str) -> str:
    """Floquet multipliers in the complex plane against the unit circle (stable inside)."""
    fig, ax = _axes(4.0, 3.6)
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
    return _svg(fig)


# ------------------------------------------------------------------------------------------
# the motion: snapshots and animation
# ------------------------------------------------------------------------------------------

def _projection(view: str | None, pts: np.ndarray) -> tuple[Callable[[np.ndarray], np.ndarray],
                                                            tuple[str, str]]:
    """A map from inertial points (…, 3) to the drawing plane, and the axis labels."""
    axes = {"x": 0, "y": 1, "z": 2}
    if view and view != "3d":
        i, j = axes[view[0]], axes[view[1]]
        return (lambda p: p[..., [i, j]]), (view[0], view[1])
    if view is None:
        spread = pts.reshape(-1, 3).std(axis=0)
        if spread.min() < 1e-9 * max(1.0, spread.max()):
            keep = [k for k in range(3) if k != int(np.argmin(spread))]
            names = "xyz"
            return (lambda p: p[..., keep]), (names[keep[0]], names[keep[1]])
    # isometric-like view with z up
    a, b = np.radians(35.0), np.radians(25.0)
    R = np.array([[np.cos(a), np.sin(a), 0.0],
                  [-np.sin(a) * np.sin(b), np.cos(a) * np.sin(b), np.cos(b)]])
    return (lambda p: p @ R.T), ("", "")


@dataclass
class _Motion:
    """Positions along the motion: for every body its frame origin and centre of mass."""

    t: np.ndarray
    origin: dict[str, np.ndarray]
    com: dict[str, np.ndarray]
    parent: dict[str, str]
    mass: dict[str, float]


def _motion(model: ModelFile, res: Any, parameters: Mapping[str, float]) -> _Motion:
    import symengine as se

    system = model.system
    origin = {b.name: res.positions(b.name, "origin") for b in system.bodies}
    com = {b.name: res.positions(b.name, "com") for b in system.bodies}
    values = system.parameter_values
    values.update(parameters)
    subs = {se.Symbol(k): v for k, v in values.items()}
    mass = {}
    for b in system.bodies:
        try:
            mass[b.name] = float(b.mass.subs(subs))
        except (RuntimeError, TypeError, ValueError):
            mass[b.name] = 1.0
    return _Motion(res.t, origin, com, {b.name: b.parent for b in system.bodies}, mass)


def _segments(m: _Motion, k: int) -> list[tuple[np.ndarray, np.ndarray]]:
    zero = np.zeros(3)
    segs = []
    for b, parent in m.parent.items():
        start = zero if parent == "world" else m.origin[parent][k]
        segs.append((start, m.origin[b][k]))
        segs.append((m.origin[b][k], m.com[b][k]))
    return segs


def _frame_geometry(m: _Motion, view: str | None) -> tuple[Callable[[np.ndarray], np.ndarray],
                                                           np.ndarray, np.ndarray]:
    allp = [np.zeros((len(m.t), 3))] + list(m.origin.values()) + list(m.com.values())
    pts = np.stack(allp, axis=1)  # (N, n, 3)
    proj, _ = _projection(view, pts)
    flat = proj(pts).reshape(-1, 2)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    span = max(float((hi - lo).max()), 1e-9)
    pad = 0.08 * span
    return proj, lo - pad, hi + pad


def _snapshot_strip(m: _Motion, view: str | None, frames: int = 8) -> str:
    from matplotlib.collections import LineCollection

    proj, lo, hi = _frame_geometry(m, view)
    idx = np.linspace(0, len(m.t) - 1, frames).round().astype(int)
    # no ticks, so fixed margins (constrained layout of 8 axes costs more than their drawing)
    fig = _figure(figsize=(1.6 * frames, 2.0))
    axs = fig.subplots(1, frames)
    fig.subplots_adjust(left=0.01, right=0.99, bottom=0.02, top=0.86, wspace=0.08)
    mmax = max(max(m.mass.values(), default=1.0), 1e-12)
    sizes = np.array([12 + 40 * m.mass[name] / mmax for name in m.com])
    for ax, k in zip(np.atleast_1d(axs), idx, strict=True):
        segs = [(proj(a), proj(b)) for a, b in _segments(m, int(k))]
        if segs:  # one collection per frame: a Line2D per segment cost 40 ms a frame
            ax.add_collection(LineCollection(segs, colors="0.25", linewidths=1.5))
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
    return _svg(fig)


def _animation(m: _Motion, view: str | None, frames: int = 120, size: int = 360) -> str:
    """An SVG with SMIL animation of the segments and centres of mass (loops forever)."""
    proj, lo, hi = _frame_geometry(m, view)
    n = len(m.t)
    idx = np.linspace(0, n - 1, min(frames, n)).round().astype(int)
    scale = size / float(max(hi - lo))
    dur = max(float(m.t[-1] - m.t[0]), 0.5)
    # centre the drawing in the square
    off = (size - (hi - lo) * scale) / 2

    def xy(p: np.ndarray) -> tuple[float, float]:
        q = proj(p)
        return (float((q[0] - lo[0]) * scale + off[0]),
                float(size - (q[1] - lo[1]) * scale - off[1]))

    def anim(attr: str, vals: list[float]) -> str:
        v = ";".join(f"{x:.2f}" for x in vals)
        return (f'<animate attributeName="{attr}" values="{v}" dur="{dur:.3f}s" '
                f'repeatCount="indefinite" calcMode="linear"/>')

    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{size}" height="{size}" '
             f'viewBox="0 0 {size} {size}" class="animation">',
             f'<rect width="{size}" height="{size}" fill="#fafafa" stroke="#ccc"/>']
    nseg = len(_segments(m, 0))
    per_frame = [_segments(m, int(k)) for k in idx]
    for s in range(nseg):
        a = [xy(f[s][0]) for f in per_frame]
        b = [xy(f[s][1]) for f in per_frame]
        parts.append(
            f'<line x1="{a[0][0]:.2f}" y1="{a[0][1]:.2f}" x2="{b[0][0]:.2f}" y2="{b[0][1]:.2f}" '
            f'stroke="#444" stroke-width="3" stroke-linecap="round">'
            + anim("x1", [p[0] for p in a]) + anim("y1", [p[1] for p in a])
            + anim("x2", [p[0] for p in b]) + anim("y2", [p[1] for p in b]) + "</line>")
    mmax = max(max(m.mass.values(), default=1.0), 1e-12)
    for name, c in m.com.items():
        pts = [xy(c[int(k)]) for k in idx]
        r = 3 + 7 * np.sqrt(m.mass[name] / mmax)
        parts.append(f'<circle cx="{pts[0][0]:.2f}" cy="{pts[0][1]:.2f}" r="{r:.1f}" '
                     f'fill="#1f77b4"><title>{_e(name)}</title>'
                     + anim("cx", [p[0] for p in pts]) + anim("cy", [p[1] for p in pts])
                     + "</circle>")
    p0 = xy(np.zeros(3))
    parts.append(f'<path d="M{p0[0]:.1f},{p0[1]:.1f} l-6,10 h12 z" fill="#000"/>')
    parts.append("</svg>")
    return "".join(parts)


# ------------------------------------------------------------------------------------------
# the report
# ------------------------------------------------------------------------------------------

_CSS = """
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;max-width:1100px;
margin:2em auto;padding:0 1em;color:#222;line-height:1.45}
h1{font-size:1.7em;margin-bottom:.2em}h2{border-bottom:1px solid #ddd;padding-bottom:.2em;
margin-top:2em}h3{margin-top:1.4em}
table{border-collapse:collapse;margin:.5em 0;font-size:.9em}
td,th{border:1px solid #ddd;padding:.25em .6em;text-align:right}
th{background:#f4f4f4}table.info td,table.info th{text-align:left}
table.matrix td{font-family:ui-monospace,Consolas,monospace}
.note{background:#fff7e0;border-left:4px solid #e0a800;padding:.4em .8em;margin:.6em 0}
.ok{color:#11772d;font-weight:600}.bad{color:#b00020;font-weight:600}
.eq{overflow-x:auto;margin:.5em 0 1em 0;padding:.3em 0}
math{font-size:1.1em;font-family:"STIX Two Math","Latin Modern Math","Cambria Math",
"DejaVu Math TeX Gyre",math}.meta{color:#666;font-size:.9em}
svg{max-width:100%;height:auto}
"""


def _note(text: str) -> str:
    return f'<p class="note">{_e(text)}</p>'


def _prescribed_joints(system: Any) -> list[str]:
    """Joints whose steps depend on t explicitly (rheonomic drives)."""
    out = []
    for b in system.bodies:
        for st in b.joint.steps:
            exprs = [st.angle] if hasattr(st, "angle") else list(st.vector)
            if any("t" in {str(x) for x in e.free_symbols} for e in exprs):
                out.append(b.joint.name)
                break
    return out


#: seconds for simplifying all matrices of one report for display (entries left as derived after)
REPORT_SIMPLIFY_SECONDS = 0.3


def _display_matrix(name: str, m: Any, system: Any, max_ops: int,
                    deadline: float | None = None) -> str:
    rows, cols = m.shape
    if rows > MAX_DISPLAY_ROWS:
        ops = export.display_ops(m)
        inner = (f"<mtext>{rows}×{cols} matrix, {ops} operations after CSE (shown in "
                 "equations.json / equations.tex)</mtext>")
    else:
        inner = export.matrix_mathml(m, system, max_ops, deadline)
    return f'<div class="eq">{_math(f"<mrow>{_SYM[name]}<mo>=</mo>{inner}</mrow>")}</div>'


def _sections(model: ModelFile, out: Path, params: dict[str, float], t_end: float | None,
              max_ops: int, progress: Any, info: ReportInfo, sections: list[str],
              ops: dict[str, int], summ: dict[str, Any], t_start: float) -> None:
    """The sections of the report, each appended to ``sections`` when it is complete, with
    their data files (so that an interruption leaves the sections finished before it)."""
    from ..cli import EVAL_FORMAT, _json_array, evaluate_all, has_capability

    # one budget for simplifying every displayed matrix: the report must not wait on SymPy
    deadline = t_start + REPORT_SIMPLIFY_SECONDS
    system = model.system
    p = len(system.bodies)

    # --- the model ------------------------------------------------------------------------
    units = model_units(system)  # declared, and derived for coordinates and inputs
    desc = dict(model.descriptions)
    pv = system.parameter_values
    pv.update(params)
    src = Path(model.path)
    copy = out / model_copy(model)
    if src.is_file() and not copy.resolve() == src.resolve():
        shutil.copyfile(src, copy)
        info.files.append(copy)
    names = export.display_names(system)

    def sym(n: str) -> str:
        return _math(names[n].mathml(), block=False) if n in names else _e(n)

    s = [f"<h2>1. Model</h2><p>{_e(model.description)}</p>" if model.description else
         "<h2>1. Model</h2>"]
    s.append(f"<p>f = {system.f} degrees of freedom, p = {p} bodies, "
             f"{summ['constraints']} constrained directions (reaction forces), "
             f"{len(system.forces)} force elements.</p>")
    s.append("<h3>Coordinates</h3>" + _table(
        [(sym(c), _e(c), _e(units.get(c, "")), _e(desc.get(c, ""))) for c in
         system.coordinate_names], ["", "name", "unit", "description"], "info"))
    if pv:
        s.append("<h3>Parameters</h3>" + _table(
            [(sym(k), _e(k), _num(v), _e(units.get(k, "")), _e(desc.get(k, ""))) for k, v in
             pv.items()], ["", "name", "value", "unit", "description"], "info"))
    if system.inputs:
        s.append("<h3>Inputs</h3>" + _table(
            [(sym(u), _e(u), _e(units.get(u, "")), _e(desc.get(u, ""))) for u in
             system.input_names], ["", "name", "unit", "description"], "info"))
    s.append("<h3>Bodies and joints</h3>" + _table(
        [(_e(j["body"]), _e(j["parent"]), _e(j["name"]), _e(j["type"]),
          _e(", ".join(j["coordinates"]) or "—"), j["constrained"]) for j in summ["joints"]],
        ["body", "parent", "joint", "type", "coordinates", "constrained"], "info"))
    if system.forces:
        s.append("<h3>Force elements</h3>" + _table(
            [(_e(f["name"]), _e(f["type"])) for f in summ["forces"]], ["name", "type"], "info"))
    if summ.get("quantities"):
        s.append("<p>Kinematic quantities in the force laws (replaced by their expressions in "
                 "y, ẏ, t in q̄<sup>e</sup>):</p>" + _table(
                     [(_e(q["name"]), _e(q["definition"]), _e(", ".join(q["symbols"])))
                      for q in summ["quantities"]], ["name", "definition", "symbols"], "info"))
    sections.append("".join(s))

    # --- equations ------------------------------------------------------------------------
    from ..cli import _eom_matrices

    mats = _eom_matrices(system)
    ops.update({k: export.display_ops(m) for k, m in mats.items()})
    s = ["<h2>2. Newton–Euler equations and equations of motion</h2>",
         "<p>Newton–Euler equations of all bodies (translational rows in the inertial frame, "
         "rotational rows in each body frame about its centre of mass):</p>",
         f'<div class="eq">{_headline_ne()}</div>']
    for k in ("M_bar", "J_bar", "q_c", "q_e"):
        s.append(_display_matrix(k, mats[k], system, max_ops, deadline))
    s.append("<p>Projection with J̄ᵀ eliminates the reaction forces (J̄ᵀQ̄ = 0):</p>")
    s.append(f'<div class="eq">{_headline_eom()}</div>')
    for k in ("M", "k", "q"):
        s.append(_display_matrix(k, mats[k], system, max_ops, deadline))
    if has_capability("reactions"):
        try:
            react = system.reactions()
            q_count = len(react.g_names)
            s.append(f"<p>Reaction forces: Q̄ ({6 * p}×{q_count}) has one column per "
                     "constrained direction (" + ", ".join(_e(n) for n in react.g_names[:12])
                     + (", …" if q_count > 12 else "") + "); N̂·g = k̂ − q̂ gives g "
                     "without ÿ:</p>")
            s.append(f'<div class="eq">{_headline_reactions()}</div>')
            s.append(_display_matrix("Q_bar", react.Q_bar, system, max_ops, deadline))
            mats_json_extra = {"Q_bar": react.Q_bar}
        except JourdainError as exc:
            s.append(_note(f"the reaction forces could not be formed: {exc}"))
            mats_json_extra = {}
    else:
        mats_json_extra = {}
    s.append("<p class='meta'>Operation counts after common-subexpression elimination: "
             + ", ".join(f"{k} {v}" for k, v in ops.items()) + ".</p>")
    sections.append("".join(s))
    # the same compilable fragment as jourdain eom --format latex (math delimiters, the
    # column count of wide matrices); the model's name only in the comment line
    latex_names = {"M_bar": r"\bar{M}", "J_bar": r"\bar{J}", "q_c": r"\bar{q}^{c}",
                   "q_e": r"\bar{q}^{e}", "M": "M", "k": "k", "q": "q"}
    (out / "equations.tex").write_text(
        export.latex_fragment(mats, latex_names, system,
                              f"{system.name}: {_dt.date.today().isoformat()}", max_ops,
                              deadline), encoding="utf-8")
    eqj = {"format": "jourdain-eom/1", "model": system.name,
           "coordinates": system.coordinate_names,
           "rates": [f"{c}_d" for c in system.coordinate_names],
           "parameters": system.parameter_values, "inputs": system.input_names}
    eqj.update(export.matrices_json({**mats, **mats_json_extra}, system))
    (out / "equations.json").write_text(json.dumps(eqj, indent=1), encoding="utf-8")
    info.files += [out / "equations.tex", out / "equations.json"]

    # --- numbers at the initial state -----------------------------------------------------
    y0 = np.array(model.simulation.y0, float)
    yd0 = np.array(model.simulation.yd0, float)
    u0 = {n: 0.0 for n in system.input_names}
    try:
        from .capabilities import T as _t

        for name, e in model.simulation.inputs:
            import symengine as se

            subs = {se.Symbol(k): v for k, v in pv.items()}
            subs[_t] = 0.0
            u0[name] = float(e.subs(subs))
    except (RuntimeError, TypeError, ValueError):
        pass
    s = ["<h2>3. Numbers at the initial state</h2>",
         "<p>" + ", ".join(f"{_e(c)} = {_num(v)}" for c, v in
                           zip(system.coordinate_names, y0, strict=True))
         + "; " + ", ".join(f"{_e(c)}_d = {_num(v)}" for c, v in
                            zip(system.coordinate_names, yd0, strict=True))
         + (("; " + ", ".join(f"{_e(k)} = {_num(v)}" for k, v in u0.items())) if u0 else "")
         + ", t = 0.</p>"]
    coords = system.coordinate_names
    values: dict[str, np.ndarray] = {}
    extra: dict[str, Any] = {}
    try:
        values, extra, missing = evaluate_all(model, y0, yd0, 0.0, params, u0)
        for k in ("M", "k", "q"):
            s.append(f"<h3>{_math(_SYM[k], False)}</h3>"
                     + _matrix_table(values[k], coords, coords if k == "M" else None))
        if "g" in values:
            g = np.asarray(values["g"], float).reshape(-1)
            labels = list(extra.get("g_names", [str(i) for i in range(g.size)]))
            s.append("<h3>Reaction forces g (N̂·g = k̂ − q̂)</h3>"
                     "<p class='meta'>Components in the child body frame at the joint point; "
                     f"forces in {_e(force_unit(units))}, torques in {_e(torque_unit(units))} "
                     "(in the model's units).</p>")
            s.append(_matrix_table(g[None, :], None, labels))
            if extra.get("g_undetermined"):
                s.append(_note("undetermined components (statically indeterminate): "
                               + ", ".join(extra["g_undetermined"])))
        for k, why in missing.items():
            info.notes.append(f"{k}: {why}")
        if missing:
            s.append(_note("not available: " + ", ".join(missing) + " — "
                           + next(iter(missing.values()))))
        vj = {"format": EVAL_FORMAT, "model": system.name, "file": model.path,
              "coordinates": coords, "t": 0.0, "y": y0.tolist(), "yd": yd0.tolist(),
              "parameters": pv, "inputs": u0,
              "values": {k: _json_array(v) for k, v in values.items()},
              "g_names": list(extra.get("g_names", [])), "not_available": missing,
              "units": value_units(system, extra.get("g_names", [])),
              "joint_wrenches": {k: w.as_dict()
                                 for k, w in extra.get("joint_wrenches", {}).items()}}
        (out / "values.json").write_text(json.dumps(vj, indent=1), encoding="utf-8")
        info.files.append(out / "values.json")
    except JourdainError as exc:
        s.append(_note(f"could not evaluate at the initial state: {exc}"))
        info.notes.append(f"evaluation: {exc}")
    sections.append("".join(s))

    # --- linearization --------------------------------------------------------------------
    s = ["<h2>4. Linearization, eigenvalues and stability</h2>",
         f'<div class="eq">{_headline_lin()}</div>',
         "<p>M̃·η̈ + P·η̇ + Q·η = h with D = ½(P + Pᵀ) (damping), G = ½(P − Pᵀ) (gyroscopic), "
         "K = ½(Q + Qᵀ) (stiffness), N = ½(Q − Qᵀ) (circulatory).</p>"]
    if not has_capability("linearize"):
        s.append(_note("the linearization is not available yet in this version of jourdain"))
        info.notes.append("linearization: not available yet")
    elif not model.nominal:
        s.append(_note("the model defines no nominal motion ([nominal.<name>] in the model "
                       "file)"))
    else:
        from . import capabilities

        for nominal in model.nominal:
            s.append(f"<h3>About “{_e(nominal.name)}”</h3>")
            if nominal.description:
                s.append(f"<p>{_e(nominal.description)}</p>")
            s.append("<p>Nominal motion: " + ", ".join(
                _math(f"<mrow>{names[c].mathml()}<mo>=</mo>"
                      f"{export.expr_mathml(to_sympy(e), system)}</mrow>", block=False)
                for c, e in zip(coords, nominal.y, strict=True)) + "</p>")
            try:
                res = capabilities.linear_analysis(model, nominal.name, params)
            except JourdainError as exc:
                s.append(_note(f"could not linearize: {exc}"))
                info.notes.append(f"linearization about {nominal.name}: {exc}")
                continue
            num = res["numbers"]
            keys = ["M_tilde", "P", "Q", "h"]
            if res["time_invariant"]:
                keys += ["D", "G", "K", "N"]
                if res.get("numerically_time_invariant"):
                    s.append("<p class='meta'>t appears in the expressions but cancels: M̃, P, "
                             "Q (and B) take the same values at every time checked, so the "
                             "system is time-invariant.</p>")
            else:
                s.append(_note("time-variant linearization ("
                               + ", ".join(res["linearization"].time_dependence)
                               + " depend on t); numbers at t = 0; no D/G/K/N split, no "
                               "eigenvalues"))
            for k in keys:
                v = np.asarray(num[k], float)
                s.append(f"<h4>{_math(_SYM[k], False)}</h4>"
                         + _matrix_table(v, coords, coords if v.ndim == 2 else None))
            if system.inputs and "B" in num:
                s.append(f"<h4>{_math(_SYM['B'], False)}</h4>"
                         + _matrix_table(num["B"], coords, system.input_names))
            if res["conservative"] is not None:
                verdict = ("<span class='ok'>conservative</span> (D = 0, N = 0, h = 0)"
                           if res["conservative"] else
                           "<span class='bad'>not conservative</span>: "
                           + ", ".join(n for n in ("D", "N") if np.abs(num[n]).max() > 1e-9
                                       * max(1.0, float(np.abs(num["Q"]).max())))
                           + (" , h ≠ 0" if not res["nominal_check"].is_solution else ""))
                s.append(f"<p>{verdict}</p>")
            elif not res["nominal_check"].is_solution:
                # h against the forces at work at the nominal state, not an absolute number
                s.append(f"<p>h ≠ 0 (largest |h| = {_num(res['h_norm'])}): the nominal motion "
                         "does not solve the equations of motion.</p>")
            m, st = res["modes"], res["stability"]
            if m is not None:
                rows = []
                lams = _snap(m.eigenvalues, 1e-9)
                zetas = _snap(m.damping_ratios, 1e-9)
                for lam, fn, z in zip(lams, m.frequencies_hz, zetas, strict=True):
                    rows.append((_num(lam.real), _num(lam.imag), _num(fn), _num(z)))
                s.append(_table(rows, ["Re λ / (1/s)", "Im λ / (rad/s)", "f<sub>n</sub> / Hz",
                                       "ζ"]))
                s.append(_eigen_plot(lams, f"eigenvalues about {nominal.name}"))
            if res.get("cyclic"):
                s.append(f"<p>{_e(capabilities.cyclic_text(res['cyclic']))}.</p>")
            fl = res.get("floquet")
            if fl is not None:
                s.append(_floquet_html(fl, nominal.name))
                info.summary_lines.append(f"  about {nominal.name} (Floquet, T = "
                                          f"{fl.period:.6g}): {fl.verdict}")
            if st is not None:
                cls = "ok" if st.is_stable else "bad"
                s.append(f"<p>Stability: <span class='{cls}'>{_e(st.verdict)}</span> — "
                         f"{_e(st.reason)}</p>")
                info.summary_lines.append(f"  about {nominal.name}: {st.verdict}")
            lj = capabilities.jsonable(res)
            fn_ = out / f"linearization-{nominal.name}.json"
            fn_.write_text(json.dumps(lj, indent=1), encoding="utf-8")
            info.files.append(fn_)
    sections.append("".join(s))

    # --- reactions symbolic summary -------------------------------------------------------
    # --- simulation -----------------------------------------------------------------------
    s = ["<h2>5. Simulation</h2>"]
    if not has_capability("simulate"):
        s.append(_note("simulation is not available yet in this version of jourdain"))
        info.notes.append("simulation: not available yet")
    else:
        from . import capabilities

        csv = out / "simulation.csv"
        try:
            t0 = time.perf_counter()
            try:  # written as the run goes; a failed run keeps the motion up to the failure
                res = capabilities.simulate(model, params, t_end=t_end, progress=progress,
                                            output=csv)
            except JourdainError as exc:
                if getattr(exc, "results", None) is None or len(exc.results.t) < 2:
                    raise
                res = exc.results
                info.status, info.message = "failed", f"the simulation failed: {exc}"
            wall = time.perf_counter() - t0
            info.files.append(csv)
            if res.interrupted:
                info.status, info.message = "interrupted", f"the simulation was {res.message}"
            if res.status in ("interrupted", "failed"):
                s.append(_note(f"{info.message}. The plots and simulation.csv hold the motion "
                               f"up to t = {res.t[-1]:g} s."))
                info.notes.append(f"simulation: {res.status} at t = {res.t[-1]:g} s")
            sim = model.simulation
            s.append(f"<p>t = 0 … {_num(res.t[-1])} s, method {_e(sim.method)}, rtol "
                     f"{sim.rtol:g}, atol {sim.atol:g}; {len(res.t)} output samples; "
                     f"{wall:.2f} s wall time (with compilation). Data: simulation.csv.</p>")
            # axis labels with units (jourdain.units): "phi1 / rad", "x_d / (m/s)"
            s.append(_time_plot(res.t, {res.label(c): res.y[:, i] for i, c in enumerate(coords)},
                                shared_label([(c, res.unit(c)) for c in coords], "y"),
                                "coordinates"))
            s.append(_time_plot(res.t, {res.label(f"{c}_d"): res.yd[:, i]
                                        for i, c in enumerate(coords)},
                                shared_label([(f"{c}_d", res.unit(f"{c}_d")) for c in coords],
                                             "ẏ"), "rates"))
            try:
                Tk, V, W = res.kinetic_energy, res.potential_energy, res.work_nonconservative
                Wd = res.work_drive
                s.append(_time_plot(res.t, {"T (kinetic)": Tk, "V (potential)": V,
                                            "T + V − W_nc − W_drive": Tk + V - W - Wd},
                                    axis_label("energy", res.unit("T")), "energy balance"))
                driven = _prescribed_joints(system)
                why = (f" (with the work W_drive of the prescribed motion of "
                       f"{', '.join(driven)})" if driven else "")
                s.append(f"<p class='meta'>energy balance error (relative): "
                         f"{res.energy_balance_error:.2e}{_e(why)}</p>")
                info.summary_lines.append(
                    f"  simulated t = 0 … {res.t[-1]:g} s, energy balance error "
                    f"{res.energy_balance_error:.1e}"
                    + (" (prescribed motion's work included)" if driven else ""))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(_note(f"energies not available: {exc}"))
                info.summary_lines.append(f"  simulated t = 0 … {res.t[-1]:g} s")
            try:
                g = res.g
                labels = res.g_names
                keep = list(range(min(12, g.shape[1])))
                s.append(_time_plot(res.t, {res.label(labels[i]): g[:, i] for i in keep},
                                    reactions_label(labels, res.units),
                                    "reaction forces along the motion"
                                    + ("" if len(keep) == g.shape[1] else
                                       f" (first {len(keep)} of {g.shape[1]})")))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(_note(f"reaction forces along the motion not available: {exc}"))
            try:
                s.append(_wrench_section(res, out, info))
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(_note(f"joint wrenches along the motion not available: {exc}"))
            try:
                mo = _motion(model, res, params)
                s.append("<h3>Snapshots of the motion</h3>" + _snapshot_strip(mo, model.view))
                s.append("<h3>Animation</h3>" + _animation(mo, model.view)
                         + "<p class='meta'>Lines join the body frames along the tree; dots "
                           "are the centres of mass (size by mass); the triangle is the "
                           "inertial origin.</p>")
            except (JourdainError, KeyError, AttributeError, ValueError) as exc:
                s.append(_note(f"positions along the motion not available: {exc}"))
            # the 3-D view (jourdain.io.viewer): its own page with three.js, in a sandboxed
            # iframe, so that this page itself runs no script
            from .viewer import report_section

            s.append(report_section(res, model))
        except JourdainError as exc:
            s.append(_note(f"the simulation failed: {exc}"))
            info.notes.append(f"simulation: {exc}")
            info.status, info.message = "failed", f"the simulation failed: {exc}"
            if csv.is_file():  # the initial state, where the run failed at once
                info.files.append(csv)
    sections.append("".join(s))


def _floquet_html(fl: Any, name: str) -> str:
    """The Floquet analysis of a periodic nominal motion: multipliers, exponents, the
    plot against the unit circle and the verdict."""
    rows = [(_num(mu.real), _num(mu.imag), f"{abs(mu):.8f}",
             _num(lam.real) if np.isfinite(lam.real) else "−∞", _num(lam.imag))
            for mu, lam in zip(fl.multipliers, fl.exponents, strict=True)]
    cls = "ok" if fl.is_stable else "bad"
    return (f"<h4>Floquet analysis (periodic nominal motion, T = {_num(fl.period)} s)</h4>"
            "<p>Monodromy matrix Φ(t<sub>0</sub> + T, t<sub>0</sub>) of ẋ = A(t)·x over one "
            "period; its eigenvalues are the Floquet multipliers μ, the exponents ln(μ)/T.</p>"
            + _table(rows, ["Re μ", "Im μ", "|μ|", "Re ln(μ)/T / (1/s)", "Im ln(μ)/T / (rad/s)"])
            + _multiplier_plot(fl.multipliers, f"Floquet multipliers about {name}")
            + f"<p>Stability (Floquet): <span class='{cls}'>{_e(fl.verdict)}</span> — "
              f"{_e(fl.reason)}</p>")


def _wrench_section(res: Any, out: Path, info: ReportInfo) -> str:
    """The magnitudes of each joint's force and torque along the motion (a plot; the vectors
    in the joint and the inertial frame in ``wrench-<joint>.csv``, one table per joint)."""
    wrenches = res.joint_wrenches
    series: dict[str, np.ndarray] = {}
    files = []
    for name, w in wrenches.items():
        series[f"|F| {name}"] = np.linalg.norm(w.force, axis=1)
        series[f"|T| {name}"] = np.linalg.norm(w.torque, axis=1)
        cols, data = res.joint_wrench_table(name)
        fn = out / f"wrench-{name}.csv"
        np.savetxt(fn, data, delimiter=",", header=",".join(cols), comments="")
        info.files.append(fn)
        files.append(fn.name)
    keep = dict(list(series.items())[:12])
    return (_time_plot(res.t, keep, reactions_label(res.g_names, res.units),
                       "joint wrenches along the motion (on the child body at the joint point)"
                       + ("" if len(keep) == len(series) else
                          f" (first {len(keep)} of {len(series)})"))
            + "<p class='meta'>Force and torque vectors per joint, in the joint frame and in "
              f"the inertial frame: {_e(', '.join(files))}.</p>")


def write_report(model: ModelFile, out: Path, parameters: Mapping[str, float] | None = None,
                 t_end: float | None = None, max_ops: int = export.MAX_DISPLAY_OPS,
                 progress: Any = False) -> ReportInfo:
    """Compute everything for ``model`` and write ``out/report.html`` with the data files.

    Files: ``report.html``, ``model.toml`` (a copy of the input; ``model.urdf`` for a URDF
    robot), ``equations.tex``,
    ``equations.json`` (the matrices with shared temporaries), ``values.json`` (the numbers at
    the initial state, the format of ``jourdain eval --json``), ``linearization-<name>.json``
    per nominal motion, ``simulation.csv`` (written as the simulation goes; ``progress`` is
    passed to it), ``run.json`` (``"format": "jourdain-run/1"``: how the run ended, ``status``
    complete, interrupted or failed, and ``message``; the files and notes).

    Ctrl-C stops the work: the sections finished before it are written (a simulation stops
    where it is and its motion up to there is shown), and report.html, run.json and the header
    of simulation.csv say that the run was interrupted (``info.status``). A simulation that
    fails keeps its motion up to the failure (``info.status`` "failed").
    """
    from ..cli import summary

    t_start = time.perf_counter()
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    system = model.system
    info = ReportInfo(out / "report.html")
    sections: list[str] = []
    ops: dict[str, int] = {}
    summ = summary(model)
    try:
        _sections(model, out, dict(parameters or {}), t_end, max_ops, progress, info,
                  sections, ops, summ, t_start)
    except KeyboardInterrupt:
        info.status = "interrupted"
        info.message = (f"interrupted by the user (Ctrl-C) after section {len(sections)} of "
                        "5; the sections after it are missing")

    # --- files ----------------------------------------------------------------------------
    info.files.insert(0, info.html)
    info.files.insert(1, out / "run.json")
    files = "".join(f"<li><a href='{_e(f.name)}'>{_e(f.name)}</a></li>" for f in info.files)
    sections.append(f"<h2>6. Files</h2><ul>{files}</ul>")
    elapsed = time.perf_counter() - t_start
    from .. import __version__

    head = (f"<h1>{_e(system.name)}</h1><p class='meta'>jourdain {__version__} report of "
            f"{_e(model.path)}, {_dt.datetime.now().strftime('%Y-%m-%d %H:%M')}, "
            f"computed in {elapsed:.1f} s</p>")
    if info.status != "complete":
        head += f"<p class='bad'>{_e(info.status.capitalize())}: {_e(info.message)}.</p>"
    page = ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>{_e(system.name)} — jourdain report</title><style>{_CSS}</style></head>"
            f"<body>{head}{''.join(sections)}</body></html>")
    info.html.write_text(page, encoding="utf-8")
    manifest = {"format": RUN_FORMAT, "model": system.name, "file": model.path,
                "status": info.status, "message": info.message,
                "files": [f.name for f in info.files], "notes": info.notes}
    (out / "run.json").write_text(json.dumps(manifest, indent=1), encoding="utf-8")
    count = (f" with {ops['M'] + ops['k'] + ops['q']} operations"
             if all(k in ops for k in ("M", "k", "q")) else "")
    info.summary_lines.insert(0, f"{system.name}: f = {system.f}, p = {len(system.bodies)} "
                                 f"bodies, {summ['constraints']} constrained directions; "
                                 f"M·ÿ + k = q{count}")
    for n in info.notes:
        info.summary_lines.append(f"  note: {n}")
    if info.status != "complete":
        info.summary_lines.append(f"  {info.status}: {info.message}")
    return info
