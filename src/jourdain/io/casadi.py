"""The equations of motion as CasADi functions with exact derivatives (the extra
``jourdain[casadi]``): :func:`to_casadi`.

The expression graph of M, k, q (:func:`jourdain.stages.projection.projection`) is translated
node by node into CasADi's scalar graph (SX): every distinct SymEngine node once, children
before parents (:meth:`jourdain.graph.Graph.merged`, the view the C generator walks), so the
sharing of the symbolic projection carries over and CasADi differentiates the result exactly
(its algorithmic differentiation, forward and reverse, to any order). Nothing is printed and
read back: each node becomes the CasADi operation of its kind.

The functions take the parameters as an input ``p`` (in the order of
``system.parameter_symbols``), so that a parameter may be a decision variable of an optimal
control or estimation problem; :attr:`CasadiDynamics.p` holds the model's values (with the
overrides of ``parameters=``) to pass where they are fixed. The time ``t`` is the last input
of each function (only a rheonomic model's equations use it; a call by name leaves it 0).

Floor: builders and whole models (io); reads the stages and the parameter vector of the
numeric layer. CasADi is imported when :func:`to_casadi` is called
(:func:`jourdain.extras.require`), so that jourdain imports without it.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping, Sequence
from dataclasses import dataclass
from fractions import Fraction
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, refuse_closed
from ..extras import require
from ..graph import Graph
from ..numeric.state import parameter_vector
from ..stages.kinematics import kinematics
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection

if TYPE_CHECKING:
    from ..model.system import System

#: what the casadi extra is needed for, in the message of a missing package
CASADI = "The CasADi bridge (jourdain.to_casadi)"


@dataclass(frozen=True)
class CasadiDynamics:
    """The equations of motion ``M(y,t)·ÿ + k(y,ẏ,t) = q(y,ẏ,t,u)`` of a system as
    ``casadi.Function`` objects over CasADi's scalar graph (SX), made by :func:`to_casadi`.

    Each function takes ``y``, ``yd`` (f), ``u`` (the inputs, ``system.inputs``), ``p`` (the
    parameters, in the order of :attr:`parameters`) and ``t`` (a scalar), as column vectors;
    CasADi's own derivatives of them are exact (``casadi.jacobian``, ``Function.jacobian``,
    inside ``casadi.Opti`` and ``nlpsol``).

    Attributes
    ----------
    forward : casadi.Function
        ``forward(y, yd, u, p, t) -> ydd``: ÿ = M⁻¹(q − k), by an LDLᵀ factorization of M
        written out in SX (no pivoting: M is symmetric positive definite). The solve adds
        about f³/2 operations to the graph of M, k, q (measured: 213 nodes at f = 6, 5 190 at
        f = 20, 36 780 at f = 40), and each derivative CasADi forms costs a small multiple of
        that: negligible for the few coordinates of a trajectory optimization, the bulk of the
        graph for a chain of some tens of bodies.
    inverse : casadi.Function
        ``inverse(y, yd, ydd, u, p, t) -> tau``: τ = M·ÿ + k − q, the generalized forces that,
        added to q, give the motion ÿ (zero where ÿ is the forward dynamics).
    ode : casadi.Function
        ``ode(x, u, p, t) -> xdot`` of the state ``x = [y; yd]``: ``xdot = [yd; ÿ]``.
    eom : casadi.Function
        ``eom(y, yd, u, p, t) -> (M, k, q)``.
    coordinates, rates, inputs, parameters : tuple of str
        The names of the entries of ``y``, ``yd``, ``u`` and ``p``.
    p : numpy.ndarray
        The parameter values: the model's, with the overrides given to :func:`to_casadi`.
    """

    forward: Any
    inverse: Any
    ode: Any
    eom: Any
    coordinates: tuple[str, ...]
    rates: tuple[str, ...]
    inputs: tuple[str, ...]
    parameters: tuple[str, ...]
    p: np.ndarray


def to_casadi(system: System, parameters: Mapping[str, float] | None = None
              ) -> CasadiDynamics:
    """The forward and inverse dynamics of ``system`` as CasADi functions with exact
    derivatives (:class:`CasadiDynamics`), for optimal control in ``casadi.Opti``.

    Parameters
    ----------
    system : jourdain.System
        An open tree (no closing joints, contacts or generalized velocities of its own:
        those raise :class:`~jourdain.errors.ClosedSystemError` naming them).
    parameters : mapping of str to float, optional
        Values that replace the model's in :attr:`CasadiDynamics.p` (an unknown name raises
        :class:`~jourdain.errors.EvaluationError` listing the known ones). The functions
        themselves take ``p`` as an input either way.

    Raises
    ------
    jourdain.extras.MissingDependency
        Where CasADi is not installed (``pip install 'jourdain[casadi]'``).
    jourdain.errors.EvaluationError
        Where the equations hold a function CasADi has no counterpart of, naming it.

    Examples
    --------
    >>> import casadi, jourdain as jd
    >>> from jourdain.models import n_link_pendulum_on_cart
    >>> dyn = jd.to_casadi(n_link_pendulum_on_cart(2))
    >>> ydd = dyn.forward([0, 3.1, 3.1], [0, 0, 0], [0.0], dyn.p, 0)  # a casadi.DM
    """
    refuse_closed(system, "to_casadi translates the equations of the open tree",
                  "a closed system's motion is not M·ÿ + k = q of its coordinates")
    cs = require("casadi", CASADI, "casadi")
    p_values = parameter_vector(system, parameters)
    eom = projection(newton_euler(kinematics(system)))
    f = system.f
    y, yd = cs.SX.sym("y", f), cs.SX.sym("yd", f)
    u = cs.SX.sym("u", len(system.inputs))
    p = cs.SX.sym("p", len(system.parameter_symbols))
    t = cs.SX.sym("t")
    symbols: dict[str, Any] = {str(system.t): t}
    for vector, syms in ((y, system.y), (yd, system.yd), (u, system.inputs),
                         (p, system.parameter_symbols)):
        for i, s in enumerate(syms):
            symbols[str(s)] = vector[i]
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    values = sx_of(cs, exprs, symbols)
    M = cs.reshape(cs.vertcat(*values[:f * f]), f, f).T  # entries come row by row
    k = cs.vertcat(*values[f * f:f * f + f])
    q = cs.vertcat(*values[f * f + f:])
    ydd = ldl_solve(cs, M, q - k)
    ydd_in = cs.SX.sym("ydd", f)
    x = cs.SX.sym("x", 2 * f)
    names = ["y", "yd", "u", "p", "t"]
    forward = cs.Function("forward", [y, yd, u, p, t], [ydd], names, ["ydd"])
    inverse = cs.Function("inverse", [y, yd, ydd_in, u, p, t], [cs.mtimes(M, ydd_in) + k - q],
                          ["y", "yd", "ydd", "u", "p", "t"], ["tau"])
    xdot = cs.vertcat(x[f:], forward(x[:f], x[f:], u, p, t))
    ode = cs.Function("ode", [x, u, p, t], [xdot], ["x", "u", "p", "t"], ["xdot"])
    mkq = cs.Function("eom", [y, yd, u, p, t], [M, k, q], names, ["M", "k", "q"])
    return CasadiDynamics(forward, inverse, ode, mkq, tuple(system.coordinate_names),
                          tuple(str(s) for s in system.yd), tuple(system.input_names),
                          tuple(str(s) for s in system.parameter_symbols), p_values)


def ldl_solve(cs: Any, M: Any, b: Any) -> Any:
    """``M⁻¹·b`` for a symmetric positive definite SX matrix ``M`` by ``M = L·D·Lᵀ`` (L unit
    lower triangular), written out entry by entry: every operation a node of the graph, so
    CasADi differentiates through the factorization. It reads M's lower triangle only."""
    n = M.shape[0]
    L: list[list[Any]] = [[None] * n for _ in range(n)]
    D: list[Any] = [None] * n
    for j in range(n):
        D[j] = M[j, j] - sum((L[j][m] * L[j][m] * D[m] for m in range(j)), cs.SX(0))
        for i in range(j + 1, n):
            s = M[i, j] - sum((L[i][m] * L[j][m] * D[m] for m in range(j)), cs.SX(0))
            L[i][j] = s / D[j]
    z: list[Any] = [None] * n  # L·z = b
    for i in range(n):
        z[i] = b[i] - sum((L[i][m] * z[m] for m in range(i)), cs.SX(0))
    x: list[Any] = [None] * n  # D·Lᵀ·x = z
    for i in reversed(range(n)):
        x[i] = z[i] / D[i] - sum((L[m][i] * x[m] for m in range(i + 1, n)), cs.SX(0))
    return cs.vertcat(*x)


def sx_of(cs: Any, exprs: Sequence[se.Basic], symbols: Mapping[str, Any]) -> list[Any]:
    """The SX expressions of SymEngine expressions, each distinct node translated once
    (children before parents); ``symbols`` maps symbol names to SX scalars. A symbol not in
    ``symbols`` or a function without a CasADi counterpart raises :class:`EvaluationError`."""
    g = Graph(list(exprs)).merged()
    funcs = _functions(cs)
    value: dict[int, Any] = {}
    for i in g.order:
        a = [value[c] if c is not None else _atom(x, symbols)
             for c, x in zip(g.arg_ids[i], g.args[i], strict=True)]
        value[i] = _node(cs, funcs, g.node[i], a, g.args[i])
    return [value[r] if r is not None else _atom(e, symbols)
            for e, r in zip(exprs, g.root_ids, strict=True)]


def _functions(cs: Any) -> dict[str, Callable[..., Any]]:
    """SymEngine's function names and their CasADi operations."""
    return {
        "sin": cs.sin, "cos": cs.cos, "tan": cs.tan, "asin": cs.asin, "acos": cs.acos,
        "atan": cs.atan, "exp": cs.exp, "log": cs.log, "sinh": cs.sinh, "cosh": cs.cosh,
        "tanh": cs.tanh, "asinh": cs.asinh, "acosh": cs.acosh, "atanh": cs.atanh,
        "Abs": cs.fabs, "sign": cs.sign, "atan2": cs.atan2, "floor": cs.floor,
        "ceiling": cs.ceil, "erf": cs.erf,
        "cot": lambda x: 1 / cs.tan(x), "sec": lambda x: 1 / cs.cos(x),
        "csc": lambda x: 1 / cs.sin(x),
    }


def _node(cs: Any, funcs: Mapping[str, Callable[..., Any]], e: se.Basic, a: list[Any],
          args: Sequence[se.Basic]) -> Any:
    """The CasADi value of node ``e`` from its arguments' values ``a`` (``args``: the
    SymEngine arguments, for the exponent of a power)."""
    tn = type(e).__name__
    if tn == "Add":
        out = a[0]
        for x in a[1:]:
            out = out + x
        return out
    if tn == "Mul":
        out = a[0]
        for x in a[1:]:
            out = out * x
        return out
    if tn == "Pow":
        base, exponent = args
        if exponent.is_Integer:
            return cs.constpow(a[0], int(exponent))
        if exponent == _HALF:
            return cs.sqrt(a[0])
        if exponent == _MHALF:
            return 1 / cs.sqrt(a[0])
        if base == se.E:
            return cs.exp(a[1])
        return cs.power(a[0], a[1])
    if tn in funcs:
        return funcs[tn](*a)
    if tn in ("Max", "Min"):
        op = cs.fmax if tn == "Max" else cs.fmin
        out = a[0]
        for x in a[1:]:
            out = op(out, x)
        return out
    text = str(e)
    text = text if len(text) <= 200 else text[:200] + " …"
    raise EvaluationError(f"cannot translate the function {tn} to CasADi (in {text}); the "
                          f"functions it translates are {', '.join(_NAMES)}")


_HALF = se.Rational(1, 2)
_MHALF = se.Rational(-1, 2)
_NAMES = ("+", "*", "**", "sin", "cos", "tan", "cot", "sec", "csc", "asin", "acos", "atan",
          "atan2", "sinh", "cosh", "tanh", "asinh", "acosh", "atanh", "exp", "log", "Abs",
          "sign", "floor", "ceiling", "erf", "Max", "Min")


def _atom(e: se.Basic, symbols: Mapping[str, Any]) -> Any:
    """A symbol's SX scalar, or a number as a float (rationals exactly rounded)."""
    if e.is_Symbol:
        try:
            return symbols[str(e)]
        except KeyError:
            raise EvaluationError(
                f'symbol "{e}" is not a coordinate, rate, t, parameter or input of the '
                "system; it cannot be translated to CasADi") from None
    try:
        if e.is_Rational:
            n, d = e.get_num_den()
            v = float(Fraction(int(n), int(d)))
        else:
            v = float(e)
    except (OverflowError, RuntimeError, TypeError, ValueError):
        v = math.nan
    if not math.isfinite(v):
        raise EvaluationError(f"the number {e} is not a finite double; it cannot be "
                              "translated to CasADi")
    return v
