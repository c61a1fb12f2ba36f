"""Reading ``[bodies.<name>]``: mass data, shapes and joints (types, axes, steps,
orientations, constrained directions).
"""

from __future__ import annotations

from typing import Any

import symengine as se

from ...errors import ModelError
from ...model import (
    WORLD,
    Body,
    Cylindrical,
    Fixed,
    Free,
    General,
    Planar,
    Prismatic,
    Revolute,
    Rot,
    Spherical,
    Trans,
    Universal,
    box,
    cylinder,
    disc,
    rod,
)
from ...model.bodies import mass_data_problem, planar_inertia
from ...model.forces import _axes
from ...model.joints import orientation_problem
from ..toml_positions import Path, line_of
from .elastic import _Elastic
from .errors import ModelFileError, _type_name
from .schema import _JOINT_COMMON, _JOINT_KEYS, _SHAPES

#: the planar inertia: the moment about the plane's normal alone (jourdain.planar_inertia)
_PLANAR = {"planar": {"moment", "axis"}}


class _Bodies(_Elastic):
    # --- bodies ---------------------------------------------------------------------------
    def read_bodies(self, data: dict) -> list[Body]:
        path: Path = ("bodies",)
        if "bodies" not in data:
            raise self.missing("missing table [bodies.<name>] (at least one body)")
        tbl = self.table(data["bodies"], path, what="tables [bodies.<name>]")
        if not tbl:
            raise self.fail(path, "the model needs at least one body")
        for bname in tbl:
            self.name(bname, (*path, bname), "body")
            if bname == WORLD:
                raise self.fail((*path, bname), '"world" is the inertial frame, not a body name')
        self.body_names = list(tbl)
        made_by = self.attachment_names(tbl)
        self.body_names += list(made_by)
        bodies = [self.read_body(bname, spec) for bname, spec in tbl.items()]
        parents = {b.name: b.parent for b in bodies}
        parents.update({frame: body for frame, body in made_by.items()})
        for b in bodies:
            seen = [b.name]
            while parents.get(seen[-1], WORLD) != WORLD:
                nxt = parents[seen[-1]]
                if nxt in seen:
                    chain = " → ".join([*seen[seen.index(nxt):], nxt])
                    raise self.fail((*path, b.name, "parent"), f"the parents form a cycle "
                                    f"({chain}); every chain of parents must end at \"world\"")
                seen.append(nxt)
        # the bodies keep the file's order (the rows of the equations follow it), so a child
        # written before its parent is an error here as in the Python API
        position = {name: k for k, name in enumerate(tbl)}
        position.update({frame: position[body] for frame, body in made_by.items()})
        for k, b in enumerate(bodies):
            if b.parent != WORLD and position[b.parent] > k:
                line = line_of(self.lines, (*path, b.parent))
                at = f", line {line}" if line else ""
                raise self.fail((*path, b.name, "parent"),
                                f'body "{b.name}" (position {k + 1}) comes before its parent '
                                f'"{b.parent}" (position {position[b.parent] + 1}{at}): list '
                                "parents before their children")
        return bodies

    def read_body(self, bname: str, spec: object) -> Body:
        p: Path = ("bodies", bname)
        spec = self.table(spec, p, {"parent", "joint", "mass", "com", "inertia", "description",
                                    "elastic"})
        parent = self.string(self.require(spec, "parent", p), (*p, "parent"))
        if parent != WORLD and parent not in self.body_names:
            others = [b for b in self.body_names if b != bname]  # a body is not its own parent
            raise self.fail((*p, "parent"), f'unknown parent "{parent}"'
                            f'{self.suggest(parent, others)}; expected "world"'
                            + (f" or one of the bodies {', '.join(others)}" if others else ""))
        if parent == bname:
            raise self.fail((*p, "parent"), "a body cannot be its own parent")
        if "elastic" in spec:
            joint = self.joint(self.require(spec, "joint", p), (*p, "joint"), bname)
            if "description" in spec:
                self.descriptions[bname] = self.string(spec["description"], (*p, "description"))
            return self.read_elastic(bname, spec, parent, joint)
        params = set(self.params)
        ctx = "mass data (parameters only)"
        mass = self.expr(self.require(spec, "mass", p), (*p, "mass"), params, ctx)
        com = self.vector(spec.get("com", [0, 0, 0]), (*p, "com"), params, ctx)
        inertia = self.inertia(self.require(spec, "inertia", p), (*p, "inertia"), mass, params,
                               ctx)
        joint = self.joint(self.require(spec, "joint", p), (*p, "joint"), bname)
        if "description" in spec:
            self.descriptions[bname] = self.string(spec["description"], (*p, "description"))
        try:
            body = Body(bname, parent, joint, mass=mass, com=com, inertia=inertia)
        except ModelError as exc:
            raise self.fail((*p, "inertia") if "inertia" in str(exc) else p, str(exc)) from None
        problem = mass_data_problem(body, self.params)
        if problem:
            key, why = problem
            value = {"mass": mass, "com": None, "inertia": None}[key]
            if value is not None and value.is_Symbol and str(value) in self.params:
                # the mass is a parameter: its value is what is wrong, so say it at its line
                raise self.fail(("parameters", str(value)),
                                f'{why} (the mass of body "{bname}" is this parameter)')
            raise self.fail((*p, key), why)
        return body

    def inertia(self, value: object, path: Path, mass: se.Basic, params: set[str],
                ctx: str) -> Any:
        if isinstance(value, str):
            if value == "point":
                return [0, 0, 0]
            raise self.fail(path, f'expected "point", [Ixx, Iyy, Izz], a 3x3 matrix or a shape '
                            f"table such as {{ rod = {{ length = \"l\", axis = \"x\" }} }}, got "
                            f'"{value}"')
        if isinstance(value, list):
            if value and isinstance(value[0], list):
                return self.matrix3(value, path, params, ctx)
            if len(value) != 3:
                raise self.fail(path, f"expected the 3 principal moments [Ixx, Iyy, Izz] or a "
                                f"3x3 matrix, got {len(value)} entries")
            return list(self.vector(value, path, params, ctx))
        if isinstance(value, dict):
            if len(value) != 1:
                raise self.fail(path, "a shape table has exactly one key: point, rod, disc, "
                                "cylinder, box or planar")
            shape, args = next(iter(value.items()))
            sp = (*path, shape)
            shapes = {**_SHAPES, **_PLANAR}
            if shape not in shapes:
                raise self.fail(sp, f'unknown shape "{shape}"{self.suggest(shape, list(shapes))}'
                                f"; expected one of {', '.join(shapes)}")
            args = self.table(args, sp, shapes[shape] | {"mass"})
            m = self.expr(args["mass"], (*sp, "mass"), params, ctx) if "mass" in args else mass

            def get(k: str) -> se.Basic:
                return self.expr(self.require(args, k, sp), (*sp, k), params, ctx)

            def ax(default: str) -> str:
                a = args.get("axis", default)
                if a not in ("x", "y", "z"):
                    raise self.fail((*sp, "axis"), f'expected one of x, y, z, got '
                                    f"{_type_name(a)}")
                return str(a)

            if shape == "point":
                return [0, 0, 0]
            if shape == "planar":
                return planar_inertia(get("moment"), ax("z"))
            if shape == "rod":
                return rod(m, get("length"), ax("x"))
            if shape == "disc":
                return disc(m, get("radius"), ax("z"))
            if shape == "cylinder":
                return cylinder(m, get("radius"), get("length"), ax("z"))
            return box(m, get("a"), get("b"), get("c"))
        raise self.fail(path, f"expected an inertia (see docs/model-format.md), got "
                        f"{_type_name(value)}")

    # --- joints ---------------------------------------------------------------------------
    def joint(self, value: object, p: Path, bname: str) -> Any:
        spec = self.table(value, p, what='a joint table such as { type = "revolute", '
                          'coordinate = "phi", axis = "z" }')
        jtype = self.kind(spec, p, _JOINT_KEYS, "joint", lower=True)
        self.table(spec, p, _JOINT_KEYS[jtype] | _JOINT_COMMON)
        jname = self.name(spec.get("name", bname), (*p, "name"), "joint")
        if jname in self.joint_of_body.values():
            other = next(b for b, j in self.joint_of_body.items() if j == jname)
            raise self.fail((*p, "name"), f'joint name "{jname}" is already used by body '
                            f'"{other}"')
        self.joint_of_body[bname] = jname
        params = set(self.params)
        kin = set(self.coords) | params | {"t"}
        ctx_const = "joint positions and orientations (parameters only)"
        position = self.vector(spec.get("position", [0, 0, 0]), (*p, "position"), params,
                               ctx_const)
        orientation = None
        if "orientation" in spec:
            orientation = self.orientation(spec["orientation"], (*p, "orientation"), params,
                                           ctx_const)
            if not isinstance(orientation, list):  # a list of rotations is one by construction
                why = orientation_problem(orientation, self.params)
                if why:
                    raise self.fail((*p, "orientation"), f'the orientation of joint "{jname}" '
                                    f"{why}")
        kw = {"position": position, "orientation": orientation}

        def coord(key: str) -> se.Symbol:
            v = self.require(spec, key, p)
            return se.Symbol(self.coordinate(v, (*p, key)))

        def coords(n: int) -> list[se.Symbol]:
            v = self.require(spec, "coordinates", p)
            if not isinstance(v, list) or len(v) != n:
                raise self.fail((*p, "coordinates"), f"a {jtype} joint needs an array of {n} "
                                f"coordinates, got {_type_name(v)}")
            return [se.Symbol(self.coordinate(c, (*p, "coordinates", i)))
                    for i, c in enumerate(v)]

        def sequence(default: str) -> str:
            s = self.string(spec.get("sequence", default), (*p, "sequence")).lower()
            ok = {"xyz", "xzy", "yxz", "yzx", "zxy", "zyx", "zxz", "xyx", "xzx", "yxy", "yzy",
                  "zyz"}
            if s not in ok:
                raise self.fail((*p, "sequence"), f'expected a rotation sequence such as "xyz" '
                                f'or "zxz", got "{s}"')
            return s

        ctx_kin = "joints (coordinates, parameters and t)"
        try:
            if jtype == "revolute":
                return Revolute(jname, coord("coordinate"),
                                self.axis(spec.get("axis", "z"), (*p, "axis"), params, ctx_const),
                                **kw)
            if jtype == "prismatic":
                return Prismatic(jname, coord("coordinate"),
                                 self.axis(spec.get("axis", "x"), (*p, "axis"), params,
                                           ctx_const), **kw)
            if jtype == "cylindrical":
                return Cylindrical(jname, coords(2), self.axis(spec.get("axis", "z"),
                                                               (*p, "axis"), params, ctx_const),
                                   **kw)
            if jtype == "universal":
                axes = spec.get("axes", ["x", "y"])
                if not isinstance(axes, list) or len(axes) != 2:
                    raise self.fail((*p, "axes"), f"expected an array of 2 axes, got "
                                    f"{_type_name(axes)}")
                ax = [self.axis(a, (*p, "axes", i), params, ctx_const)
                      for i, a in enumerate(axes)]
                return Universal(jname, coords(2), ax, **kw)
            if jtype == "spherical":
                return Spherical(jname, coords(3), sequence("xyz"), **kw)
            if jtype == "planar":
                normal = self.string(spec.get("normal", "z"), (*p, "normal"))
                if normal not in ("x", "y", "z"):
                    raise self.fail((*p, "normal"), f'expected one of x, y, z, got "{normal}"')
                return Planar(jname, coords(3), normal, **kw)
            if jtype == "free":
                return Free(jname, coords(6), sequence("xyz"), **kw)
            if jtype == "fixed":
                return Fixed(jname, **kw)
            steps = self.steps(self.require(spec, "steps", p), (*p, "steps"), kin, ctx_kin)
            driven = []
            if "coordinates" in spec:
                v = spec["coordinates"]
                if not isinstance(v, list):
                    raise self.fail((*p, "coordinates"), f"expected an array of coordinate "
                                    f"names, got {_type_name(v)}")
                driven = [se.Symbol(self.coordinate(c, (*p, "coordinates", i)))
                          for i, c in enumerate(v)]
            else:
                used = set().union(*(_free(s) for s in steps)) & set(self.coords)
                driven = [se.Symbol(c) for c in self.coords if c in used]
            constrained = None
            if "constrained" in spec:
                constrained = self.constrained(spec["constrained"], (*p, "constrained"), params)
            return General(jname, steps, coordinates=driven, constrained=constrained, **kw)
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(p, str(exc)) from None

    def constrained(self, value: object, path: Path, params: set[str]) -> list[Any]:
        """Constrained directions of a general joint: "F_x" … "T_z" or
        { name = "T_a", wrench = [F_x, F_y, F_z, T_x, T_y, T_z] } (child frame)."""
        if not isinstance(value, list):
            raise self.fail(path, f'expected an array of directions such as ["F_x", "T_y"], got '
                            f"{_type_name(value)}")
        out: list[Any] = []
        units = ("F_x", "F_y", "F_z", "T_x", "T_y", "T_z")
        for i, item in enumerate(value):
            ip = (*path, i)
            if isinstance(item, str):
                if item not in units:
                    raise self.fail(ip, f'expected one of {", ".join(units)} or a table '
                                    f'{{ name = "T_a", wrench = [...] }}, got "{item}"')
                out.append(item)
                continue
            tb = self.table(item, ip, {"name", "wrench"})
            nm = self.name(self.require(tb, "name", ip), (*ip, "name"), "direction")
            w = self.vector(self.require(tb, "wrench", ip), (*ip, "wrench"),
                            params | set(self.coords), "constrained directions (coordinates "
                            "and parameters)", n=6)
            out.append((nm, w))
        return out

    def coordinate(self, value: object, path: Path, drive: bool = True) -> str:
        s = self.string(value, path)
        if s not in self.coords:
            raise self.fail(path, f'"{s}" is not a declared coordinate'
                            f"{self.suggest(s, self.coords)}; coordinates are "
                            f"{', '.join(self.coords)}")
        if drive and path[0] == "bodies":
            other = self.driven.get(s)
            if other is not None and other != path[1]:
                raise self.fail(path, f'coordinate "{s}" is already driven by the joint of body '
                                f'"{other}"; each coordinate belongs to one joint')
            self.driven[s] = str(path[1])
        return s

    def orientation(self, value: object, path: Path, params: set[str], ctx: str) -> Any:
        if isinstance(value, list) and value and all(isinstance(r, dict) for r in value):
            rots = self.steps(value, path, params, ctx)
            if any(isinstance(s, Trans) for s in rots):
                raise self.fail(path, "an orientation is made of rotations only ({ rot = ..., "
                                "angle = ... })")
            return list(rots)
        return self.matrix3(value, path, params, ctx)

    def steps(self, value: object, path: Path, allowed: set[str], ctx: str) -> list[Rot | Trans]:
        if not isinstance(value, list) or not value:
            raise self.fail(path, f'expected an array of steps such as {{ rot = "z", angle = '
                            f'"phi" }} or {{ trans = "x", distance = "s" }}, got '
                            f"{_type_name(value)}")
        out: list[Rot | Trans] = []
        for i, st in enumerate(value):
            sp = (*path, i)
            st = self.table(st, sp, {"rot", "angle", "trans", "distance"},
                            what='a step table such as { rot = "z", angle = "phi" }')
            if "rot" in st:
                if "trans" in st or "distance" in st:
                    raise self.fail(sp, "a step is either a rotation (rot, angle) or a "
                                    "translation (trans, distance), not both")
                ax = self.axis(st["rot"], (*sp, "rot"), set(self.params), ctx)
                angle = self.expr(self.require(st, "angle", sp), (*sp, "angle"), allowed, ctx)
                out.append(Rot(ax, angle))
            elif "trans" in st:
                if "angle" in st:
                    raise self.fail((*sp, "angle"), "a translation step has a distance, not an "
                                    "angle")
                tr = st["trans"]
                if isinstance(tr, list) and "distance" not in st:
                    out.append(Trans(vector=self.vector(tr, (*sp, "trans"), allowed, ctx)))
                else:
                    ax = self.axis(tr, (*sp, "trans"), set(self.params), ctx)
                    dist = self.expr(self.require(st, "distance", sp), (*sp, "distance"),
                                     allowed, ctx)
                    out.append(Trans(ax, dist))
            else:
                raise self.fail(sp, 'a step needs "rot" (with "angle") or "trans" (with '
                                '"distance", or a 3-vector)')
        return out


def _product(rotations: list) -> Any:
    """The rotation matrix of a list of Rot steps."""
    return _axes(rotations, "axes")


def _free(step: Rot | Trans) -> set[str]:
    exprs = [step.angle] if isinstance(step, Rot) else list(step.vector)
    return {str(s) for e in exprs for s in e.free_symbols}


