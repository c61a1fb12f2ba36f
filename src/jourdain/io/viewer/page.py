"""The self-contained HTML page (three.js and the viewer inlined), :class:`View` for notebooks,
:func:`view` and the report's section.
"""

from __future__ import annotations

import html
import json
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import resources
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from ...errors import JourdainError, ModelError

if TYPE_CHECKING:
    from ...simulation.results import Results

from .poses import _system
from .scene import scene
from .visuals import contact_visuals


@dataclass(frozen=True)
class View:
    """A 3-D view of a motion: ``html`` is the self-contained page; in Jupyter the view shows
    itself (``_repr_html_``: the page in an ``<iframe srcdoc>`` of ``height`` pixels).

    ``notes``: what could not be drawn as asked (a mesh left out, ...)."""

    html: str
    notes: tuple[str, ...] = ()
    height: int = 480
    scene: dict = field(default_factory=dict, repr=False, compare=False)

    def _repr_html_(self) -> str:
        return embed(self.html, self.height)

    def save(self, path: str | Path) -> Path:
        """Write the page to ``path`` (it opens offline, from ``file://``)."""
        path = Path(path)
        path.write_text(self.html, encoding="utf-8")
        return path

    def __repr__(self) -> str:
        return (f"View({self.scene.get('name', '')!r}: {len(self.scene.get('bodies', []))} "
                f"bodies, {self.scene.get('n_frames', 0)} frames, {len(self.html)} characters)")



_PAGE_CSS = """
html,body{height:100%;margin:0}
body{font-family:system-ui,-apple-system,Segoe UI,Helvetica,Arial,sans-serif;font-size:13px;
color:#222;background:#f7f7f7}
#jourdain-view{display:flex;flex-direction:column;height:100%}
.jv-canvas{flex:1;min-height:120px;position:relative;overflow:hidden}
.jv-canvas canvas{display:block;width:100%;height:100%}
.jv-bar{display:flex;gap:.6em;align-items:center;padding:.3em .6em;background:#eee;
border-top:1px solid #ccc}
.jv-slider{flex:1}.jv-time{font-variant-numeric:tabular-nums;min-width:7.5em}
.jv-help{color:#666;padding:.2em .6em;background:#eee;font-size:11px}.jv-note{color:#8a5a00}
"""


def _asset(name: str) -> str:
    return resources.files(__package__ or "jourdain.io.viewer").joinpath(name).read_text(encoding="utf-8")


@lru_cache(maxsize=1)
def _scripts() -> tuple[str, str]:
    return _asset("three_bundle.js"), _asset("viewer.js")


def page(sc: Mapping[str, Any]) -> str:
    """The self-contained HTML page of a scene (three.js and the viewer inlined)."""
    bundle, viewer = _scripts()
    data = json.dumps(sc, separators=(",", ":")).replace("</", "<\\/")
    name = html.escape(str(sc.get("name", "")))
    shape = {"box": "equivalent boxes", "ellipsoid": "equivalent ellipsoids"}[
        sc.get("shape", "box")]
    notes = "".join(f"<div class='jv-help jv-note'>{html.escape(n)}</div>"
                    for n in sc.get("notes", []))
    help_ = (f"<div class='jv-help'>{name}: bodies as {shape} (same mass and principal "
             "inertia, at the centre of mass) or meshes; triads: body frames (x red, y green, "
             "z blue), fainter ones the joint frames; purple lines: spring-dampers"
             + ("; dark blue lines: elastic bodies through their nodes" if sc.get("elastic")
                else "") + ". Drag to orbit, wheel to zoom, right-drag to pan.</div>")
    speeds = "".join(f"<option value='{s}'{' selected' if s == '1' else ''}>{s}×</option>"
                     for s in ("0.1", "0.25", "0.5", "1", "2", "4"))
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            "<meta name='viewport' content='width=device-width, initial-scale=1'>"
            f"<title>{name} — jourdain 3-D view</title><style>{_PAGE_CSS}</style></head><body>"
            "<div id='jourdain-view'><div class='jv-canvas'></div><div class='jv-bar'>"
            "<button class='jv-play' type='button'>▶ play</button>"
            "<input class='jv-slider' type='range' aria-label='time'>"
            "<span class='jv-time'></span><label>speed <select class='jv-speed'>"
            f"{speeds}</select></label></div>{help_}{notes}</div>"
            f"<script type='application/json' id='jourdain-scene'>{data}</script>"
            f"<script>{bundle}</script><script>{viewer}</script></body></html>")


def embed(page_html: str, height: int = 480) -> str:
    """The page in an ``<iframe srcdoc>`` (sandboxed: its scripts run apart from the page that
    embeds it, which itself runs none)."""
    return (f"<iframe class='jourdain-view' srcdoc=\"{html.escape(page_html, quote=True)}\" "
            f"sandbox='allow-scripts' title='3-D view' style='width:100%;height:{int(height)}px;"
            "border:1px solid #ccc'></iframe>")


def at_rest(system: Any, y: Any = None, parameters: Any = None) -> Results:
    """One sample at rest of ``system`` at the configuration ``y`` (the tree's coordinates, in
    order or by name; default all zero) as :class:`Results`: what :func:`view` draws of a
    system. A closed system's configuration is assembled onto Φ = 0 (the independent
    coordinates held, :meth:`jourdain.System.evaluate`): the mechanism drawn closed."""
    from ...simulation.results import Results

    names = system.coordinate_names
    if y is None:
        y0 = np.zeros(system.f)
    elif hasattr(y, "items"):
        unknown = [k for k in y if str(k) not in names]
        if unknown:
            raise ModelError(f"3-D view: {', '.join(map(str, unknown))} not a coordinate of "
                             f"{system.name!r}; coordinates are {', '.join(names)}")
        given = {str(k): float(v) for k, v in y.items()}
        y0 = np.array([given.get(c, 0.0) for c in names])
    else:
        y0 = np.asarray(y, float).reshape(-1)
        if y0.size != system.f:
            raise ModelError(f"3-D view: y has {y0.size} values, {system.name!r} has "
                             f"{system.f} coordinates")
    values = dict(system.parameter_values)
    values.update(parameters or {})
    if system.closing:  # onto the manifold; the bodies then move as the tree's at this y
        try:
            y0 = np.asarray(system.evaluate(y0, np.zeros(system.f), parameters=values)["y"],
                            float)
        except JourdainError as exc:
            raise ModelError(f"3-D view: {system.name!r} could not be assembled at y = "
                             f"{y0.tolist()} ({exc}); give y=... near a configuration of "
                             "the closed mechanism") from exc
    z = np.zeros((1, system.f))
    return Results(system, np.zeros(1), y0[None, :], z, z, np.zeros((1, len(system.inputs))),
                   np.zeros(1), values, status="finished", message="a configuration at rest")


def view(results: Results | Any, *, visuals: Any = None,
         shape: str = "box", max_frames: int | None = None, height: int = 480,
         y: Any = None) -> View:
    """The 3-D view of a simulation's motion (``jd.view(results)``), or of a system at one
    configuration (``jd.view(system, y=...)``; a closed system's assembled onto its loops).
    A closed system's closing joints are drawn: red lines from each body's origin to its point
    of the joint, and a marker at the joint (the loops drawn closed).

    Parameters
    ----------
    results : the :class:`~jourdain.simulation.results.Results` of a simulation (with its
        system), or a :class:`jourdain.System`
    y : with a system: its configuration (the tree's coordinates, in order or by name;
        default zero); with results: not used
    visuals : per body name a list of :class:`Visual` (meshes, boxes, cylinders, spheres), or
        a URDF model's ``visuals`` (``view(res, visuals=model.visuals)``); default: the
        system's ``visuals`` attribute where it has one, else none
    shape : "box" or "ellipsoid", the equivalent solid drawn for a body without visuals
    max_frames : at most this many frames (default :data:`MAX_FRAMES`)
    height : pixels of the view in a notebook
    """
    from ...model.system import System

    if isinstance(results, System):  # a system: one configuration at rest
        results = at_rest(results, y)
    if visuals is None:
        visuals = getattr(_system(results), "visuals", None)
    sc = scene(results, visuals, shape, max_frames)
    return View(page(sc), tuple(sc["notes"]), int(height), sc)


def model_visuals(model: Any) -> Any:
    """The visuals of a model for the ``visuals`` hook: its ``visual_geometry`` (a URDF model's
    ``<visual>`` elements, every kind) where it has them, else its ``visuals``, else None; a
    model with rolling discs has its wheels drawn as cylinders (:func:`contact_visuals`)."""
    own = getattr(model, "visual_geometry", None) or getattr(model, "visuals", None)
    system = getattr(model, "system", None)
    if system is None or not getattr(system, "contacts", ()):
        return own
    wheels = contact_visuals(system, system.parameter_values)  # rolling discs as wheels
    return {**wheels, **dict(own or {})}


def report_section(results: Results, model: Any = None) -> str:
    """The report's "3-D view" section (HTML) for the results of ``model`` (a
    :class:`~jourdain.io.ModelFile`; its visuals are drawn where it has any, see
    :func:`model_visuals`); a note instead where the view cannot be drawn."""
    try:
        v = view(results, visuals=model_visuals(model))
    except JourdainError as exc:
        why = html.escape(f"3-D view not available: {exc}")
        return f"<h3>3-D view</h3><p class='note'>{why}</p>"
    return ("<h3>3-D view</h3>" + v._repr_html_()
            + "<p class='meta'>Bodies as boxes of the same mass and principal inertia (or their "
              "visuals), body and joint frames as triads, spring-dampers as lines; play, pause "
              "and drag the slider; drag to turn the view. Needs JavaScript and WebGL; the SVG "
              "animation above needs neither.</p>")

