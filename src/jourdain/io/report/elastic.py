"""The report's part on elastic bodies (in section 1, after the model): per body its modal
basis — the natural frequencies of the basis, the nodes and the mass — and the mode shapes
drawn along the body's axis (the translation of every node, each mode scaled to its largest
displacement). The 3-D view draws the bodies themselves, deflecting as they move."""

from __future__ import annotations

from typing import Any

import numpy as np

from ...analysis.mode_motion import mode_motion
from ..viewer import view
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
             "the elastic coordinates are the amplitudes of the basis below. Frequencies: the "
             "basis's own (K_e, M_e of the finite-element model; for a rotor on its bearings, "
             "at rest).</p>"]
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


#: oscillating modes of a model with elastic bodies animated in 3-D views of their own
MODE_VIEWS = 3


def mode_amplitude(system: Any, shape: np.ndarray) -> float:
    """The amplitude for :func:`jourdain.analysis.mode_motion.mode_motion` of the mode
    ``shape`` (complex, f): the elastic bodies' nodes move by at most 5 % of the largest body's
    extent, the other coordinates by at most 0.1 (rad or m)."""
    names = list(system.coordinate_names)
    shape = np.asarray(shape)
    move, extent = 0.0, 0.0
    elastic: set[int] = set()
    for g in getattr(system, "groups", ()):
        if not hasattr(g, "modal"):
            continue
        idx = [names.index(str(c)) for c in g.coordinates]
        elastic.update(idx)
        # a gyroscopic mode's complex shape: each node's largest excursion, |Φ_t·s|
        u = np.einsum("nik,k->ni", np.asarray(g.modal.Phi_t, float), shape[idx])
        move = max(move, float(np.abs(u).max(initial=0.0)))
        nodes = np.asarray(g.modal.nodes, float)
        extent = max(extent, float(np.ptp(nodes, axis=0).max()) if len(nodes) > 1 else 0.0)
    rigid = [abs(shape[i]) for i in range(len(names)) if i not in elastic]
    bounds = [0.1 / max(rigid)] if rigid and max(rigid) > 0 else []
    if move > 0 and extent > 0:
        bounds.append(0.05 * extent / move)
    return min(bounds, default=0.1)


def mode_views(run: Run, nominal: str, lin: Any, modes: Any) -> str:
    """``mode-<nominal>-<k>.html``: the model's lowest oscillating modes about ``nominal``
    animated in the 3-D view (:func:`jourdain.mode_motion`), for models with elastic bodies;
    a line linking them ("" otherwise)."""
    system = run.model.system
    if not getattr(system, "groups", ()):
        return ""
    osc = modes.oscillating()[:MODE_VIEWS]
    links = []
    for k, i in enumerate(osc, start=1):
        amp = mode_amplitude(system, modes.shapes[:, i])
        v = view(mode_motion(lin, k, amplitude=amp, parameters=run.params))
        path = v.save(run.out / f"mode-{nominal}-{k}.html")
        run.info.files.append(path)
        links.append(f"<a href='{esc(path.name)}'>mode {k}, "
                     f"{modes.damped_frequencies[i] / (2 * np.pi):.4g} Hz</a>")
    return ("<p>The lowest modes, animated in the 3-D view (nodes moved by up to 5 % of the "
            "body's length, other coordinates by up to 0.1): " + ", ".join(links)
            + ".</p>") if links else ""
