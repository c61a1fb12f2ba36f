"""Coulomb friction in a joint, from the joint's reaction forces (METHOD.md §7: Schiehlen's
*general* systems, where applied forces depend on reactions).

:class:`JointFriction` is a force element on one coordinate ``c`` of a joint: the generalized
force

    Q_f = −μ · r · |N| · tanh(ċ / v_eps)

on ``c``, with ``N`` the joint's normal load taken from the reaction forces g: one component
(``normal="F_y"``: a block on a slide; ``|N|`` its absolute value) or the resultant
``√(Σ g_i²)`` of several (``normal=["F_x", "F_y"]``: the radial load of a pin whose axis is z).
``r`` (``radius``) is the lever arm of the friction force: 1 for a slide (Q_f is a force), the
pin's radius for a revolute joint (Q_f is the torque ``μ·r_pin·|F_radial|``). Like a
:class:`~jourdain.model.forces.GeneralizedForce` on ``c``, it acts as an equal and opposite
force (or torque) pair on the joint's two bodies, so it enters q̄^e, q, q̂ and the reactions.

**Coupling.** The reactions follow from ``N̂·g = k̂ − q̂`` (METHOD.md §4), and q̂ holds the
friction, which depends on g: ``g = g_0 − D·φ`` is affine in the friction forces φ (one column
of D per element: the reactions that a unit friction force causes, through the joint's pair
and the bodies' accelerations it drives). The forces solve ``φ = −μ·r·tanh(ċ/v_eps)·|N(g_0 −
D·φ)|``, piecewise linear for single components, solved by Newton's method (exact after the
signs of the normal components settle; a few steps), then ÿ from ``M·ÿ + k = q + q_f``.
Where ``μ·r·|∂N/∂φ| ≥ 1`` the friction force is not determined by the normal force it makes
(Painlevé's paradox): the evaluation stops with an error naming the elements. The numbers are
:mod:`jourdain.analysis.friction`'s (``System.evaluate``, ``System.simulate``/``jd.simulate``,
parameter studies' runs); ``System.linearize`` refuses the element, and what works on the
symbolic equations or on the model's own compiled ones (``equations_of_motion``,
``jd.evaluate_reactions``, ``jd.joint_reactions``) holds the other forces only.

**Stick–slip: regularized.** ``sign(ċ)`` is replaced by ``tanh(ċ/v_eps)`` (``v_eps``: a
parameter of the element, default ``1e-3`` in the coordinate's units per second). A joint at
rest under a tangential load ``F_t`` below ``μ·r·|N|`` does not stay exactly still: it creeps,
and in the steady creep the friction balances the load exactly, at the rate
``ċ = v_eps·atanh(F_t / (μ·r·|N|))`` (0.55·v_eps at half the limit), reached within a few
``m·v_eps/(μ·|N|)``. So "sticks" means: moves at most ``v_eps·atanh(F_t/(μ·r·|N|))``
per second. Above the limit there is no steady creep and the joint slides, with
``|Q_f| → μ·r·|N|`` once ``|ċ| ≫ v_eps`` (tanh(20) = 1 − 8e-18). A smaller ``v_eps`` sticks
better and makes the equations stiffer (time constant ``m·v_eps/(μ·|N|)``): use ``Radau``.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace
from typing import Any, TypeVar

import symengine as se

from ..errors import ModelError
from .expressions import Expr, as_expr, free_names

_F = TypeVar("_F")

#: Default regularization rate of :class:`JointFriction` (units of the coordinate per second)
V_EPS = 1e-3


@dataclass(frozen=True)
class JointFriction:
    """Coulomb friction in ``joint`` along (or about) its ``coordinate``, proportional to the
    joint's reaction force (see the module :mod:`jourdain.model.friction`).

    Parameters
    ----------
    name : str
        The element's name; its friction force (torque) along a simulated motion is the input
        column of that name in the results.
    joint : str
        The joint's name.
    mu : expression of the parameters
        The coefficient of friction (≥ 0).
    normal : str or list of str
        The reaction component(s) that press the joint's surfaces together: a suffix of the
        joint's reaction names (``"F_y"``; ``"T_x"`` for a moment) or a full name of any joint's
        (``"slide.F_y"``); several give their resultant ``√(Σ g_i²)``.
    coordinate : symbol or name, optional
        The coordinate of the joint the friction opposes (default: the joint's only one).
    radius : expression of the parameters, default 1
        Lever arm: the friction torque of a pin of radius r is ``μ·r·|F_radial|``.
    v_eps : expression of the parameters, default :data:`V_EPS`
        Rate of the regularization ``tanh(ċ/v_eps)`` of ``sign(ċ)`` (stick–slip).
    """

    name: str
    joint: str
    mu: Expr
    normal: tuple[str, ...]
    coordinate: se.Symbol | None = None
    radius: Expr = se.Integer(1)
    v_eps: Expr = se.Float(V_EPS)

    def __init__(self, name: str, joint: str, mu: object, normal: str | Sequence[str],
                 coordinate: object = None, radius: object = 1, v_eps: object = V_EPS) -> None:
        w = f'joint friction "{name}"'
        if not isinstance(name, str) or not name.isidentifier():
            raise ModelError(f"joint friction name {name!r} must be an identifier")
        if not isinstance(joint, str) or not joint.isidentifier():
            raise ModelError(f"{w}: joint {joint!r} must be a joint's name")
        items = [normal] if isinstance(normal, str) else list(normal)
        if not items:
            raise ModelError(f"{w}: normal names no reaction component")
        names = []
        for item in items:
            if not isinstance(item, str) or not all(p.isidentifier() for p in item.split(".")) \
                    or item.count(".") > 1:
                raise ModelError(f"{w}: normal {item!r} is not a reaction component's name "
                                 '("F_y", or "<joint>.F_y")')
            names.append(item if "." in item else f"{joint}.{item}")
        if len(set(names)) != len(names):
            raise ModelError(f"{w}: normal names a component twice: {names}")
        c = None if coordinate is None else as_expr(coordinate, f"{w} coordinate")
        if c is not None and not isinstance(c, se.Symbol):
            raise ModelError(f"{w}: coordinate {coordinate!r} must be a coordinate's name")
        set_ = object.__setattr__
        set_(self, "name", name)
        set_(self, "joint", joint)
        set_(self, "mu", as_expr(mu, f"{w} mu"))
        set_(self, "normal", tuple(names))
        set_(self, "coordinate", c)
        set_(self, "radius", as_expr(radius, f"{w} radius"))
        set_(self, "v_eps", as_expr(v_eps, f"{w} v_eps"))

    @property
    def expressions(self) -> list[Expr]:
        """The element's expressions (parameters only)."""
        return [self.mu, self.radius, self.v_eps]


def split_frictions(forces: Sequence[_F]) -> tuple[list[_F], list[JointFriction]]:
    """The force elements given to a System: the others, and the joint frictions."""
    return ([f for f in forces if not isinstance(f, JointFriction)],
            [f for f in forces if isinstance(f, JointFriction)])


def check_frictions(system: Any, items: Sequence[JointFriction]
                    ) -> tuple[JointFriction, ...]:
    """The joint frictions of ``system`` (a :class:`jourdain.model.System` being built),
    checked (names, joints, coordinates, parameters) and with their coordinates resolved; a
    ModelError naming the element otherwise. The reaction components named by ``normal`` are
    checked when the reactions are formed (numbers)."""
    if not items:
        return ()
    if system.is_closed:
        raise ModelError(f'joint friction "{items[0].name}": friction from reaction forces is '
                         "available for trees (no closing joints or contacts) only")
    joints = {b.joint.name: b.joint for b in system.bodies}
    params = {k for k, _ in system.parameters}
    taken = {*system.coordinate_names, *(f"{c}_d" for c in system.coordinate_names), *params,
             *system.input_names, *(n for q in system.quantities for n in q.symbol_names)}
    names = {f.name for f in system.forces}
    out = []
    for fr in items:
        w = f'joint friction "{fr.name}"'
        if fr.name in names:
            raise ModelError(f'duplicate force name "{fr.name}"')
        names.add(fr.name)
        if fr.name in taken:
            raise ModelError(f"{w}: its name is also a coordinate, rate, parameter, input or "
                             "quantity; the friction force is an input of that name in a "
                             "simulation's results: choose another name")
        joint = joints.get(fr.joint)
        if joint is None:
            raise ModelError(f'{w}: unknown joint "{fr.joint}"; joints are '
                             f"{', '.join(joints)}")
        own = [str(c) for c in joint.coordinates]
        if fr.coordinate is None:
            if len(own) != 1:
                raise ModelError(f'{w}: joint "{fr.joint}" has {len(own)} coordinates '
                                 f"({', '.join(own) or 'none'}); name the one the friction "
                                 "opposes with coordinate=")
            c = joint.coordinates[0]
        elif str(fr.coordinate) in own:
            c = fr.coordinate
        else:
            raise ModelError(f'{w}: "{fr.coordinate}" is not a coordinate of joint '
                             f'"{fr.joint}" ({", ".join(own) or "it has none"})')
        bad = free_names(fr.expressions) - params
        if bad:
            raise ModelError(f"{w}: mu, radius and v_eps may use parameters only, not "
                             f"{', '.join(sorted(bad))}")
        for key, e, strict in (("mu", fr.mu, False), ("radius", fr.radius, True),
                               ("v_eps", fr.v_eps, True)):
            if e.is_Number and (float(e) < 0 or strict and float(e) == 0):
                raise ModelError(f"{w}: {key} = {e} must be {'positive' if strict else '≥ 0'}")
        out.append(replace(fr, coordinate=c) if fr.coordinate is None else fr)
    return tuple(out)
