"""Reading ``[forces.<name>]`` and ``[quantities.<name>]``: force elements and the kinematic
quantities their laws use.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import symengine as se

from ...errors import ModelError
from ...model import (
    WORLD,
    Bushing,
    Force,
    GeneralizedForce,
    Gravity,
    JointFriction,
    RotationalSpringDamper,
    SpringDamper,
    Torque,
)
from ...model.forces import BUSHING_COMPONENTS
from ...model.friction import V_EPS
from ...model.joints import orientation_problem
from ...model.quantities import KINDS as QUANTITY_KINDS
from ...model.quantities import declare as declare_quantity
from ...model.quantities import quantity as make_quantity
from ..expressions import RESERVED_NAMES
from ..toml_positions import Path
from .bodies import _Bodies, _product
from .errors import ModelFileError, _type_name
from .schema import _FORCE_KEYS, _QUANTITY_KEYS_ONE, _QUANTITY_KEYS_TWO


class _Forces(_Bodies):
    # --- forces ---------------------------------------------------------------------------
    def read_forces(self, data: dict) -> list[Any]:
        path: Path = ("forces",)
        tbl = self.table(data.get("forces", {}), path, what="tables [forces.<name>]")
        out = []
        for fname, spec in tbl.items():
            out.append(self.force(fname, spec, (*path, fname)))
        return out

    def force(self, fname: str, spec: object, p: Path) -> Any:
        self.name(fname, p, "force")
        spec = self.table(spec, p, what='a force table with a "type"')
        ftype = self.kind(spec, p, _FORCE_KEYS, "force", lower=True)
        self.table(spec, p, _FORCE_KEYS[ftype] | {"type", "description"})
        rates = {f"{c}_d" for c in self.coords}
        allowed = (set(self.coords) | rates | set(self.params) | set(self.inputs) | {"t"}
                   | set(self.quantity_symbols))
        ctx = "forces (coordinates, rates, parameters, inputs, t and kinematic quantities)"
        params = set(self.params)
        pctx = "points (parameters only)"

        def body(key: str, world_ok: bool) -> str:
            b = self.string(self.require(spec, key, p), (*p, key))
            ok = self.body_names + ([WORLD] if world_ok else [])
            if b not in ok:
                raise self.fail((*p, key), f'unknown body "{b}"{self.suggest(b, ok)}; expected '
                                f"one of {', '.join(ok)}")
            return b

        def frame(key: str = "frame", default: object = WORLD) -> str:
            fr = self.string(spec.get(key, default), (*p, key))
            ok = [WORLD, *self.body_names]
            if fr not in ok:
                raise self.fail((*p, key), f'unknown frame "{fr}"; expected "world" or a '
                                "body name")
            return fr

        def e(key: str, default: object = None, names: set[str] = allowed,
              context: str = ctx) -> se.Basic:
            v = spec.get(key, default) if default is not None else self.require(spec, key, p)
            return self.expr(v, (*p, key), names, context)

        try:
            if ftype == "gravity":
                return Gravity(self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                           params | {"t"}, "gravity (parameters and t)"),
                               name=fname)
            if ftype == "force":
                return Force(fname, body("body", False),
                             self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                         allowed, ctx),
                             self.vector(spec.get("point", [0, 0, 0]), (*p, "point"), params,
                                         pctx), frame(),
                             point_frame=frame("point_frame", spec.get("body")))
            if ftype == "torque":
                return Torque(fname, body("body", False),
                              self.vector(self.require(spec, "vector", p), (*p, "vector"),
                                          allowed, ctx), frame())
            if ftype == "spring_damper":
                law = None
                if "law" in spec:
                    law = e("law", names=allowed | {"elongation", "elongation_d"},
                            context="a spring law (elongation, elongation_d, coordinates, "
                            "rates, parameters, inputs and t)")
                return SpringDamper(
                    fname, body("body_a", True),
                    self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params, pctx),
                    body("body_b", True),
                    self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"), params, pctx),
                    stiffness=e("stiffness", 0), damping=e("damping", 0),
                    rest_length=e("rest_length", 0), law=law)
            if ftype == "bushing":
                return self.bushing(fname, spec, p, body, e, params, pctx, allowed)
            if ftype == "joint_friction":
                return self.joint_friction(fname, spec, p)
            defl = allowed | {"deflection", "deflection_d"}
            vctx = ("a generalized force (deflection, deflection_d, coordinates, rates, "
                    "parameters, inputs, t and kinematic quantities)")
            if ftype == "generalized":
                c = self.generalized_coordinate(spec, p)
                return GeneralizedForce(fname, c, e("value", names=defl, context=vctx))
            c = self.generalized_coordinate(spec, p)
            return RotationalSpringDamper(fname, c, stiffness=e("stiffness", 0),
                                          damping=e("damping", 0),
                                          rest_angle=e("rest_angle", 0, params | {"t"},
                                                       "a rest angle (parameters and t)"))
        except ModelFileError:
            raise
        except ModelError as exc:
            raise self.fail(p, str(exc)) from None

    def generalized_coordinate(self, spec: dict, p: Path) -> se.Basic:
        """A generalized force's ``coordinate``: a coordinate's name, or an expression of the
        coordinates, the parameters, t and the position quantities (``"phi2 - phi1"``)."""
        value = self.require(spec, "coordinate", p)
        if isinstance(value, str) and value.strip() in self.coords:
            return se.Symbol(self.coordinate(value.strip(), (*p, "coordinate")))
        names = (set(self.coords) | set(self.params) | {"t"}
                 | {n for n, s in self.quantity_symbols.items()
                    if not s.quantity.uses_rates})
        e = self.expr(value, (*p, "coordinate"), names,
                      "a generalized coordinate (coordinates, parameters, t and position "
                      "quantities)")
        if not {str(x) for x in e.free_symbols} & (set(self.coords)
                                                   | set(self.quantity_symbols)):
            raise self.fail((*p, "coordinate"), f'"{value}" depends on no coordinate')
        return e

    def joint_friction(self, fname: str, spec: dict, p: Path) -> JointFriction:
        """A ``type = "joint_friction"`` force table: Coulomb friction in a joint from its
        reaction forces (:mod:`jourdain.model.friction`)."""
        joints = list(self.joint_of_body.values())
        joint = self.string(self.require(spec, "joint", p), (*p, "joint"))
        if joint not in joints:
            raise self.fail((*p, "joint"), f'unknown joint "{joint}"'
                            f"{self.suggest(joint, joints)}; joints are {', '.join(joints)}")
        normal = self.require(spec, "normal", p)
        items = normal if isinstance(normal, list) else [normal]
        if not items:
            raise self.fail((*p, "normal"), "expected a reaction component or a list of them")
        names = [self.string(v, (*p, "normal", i) if isinstance(normal, list) else
                             (*p, "normal")) for i, v in enumerate(items)]
        coordinate = None
        if "coordinate" in spec:
            coordinate = self.coordinate(spec["coordinate"], (*p, "coordinate"), drive=False)
        params = set(self.params)
        ctx = "joint friction (parameters only)"
        return JointFriction(
            fname, joint, self.expr(self.require(spec, "mu", p), (*p, "mu"), params, ctx),
            names, coordinate,
            radius=self.expr(spec.get("radius", 1), (*p, "radius"), params, ctx),
            v_eps=self.expr(spec.get("v_eps", V_EPS), (*p, "v_eps"), params, ctx))

    def bushing(self, fname: str, spec: dict, p: Path, body: Callable, e: Callable,
                params: set[str], pctx: str, allowed: set[str]) -> Bushing:
        """A ``type = "bushing"`` force table."""
        fr = spec.get("frame")
        if fr is not None:
            fr = self.string(fr, (*p, "frame"))
        a, b = body("body_a", True), body("body_b", True)
        if fr is not None and fr not in (a, b):
            raise self.fail((*p, "frame"), f'frame "{fr}" must be one of the bushing\'s bodies, '
                            f'"{a}" or "{b}"')

        def six(key: str, matrix: bool) -> object:
            v = spec.get(key, 0)
            kp = (*p, key)
            if v == 0 and not isinstance(v, bool) and matrix:
                return 0
            if not isinstance(v, list) or len(v) != 6:
                what = "a 6-vector (the diagonal) or 6 rows of 6" if matrix else "a 6-vector"
                raise self.fail(kp, f"expected {what}, got {_type_name(v)}")
            if matrix and all(isinstance(r, list) for r in v):
                for i, r in enumerate(v):
                    if len(r) != 6:
                        raise self.fail((*kp, i), f"expected a row of 6 entries, got {len(r)}")
                return [[self.expr(x, (*kp, i, j), allowed, ctx) for j, x in enumerate(r)]
                        for i, r in enumerate(v)]
            return [self.expr(x, (*kp, i), allowed, ctx) for i, x in enumerate(v)]

        ctx = "a bushing (coordinates, rates, parameters, inputs, t and kinematic quantities)"
        axes = {}
        for key in ("axes_a", "axes_b"):
            if key in spec:
                axes[key] = self.orientation(spec[key], (*p, key), params,
                                             "a bushing's axes (parameters only)")
                why = orientation_problem(
                    axes[key] if not isinstance(axes[key], list) else _product(axes[key]),
                    self.params)
                if why:
                    raise self.fail((*p, key), f"the axes {why}")
        laws = {}
        if "laws" in spec:
            tbl = self.table(spec["laws"], (*p, "laws"), set(BUSHING_COMPONENTS),
                             what="a table of laws by component (x, y, z, rx, ry, rz)")
            for comp, law in tbl.items():
                laws[comp] = self.expr(law, (*p, "laws", comp),
                                       allowed | {"deflection", "deflection_d"},
                                       "a bushing law (deflection, deflection_d, coordinates, "
                                       "rates, parameters, inputs, t and kinematic quantities)")
        return Bushing(fname, a, b,
                       self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params, pctx),
                       self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"), params, pctx),
                       stiffness=six("stiffness", True), damping=six("damping", True),
                       preload=six("preload", False) if "preload" in spec else (0,) * 6,
                       frame=fr, laws=laws, **axes)

    # --- kinematic quantities -------------------------------------------------------------
    def read_quantities(self, data: dict) -> None:
        """[quantities.<name>]: kinematic quantities for force laws (symbols ``<name>_x``,
        ``<name>_y``, ``<name>_z`` of a vector, ``<name>`` of a distance)."""
        path: Path = ("quantities",)
        tbl = self.table(data.get("quantities", {}), path, what="tables [quantities.<name>]")
        taken = {*self.coords, *(f"{c}_d" for c in self.coords),
                 *(f"{c}_dd" for c in self.coords), *self.params, *self.inputs}
        params = set(self.params)
        pctx = "points (parameters only)"
        for qname, spec in tbl.items():
            p: Path = (*path, qname)
            self.name(qname, p, "quantity")
            spec = self.table(spec, p, what='a quantity table with a "type"')
            kind = self.kind(spec, p, QUANTITY_KINDS, "quantity", lower=True)
            two = QUANTITY_KINDS[kind][1]
            self.table(spec, p, (_QUANTITY_KEYS_TWO if two else _QUANTITY_KEYS_ONE)
                       | {"type", "description"})
            ok = [WORLD, *self.body_names]

            def frame_name(key: str, default: str | None, spec: dict = spec, p: Path = p,
                           ok: list = ok) -> str:
                if default is None:
                    v = self.string(self.require(spec, key, p), (*p, key))
                else:
                    v = self.string(spec.get(key, default), (*p, key))
                if v not in ok:
                    raise self.fail((*p, key), f'unknown body "{v}"{self.suggest(v, ok)}; '
                                    f"expected one of {', '.join(ok)}")
                return v

            try:
                if two:
                    qa = frame_name("body_a", None)
                    q = make_quantity(
                        kind, qname, qa,
                        self.vector(spec.get("point_a", [0, 0, 0]), (*p, "point_a"), params,
                                    pctx),
                        frame=frame_name("frame", WORLD), body_b=frame_name("body_b", None),
                        point_b=self.vector(spec.get("point_b", [0, 0, 0]), (*p, "point_b"),
                                            params, pctx))
                else:
                    qb = frame_name("body", None)
                    default_frame = qb if kind == "angular_velocity" else WORLD
                    if kind == "angular_velocity" and ("point" in spec or "point_frame" in spec):
                        raise self.fail(p, "an angular velocity has no point")
                    q = make_quantity(
                        kind, qname, qb,
                        self.vector(spec.get("point", [0, 0, 0]), (*p, "point"), params, pctx),
                        frame=frame_name("frame", default_frame),
                        point_frame=frame_name("point_frame", qb))
            except ModelFileError:
                raise
            except ModelError as exc:
                raise self.fail(p, str(exc)) from None
            for sym in declare_quantity(q):
                n = str(sym)
                if n in taken or n in RESERVED_NAMES:
                    raise self.fail(p, f'its symbol "{n}" is already a declared or reserved name; '
                                    "choose another name for the quantity")
                taken.add(n)
                self.quantity_symbols[n] = sym
            if "description" in spec:
                self.descriptions[qname] = self.string(spec["description"], (*p, "description"))


