"""Model-file sections of closed systems: ``[closing_joints.<name>]`` and ``[loops]``.

Read by :mod:`jourdain.io.modelfile` (which calls :func:`read_loops` with its loader, so the
errors name the file, line and key like every other section). The syntax is documented in
``docs/model-format.md`` (section "Closing joints and loops").
"""

from __future__ import annotations

from typing import Any, TypeVar

from ..errors import ModelError
from ..model import System
from ..model.closing import KINDS, ClosingJoint

_S = TypeVar("_S", bound=System)

#: keys of a [closing_joints.<name>] table, by its type
_KEYS: dict[str, set[str]] = {
    "revolute": {"body_a", "body_b", "point_a", "point_b", "axis", "axis_b"},
    "universal": {"body_a", "body_b", "point_a", "point_b", "axis", "axis_b"},
    "spherical": {"body_a", "body_b", "point_a", "point_b"},
    "prismatic": {"body_a", "body_b", "point_a", "point_b", "axis"},
    "point_on_line": {"body_a", "body_b", "point_a", "point_b", "axis"},
    "point_on_plane": {"body_a", "body_b", "point_a", "point_b", "axis"},
    "constraint": {"expressions"},
}


def read_loops(loader: Any, data: dict, system: _S) -> _S:
    """The tree ``system`` closed by the file's closing joints (itself without any).

    ``loader`` is :class:`jourdain.io.modelfile._Loader` (its typed accessors locate errors).
    """
    p = ("closing_joints",)
    tbl = loader.table(data.get("closing_joints", {}), p,
                       what="tables [closing_joints.<name>]")
    lp = ("loops",)
    loops = loader.table(data.get("loops", {}), lp, {"independent"})
    if not tbl:
        if loops and "contacts" not in data:
            raise loader.fail(lp, "[loops] without any [closing_joints.<name>] or "
                              "[contacts.<name>]")
        return system
    params = set(loader.params)
    bodies = ["world", *system.body_names]
    closing = []
    for name, spec in tbl.items():
        jp = (*p, name)
        spec = loader.table(spec, jp, what=f'a table [closing_joints.{name}]')
        kind = loader.kind(spec, jp, KINDS, "closing joint")
        loader.table(spec, jp, _KEYS[kind] | {"type"})
        kw: dict[str, Any] = {}
        if kind == "constraint":
            exprs = loader.require(spec, "expressions", jp)
            if not isinstance(exprs, list) or not exprs:
                raise loader.fail((*jp, "expressions"), "expected a non-empty array of "
                                  "expression strings")
            allowed = params | set(loader.coords) | {"t"}
            kw["expressions"] = [loader.expr(e, (*jp, "expressions", i), allowed,
                                             "constraint expressions (coordinates, t and "
                                             "parameters)")
                                 for i, e in enumerate(exprs)]
        else:
            for side in ("body_a", "body_b"):
                b = loader.string(loader.require(spec, side, jp), (*jp, side))
                if b not in bodies:
                    raise loader.fail((*jp, side), f'unknown body "{b}"'
                                      f"{loader.suggest(b, bodies)}; bodies are "
                                      f"{', '.join(bodies)}")
                kw[side] = b
            for key in ("point_a", "point_b"):
                if key in spec:
                    kw[key] = loader.vector(spec[key], (*jp, key), params,
                                            "closing joint points (parameters)")
            for key in ("axis", "axis_b"):
                if key in spec:
                    kw[key] = loader.axis(spec[key], (*jp, key), params,
                                          "closing joint axes (parameters)")
        try:
            closing.append(ClosingJoint(name, kind, **kw))
        except ModelError as exc:
            raise loader.fail(jp, str(exc)) from None
    independent = None
    if "independent" in loops:
        v = loops["independent"]
        if not isinstance(v, list) or not all(isinstance(c, str) for c in v):
            raise loader.fail((*lp, "independent"), "expected an array of coordinate names")
        for c in v:
            if c not in loader.coords:
                raise loader.fail((*lp, "independent"), f'"{c}" is not a declared coordinate'
                                  f"{loader.suggest(c, list(loader.coords))}")
        independent = tuple(v)
    try:
        return system.closed_by(closing, independent)
    except ModelError as exc:
        raise loader.fail(p, str(exc)) from None


__all__ = ["read_loops"]
