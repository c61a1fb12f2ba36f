"""Model-file sections of general systems: ``[contacts.<name>]`` and ``[speeds]``.

Read by :mod:`jourdain.io.modelfile` (which calls :func:`read_contacts` with its loader, so
errors name the file, line and key like every other section). Syntax (``docs/model-format.md``,
"Contacts and speeds")::

    [contacts.rear]          # a wheel rolling without slip
    type = "rolling_disc"
    body = "R"
    radius = "rR"
    axis = "y"               # the axle, body frame
    normal = "-z"            # the ground's normal, to the bodies' side (default "z")

    [contacts.edge]          # a knife edge / skate
    type = "knife_edge"
    body = "sleigh"
    point = ["a", 0, 0]
    direction = "x"

    [contacts.c]             # velocity rows, linear in the rates <coordinate>_d
    type = "velocity"
    expressions = ["x_d - r*theta_d"]

    [speeds]                 # the generalized velocities: coordinates' rates ...
    coordinates = ["phi", "delta", "thetaR"]
    # ... or definitions:  u = "cos(psi)*x_d + sin(psi)*y_d"

Independent coordinates of the holonomic rows (a wheel touching the ground) are chosen by
``[loops] independent`` as for closing joints.
"""

from __future__ import annotations

from typing import Any, TypeVar

from ..errors import ModelError
from ..model import System
from ..model.contacts import KnifeEdge, RollingDisc, VelocityConstraint

_S = TypeVar("_S", bound=System)

#: keys of a [contacts.<name>] table, by its type
_KEYS: dict[str, set[str]] = {
    "rolling_disc": {"body", "radius", "axis", "center", "normal", "tube_radius"},
    "knife_edge": {"body", "point", "direction", "normal"},
    "velocity": {"expressions"},
}


def _contact(loader: Any, name: str, spec: Any, bodies: list[str]) -> Any:
    p = ("contacts", name)
    spec = loader.table(spec, p, what=f"a table [contacts.{name}]")
    kind = loader.kind(spec, p, _KEYS, "contact")
    loader.table(spec, p, _KEYS[kind] | {"type"})
    params = set(loader.params)
    if kind == "velocity":
        exprs = loader.require(spec, "expressions", p)
        if not isinstance(exprs, list) or not exprs:
            raise loader.fail((*p, "expressions"), "expected a non-empty array of expression "
                              "strings")
        coords = list(loader.coords)
        allowed = params | set(coords) | {f"{c}_d" for c in coords} | {"t"}
        return VelocityConstraint(name, [
            loader.expr(e, (*p, "expressions", i), allowed, "velocity constraints "
                        "(coordinates, their rates <name>_d, t and parameters)")
            for i, e in enumerate(exprs)])
    body = loader.string(loader.require(spec, "body", p), (*p, "body"))
    if body not in bodies:
        raise loader.fail((*p, "body"), f'unknown body "{body}"{loader.suggest(body, bodies)}; '
                          f"bodies are {', '.join(bodies)}")
    kw: dict[str, Any] = {}
    if "normal" in spec:
        kw["normal"] = loader.string(spec["normal"], (*p, "normal"))
    if kind == "rolling_disc":
        radius = loader.expr(loader.require(spec, "radius", p), (*p, "radius"), params,
                             "a disc's radius (parameters)")
        if "axis" in spec:
            kw["axis"] = loader.axis(spec["axis"], (*p, "axis"), params,
                                     "a disc's axle (parameters)")
        if "center" in spec:
            kw["center"] = loader.vector(spec["center"], (*p, "center"), params,
                                         "a disc's centre (parameters)")
        if "tube_radius" in spec:
            kw["tube_radius"] = loader.expr(spec["tube_radius"], (*p, "tube_radius"), params,
                                            "a torus' tube radius (parameters)")
        return RollingDisc(name, body, radius, **kw)
    if "point" in spec:
        kw["point"] = loader.vector(spec["point"], (*p, "point"), params,
                                    "a knife edge's point (parameters)")
    if "direction" in spec:
        kw["direction"] = loader.axis(spec["direction"], (*p, "direction"), params,
                                      "a knife edge's direction (parameters)")
    return KnifeEdge(name, body, **kw)


def _speeds(loader: Any, data: dict) -> Any:
    p = ("speeds",)
    tbl = loader.table(data["speeds"], p)
    coords = list(loader.coords)
    if "coordinates" in tbl:
        if len(tbl) > 1:
            raise loader.fail(p, "[speeds] holds either coordinates = [...] or definitions "
                              "<name> = \"expression\", not both")
        v = tbl["coordinates"]
        if not isinstance(v, list) or not all(isinstance(c, str) for c in v):
            raise loader.fail((*p, "coordinates"), "expected an array of coordinate names")
        for c in v:
            if c not in coords:
                raise loader.fail((*p, "coordinates"), f'"{c}" is not a declared coordinate'
                                  f"{loader.suggest(c, coords)}")
        return list(v)
    allowed = set(loader.params) | set(coords) | {f"{c}_d" for c in coords} | {"t"}
    return {k: loader.expr(e, (*p, k), allowed, "speed definitions (coordinates, their rates "
                           "<name>_d, t and parameters)") for k, e in tbl.items()}


def read_contacts(loader: Any, data: dict, system: _S) -> _S:
    """``system`` with the file's contacts and speeds (itself without any).

    ``loader`` is :class:`jourdain.io.modelfile._Loader` (its typed accessors locate errors).
    """
    p = ("contacts",)
    tbl = loader.table(data.get("contacts", {}), p, what="tables [contacts.<name>]")
    if not tbl and "speeds" not in data:
        return system
    bodies = system.body_names
    contacts = []
    for name, spec in tbl.items():
        try:
            contacts.append(_contact(loader, name, spec, bodies))
        except ModelError as exc:
            raise loader.fail((*p, name), str(exc)) from None
    speeds = _speeds(loader, data) if "speeds" in data else None
    independent = system.independent
    loops = data.get("loops", {})
    if independent is None and isinstance(loops, dict) and "independent" in loops:
        independent = tuple(loops["independent"])
    try:
        return type(system)(system.coordinates, system.bodies, system.forces,
                            dict(system.parameters), system.inputs, dict(system.units),
                            system.name, closing=system.closing, independent=independent,
                            contacts=contacts, speeds=speeds)
    except ModelError as exc:
        raise loader.fail(("speeds",) if "speeds" in str(exc) else p, str(exc)) from None


__all__ = ["read_contacts"]
