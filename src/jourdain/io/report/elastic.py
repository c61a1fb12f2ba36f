"""The report's part on elastic bodies (in section 1, after the model): per body its modal
basis — the natural frequencies of the basis, the nodes and the mass — and the mode shapes
drawn along the body's axis (the translation of every node, each mode scaled to its largest
displacement). The 3-D view draws the bodies themselves, deflecting as they move."""

from __future__ import annotations

from typing import Any

import numpy as np

from .figures import plot_axes, svg
from .html import esc, html_table, numstr
from .state import Run

#: modes drawn per body
SHAPES = 4


def mode_shape_plot(s: np.ndarray, shapes: np.ndarray, labels: list[str], title: str) -> str:
    fig, ax = plot_axes(7.5, 3.2)
    ax.axhline(0, color="0.6", linewidth=0.8)
    for k in range(shapes.shape[0]):
        ax.plot(s, shapes[k], "o-", markersize=2.5, linewidth=1.2, label=labels[k])
    ax.set_xlabel("position along the body / m")
    ax.set_ylabel("displacement (scaled)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8, loc="best")
    return svg(fig)


def _shapes(body: Any) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Node positions along the body's principal direction, and the first modes' signed
    displacement: per mode the translation component that moves most, scaled to 1."""
    nodes = np.asarray(body.modal.nodes, float)
    c = nodes - nodes.mean(axis=0)
    axis = np.linalg.svd(c, full_matrices=False)[2][0] if len(nodes) > 1 else np.eye(3)[0]
    s = (nodes - nodes[0]) @ axis
    s = s if s[-1] >= s[0] else -s
    Pt = np.asarray(body.modal.Phi_t, float)
    out, labels = [], []
    for k in range(min(SHAPES, body.n_q)):
        u = Pt[:, :, k]
        comp = int(np.argmax(np.abs(u).max(axis=0)))
        v = u[:, comp]
        big = float(np.abs(v).max())
        if big == 0.0:
            continue
        out.append(v / v[int(np.argmax(np.abs(v)))])
        labels.append(f"mode {k + 1} ({'xyz'[comp]}), "
                      f"{body.modal.omega[k] / (2 * np.pi):.4g} Hz")
    return s, np.array(out), labels


def elastic_html(run: Run) -> str:
    """The part for every elastic body of the model ("" when it has none)."""
    groups = getattr(run.model.system, "groups", ())
    bodies = [g for g in groups if hasattr(g, "modal")]
    if not bodies:
        return ""
    parts = ["<h3>Elastic bodies</h3><p>Floating frame of reference with the mass at the "
             "nodes (lumped) or at the elements' Gauss points (consistent; docs/elastic.md); "
             "the elastic coordinates are the amplitudes of the basis below. Frequencies: the basis's own (K_e, M_e of the finite-element "
             "model; for a rotor on its bearings, at rest).</p>"]
    for b in bodies:
        m = b.modal
        rows = [(str(k + 1), esc(m.kinds[k] if k < len(m.kinds) else ""), numstr(m.omega[k]),
                 numstr(m.omega[k] / (2 * np.pi))) for k in range(b.n_q)]
        spin = "" if getattr(b, "spin", None) is None else f", spinning by {esc(str(b.spin[1]))}"
        parts.append(f"<h4>{esc(b.name)}</h4><p>{len(m.nodes)} nodes, mass "
                     f"{numstr(b.total_mass)} kg"
                     f"{'' if b.points is None else f' ({len(b.points.mass)} mass points)'}"
                     f", {b.n_q} elastic coordinates "
                     f"{esc(', '.join(str(c) for c in b.coordinates))} ({esc(m.method)}"
                     f"{'' if b.Psi is None else ', geometric stiffening'}{spin})</p>")
        parts.append(html_table(rows, ["mode", "kind", "ω / (rad/s)", "f / Hz"]))
        s, shapes, labels = _shapes(b)
        if len(shapes):
            parts.append(run.figures.add(mode_shape_plot, s, shapes, labels,
                                         f"mode shapes of {b.name}"))
    return "".join(parts)
