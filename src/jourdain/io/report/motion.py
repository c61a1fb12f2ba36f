"""The motion in the report: positions of the body frames and centres of mass along the
simulated motion, their projection onto the drawing plane, and the SVG animation (SMIL)."""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import symengine as se

from ..modelfile import ModelFile
from ..viewer.poses import body_poses, closing_points
from .html import esc


def projection(view: str | None, pts: np.ndarray) -> tuple[Callable[[np.ndarray], np.ndarray],
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
class Motion:
    """Positions along the motion: for every body its frame origin and centre of mass."""

    t: np.ndarray
    origin: dict[str, np.ndarray]
    com: dict[str, np.ndarray]
    parent: dict[str, str]
    mass: dict[str, float]
    #: per closing joint (a closed system's): body A's origin, its point, body B's origin,
    #: its point, each (N, 3); the segments that draw the loops closed
    closing: dict[str, tuple[np.ndarray, ...]] = field(default_factory=dict)


def motion_of(model: ModelFile, res: Any, parameters: Mapping[str, float]) -> Motion:
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
    closing: dict[str, tuple[np.ndarray, ...]] = {}
    if system.closing:  # the closing joints' points, from the tree's poses at the same y
        r, S = body_poses(res, np.asarray(res.t, float))
        zero = np.zeros((len(res.t), 3))
        for c in system.closing:
            pts = closing_points(system, r, S, values).get(c.name)
            if pts is not None:
                closing[c.name] = (zero if c.body_a == "world" else origin[c.body_a], pts[0],
                                   zero if c.body_b == "world" else origin[c.body_b], pts[1])
    return Motion(res.t, origin, com, {b.name: b.parent for b in system.bodies}, mass,
                  closing)


def closing_segments(m: Motion, k: int) -> list[tuple[np.ndarray, np.ndarray]]:
    """The segments of the closing joints at sample ``k``: each body's origin to its point
    and the two points joined (of zero length where the loop is closed)."""
    segs = []
    for oa, pa, ob, pb in m.closing.values():
        segs += [(oa[k], pa[k]), (ob[k], pb[k]), (pa[k], pb[k])]
    return segs


def segments(m: Motion, k: int) -> list[tuple[np.ndarray, np.ndarray]]:
    zero = np.zeros(3)
    segs = []
    for b, parent in m.parent.items():
        start = zero if parent == "world" else m.origin[parent][k]
        segs.append((start, m.origin[b][k]))
        segs.append((m.origin[b][k], m.com[b][k]))
    return segs


def frame_geometry(m: Motion, view: str | None) -> tuple[Callable[[np.ndarray], np.ndarray],
                                                           np.ndarray, np.ndarray]:
    allp = ([np.zeros((len(m.t), 3))] + list(m.origin.values()) + list(m.com.values())
            + [p for c in m.closing.values() for p in (c[1], c[3])])
    pts = np.stack(allp, axis=1)  # (N, n, 3)
    proj, _ = projection(view, pts)
    flat = proj(pts).reshape(-1, 2)
    lo, hi = flat.min(axis=0), flat.max(axis=0)
    span = max(float((hi - lo).max()), 1e-9)
    pad = 0.08 * span
    return proj, lo - pad, hi + pad



def animation(m: Motion, view: str | None, frames: int = 120, size: int = 360) -> str:
    """An SVG with SMIL animation of the segments and centres of mass (loops forever)."""
    proj, lo, hi = frame_geometry(m, view)
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
    ntree = len(segments(m, 0))
    per_frame = [segments(m, int(k)) + closing_segments(m, int(k)) for k in idx]
    for s in range(len(per_frame[0])):
        a = [xy(f[s][0]) for f in per_frame]
        b = [xy(f[s][1]) for f in per_frame]
        color = "#444" if s < ntree else "#d62728"  # the closing joints' segments in red
        parts.append(
            f'<line x1="{a[0][0]:.2f}" y1="{a[0][1]:.2f}" x2="{b[0][0]:.2f}" y2="{b[0][1]:.2f}" '
            f'stroke="{color}" stroke-width="3" stroke-linecap="round">'
            + anim("x1", [p[0] for p in a]) + anim("y1", [p[1] for p in a])
            + anim("x2", [p[0] for p in b]) + anim("y2", [p[1] for p in b]) + "</line>")
    mmax = max(max(m.mass.values(), default=1.0), 1e-12)
    for name, c in m.com.items():
        pts = [xy(c[int(k)]) for k in idx]
        r = 3 + 7 * np.sqrt(m.mass[name] / mmax)
        parts.append(f'<circle cx="{pts[0][0]:.2f}" cy="{pts[0][1]:.2f}" r="{r:.1f}" '
                     f'fill="#1f77b4"><title>{esc(name)}</title>'
                     + anim("cx", [p[0] for p in pts]) + anim("cy", [p[1] for p in pts])
                     + "</circle>")
    p0 = xy(np.zeros(3))
    parts.append(f'<path d="M{p0[0]:.1f},{p0[1]:.1f} l-6,10 h12 z" fill="#000"/>')
    parts.append("</svg>")
    return "".join(parts)

