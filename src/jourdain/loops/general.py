"""The numbers of a *general* system (METHOD.md §7, ``docs/rolling.md``): velocity constraints
(rolling contacts, knife edges, velocity rows) and generalized velocities ``z``.

The tree's coordinates ``y`` (f) carry the holonomic rows ``Φ(y, t) = 0`` (closing joints, a
wheel touching the ground: ``r_h``) and all rows at the velocity level ``A·ẏ + a = 0`` (r,
the holonomic ones as ``Φ_y·ẏ + Φ_t``). The generalized velocities are g = f − r quantities
``z = Y(y, t)·ẏ + b`` (the user's definitions, or the rates of chosen coordinates). Stacked,

    W·ẏ = [z − b; −a],   W = [Y; A]   ⇒   ẏ = L·z + l,   L = W⁻¹[E; 0],  l = W⁻¹[−b; −a]

(the kinematic differential equations), and from ``W·ÿ + [c_Y; c] = [ż; 0]``: ``ÿ = L·ż + γ``
with ``γ = −W⁻¹[c_Y; c]``. Projection with ``L̄ᵀ = (J̄_tree·L)ᵀ`` gives ``M·ż + k = q``:
``M = LᵀM_tree·L``, ``k = Lᵀ(k_tree + M_tree·γ)``, ``q = Lᵀq_tree``. The rows' multipliers
(the contact forces along their directions) solve ``M_tree·ÿ + k_tree − q_tree = Aᵀλ``.

The state is ``x = (y_i, z)``: the independent coordinates (f − r_h; the dependent ones by
Newton on Φ = 0, so the holonomic rows hold to rounding at every state) and z. Every function
here runs in real or in complex arithmetic (:class:`Functions`), so that a linearization takes
its derivatives by the complex step, exact to rounding (:mod:`jourdain.loops.general_linear`).
"""

from __future__ import annotations

import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any

import numpy as np
import scipy.linalg as sla
import symengine as se

from ..errors import EvaluationError, SingularConfiguration
from ..graph.complex_step import ComplexTape
from ..model import System
from ..model.forces import rate
from ..numeric import lambdify, mkq_function, parameter_vector
from ..stages.kinematics import kinematics
from ..stages.newton_euler import newton_euler
from ..stages.projection import projection
from ..symbolic import SymMatrix
from .evaluator import _newton_stop
from .general_choice import Choice, choose, general_constraints, least_norm

EPS = float(np.finfo(float).eps)


def _speed_rows(system: System) -> tuple[SymMatrix, SymMatrix, SymMatrix] | None:
    """``Y``, ``b`` and ``c_Y`` of the user's speed definitions (None: chosen coordinates'
    rates, found by the partition)."""
    if system.speeds is None:
        return None
    y = system.coordinates
    yd = [rate(c) for c in y]
    zero = {d: se.Integer(0) for d in yd}
    Y, b, c = [], [], []
    for _, e in system.speeds:
        Y.append([se.diff(e, d) for d in yd])
        b.append(se.expand(e.subs(zero)))
        c.append(se.Add(*(se.diff(e, y[j]) * yd[j] for j in range(len(y))))
                 + se.diff(e, system.t))
    return SymMatrix.from_rows(Y), SymMatrix.column(b), SymMatrix.column(c)


#: the groups of :class:`Functions`: positions (Newton), velocities (W, ẏ, γ), the tree's M, k, q
POS, VEL, TREE = "pos", "vel", "tree"


class Functions:
    """At a state, by group: the holonomic rows' ``Phi, Phi_y, Phi_t`` (``"pos"``), every
    row's ``A, a, c`` and the speeds' ``Y, b, cY`` (``"vel"``), the tree's ``M, k, q``
    (``"tree"``); compiled (real) or in complex arithmetic for the complex step
    (:class:`jourdain.graph.complex_step.ComplexTape`, exact for integer powers of negative
    numbers, where SymEngine's complex evaluation is not). Newton evaluates the
    positions' group alone, the velocity map the velocities', so that no call computes what
    its caller throws away."""

    def __init__(self, system: System, complex_: bool = False) -> None:
        tree = system.tree
        con = general_constraints(system)
        vel = {"A": con.A, "a": con.a, "c": con.c}
        sp = _speed_rows(system)
        if sp is not None:
            vel.update(Y=sp[0], b=sp[1], cY=sp[2])
        groups = {POS: {"Phi": con.Phi, "Phi_y": con.Phi_y, "Phi_t": con.Phi_t}, VEL: vel}
        self.complex = complex_
        self.fns: dict[str, Any] = {}
        if not complex_:
            self.fns = {k: lambdify(tree, g) for k, g in groups.items()}
            self.fns[TREE] = mkq_function(tree)
            return
        eom = projection(newton_euler(kinematics(tree)))
        groups[TREE] = {"M": eom.M, "k": eom.k, "q": eom.q}
        args = [*tree.y, *tree.yd, tree.t, *tree.parameter_symbols, *tree.inputs]
        for key, group in groups.items():
            names = list(group)
            exprs = [e for n in names for e in group[n].entries()]
            self.fns[key] = (names, [group[n].shape for n in names],
                             ComplexTape(args, exprs))

    def __call__(self, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray,
                 u: np.ndarray, groups: tuple[str, ...] = (POS, VEL, TREE)
                 ) -> dict[str, np.ndarray]:
        """The functions of ``groups`` at a state."""
        out: dict[str, np.ndarray] = {}
        if not self.complex:
            y = np.ascontiguousarray(y, dtype=float)
            yd = np.ascontiguousarray(yd, dtype=float)
            for key in groups:
                fn = self.fns[key]
                out.update(fn.split(fn.raw(y, yd, t, p, u)))
            return self._shaped(out, len(y))
        x = np.concatenate([y, yd, [t], p, u]).astype(complex)
        for key in groups:
            names, shapes, fn = self.fns[key]
            flat = np.asarray(fn(x)).reshape(-1)
            i = 0
            for n, (r, c) in zip(names, shapes, strict=True):
                out[n] = flat[i:i + r * c].reshape(r, c)
                i += r * c
        return self._shaped(out, len(y))

    @staticmethod
    def _shaped(out: dict[str, np.ndarray], n: int) -> dict[str, np.ndarray]:
        """Rows × columns also where there are no rows (a system without holonomic rows, or
        with speeds but no contact: (0, n) and (0, 1), never (0, 0))."""
        for k, v in out.items():
            if v.size == 0:
                out[k] = v.reshape(0, n if k in ("Phi_y", "A", "Y") else 1)
        return out


@lru_cache(maxsize=16)
def functions(system: System, complex_: bool = False) -> Functions:
    """:class:`Functions` of ``system`` (memoized)."""
    return Functions(system, complex_)


class GeneralEvaluator:
    """Numbers of a general system at states ``x = (y_i, z)`` (see the module docstring), in
    real (default) or complex arithmetic."""

    def __init__(self, system: System, y0: Any, t: float = 0.0,
                 parameters: Mapping[str, float] | None = None, inputs: Any = None,
                 complex_: bool = False, choice: Choice | None = None) -> None:
        tree = system.tree
        self.system = system
        self.n = tree.f
        self.p = parameter_vector(tree, parameters)
        self.u = (np.zeros(len(tree.inputs)) if inputs is None
                  else np.ascontiguousarray(inputs, dtype=float))
        self.fn = functions(system, complex_)
        self.dtype = complex if complex_ else float
        self.labels = general_constraints(system).labels
        y = np.asarray(y0, dtype=float).reshape(-1)
        if y.size != self.n:
            raise EvaluationError(f"{system.name}: {self.n} coordinates expected, got {y.size}")
        if choice is None:  # the partition at y0
            real = functions(system, False) if complex_ else self.fn
            choice = choose(system, real(y, np.zeros(self.n), float(t), self.p, self.u,
                                         (POS, VEL)))
        self.choice = choice
        self.y_guess = y.astype(self.dtype)
        self.max_newton = 25
        self.newton_tol = 1e-13

    @property
    def speed_names(self) -> tuple[str, ...]:
        return self.choice.speeds

    @property
    def independent_names(self) -> list[str]:
        return [self.system.coordinate_names[j] for j in self.choice.independent]

    def _f(self, y: np.ndarray, yd: np.ndarray, t: float, groups: tuple[str, ...]
           ) -> dict[str, np.ndarray]:
        return self.fn(y, yd, t, self.p, self.u, groups)

    def positions(self, yi: np.ndarray, t: float, guess: np.ndarray | None = None
                  ) -> np.ndarray:
        """The coordinates y with the independent ones ``yi`` held, the dependent ones by
        Newton on the kept holonomic rows (from ``guess`` or the last solution)."""
        ch = self.choice
        y = (self.y_guess if guess is None else guess).astype(self.dtype, copy=True)
        y[list(ch.independent)] = yi
        if not ch.dependent:
            return y
        rows, dep = list(ch.rows_h), list(ch.dependent)
        zero = np.zeros(self.n, dtype=self.dtype)
        last, extra = math.inf, -1
        for _ in range(self.max_newton + 1):
            fn = self._f(y, zero, t, (POS,))
            Phi = fn["Phi"][rows, 0]
            if extra < 0:
                stop, res, last = _newton_stop(np.real(Phi), np.real(fn["Phi_y"][rows]),
                                               np.real(fn["Phi_t"][rows, 0]), np.real(y),
                                               float(t), self.newton_tol, last)
                if stop > 0:
                    # in complex arithmetic, two more steps carry the imaginary part (the
                    # derivative) to the same accuracy
                    extra = 2 if self.dtype is complex else 0
                elif stop < 0:
                    break
            if extra == 0:
                self.y_guess = y.copy()
                return y
            if extra > 0:
                extra -= 1
            Pd = fn["Phi_y"][np.ix_(rows, dep)]
            try:
                y[dep] -= np.linalg.solve(Pd, Phi)
            except np.linalg.LinAlgError:
                break
        names = self.system.coordinate_names
        raise SingularConfiguration(
            f"{self.system.name}: no configuration with the holonomic rows satisfied for "
            f"{', '.join(f'{names[j]} = {np.real(v):.6g}' for j, v in zip(ch.independent, yi, strict=True))}"
            f" at t = {t:.6g} (dependent {', '.join(names[j] for j in ch.dependent)})",
            t=t, z=np.real(y))

    def velocity_map(self, fn: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray,
                                                                np.ndarray]:
        """``W``, ``L`` (f×g) and ``l`` (f) at the functions ``fn`` of a configuration
        (``ẏ = L·z + l``). Raises SingularConfiguration naming the contacts where W is
        singular (the speeds do not determine the motion there)."""
        ch = self.choice
        A = fn["A"][list(ch.rows_v)]
        a = fn["a"][list(ch.rows_v), 0]
        g = len(ch.speeds)
        if ch.speed_coordinates is not None:
            Y = np.zeros((g, self.n), dtype=self.dtype)
            Y[np.arange(g), list(ch.speed_coordinates)] = 1.0
            b = np.zeros(g, dtype=self.dtype)
        else:
            Y, b = fn["Y"], fn["b"][:, 0]
        W = np.vstack([Y, A])
        rhs = np.zeros((self.n, g + 1), dtype=self.dtype)
        rhs[:g, :g] = np.eye(g)
        rhs[:g, g] = -b
        rhs[g:, g] = -a
        getrf, getrs = sla.get_lapack_funcs(("getrf", "getrs"), (W,))
        finite = bool(np.all(np.isfinite(W)))
        lu, piv, info = getrf(W) if finite else (W, None, 1)
        dmin = float(np.min(np.abs(np.diag(lu)))) if info == 0 else 0.0
        if not dmin > EPS * self.n * float(np.max(np.abs(W))):
            names = [c.name for c in self.system.contacts]
            raise SingularConfiguration(
                f"{self.system.name}: the speeds {', '.join(ch.speeds)} do not determine the "
                f"velocities here: the velocity rows of {', '.join(names)} are singular or "
                "redundant with them at this state (choose other speeds, or a state where the "
                "contacts are regular)")
        # column by column: a matrix right-hand side goes through multithreaded BLAS (dtrsm),
        # 20 ms on a loaded machine against microseconds per vector
        sol = np.empty(rhs.shape, dtype=self.dtype)
        for j in range(rhs.shape[1]):
            sol[:, j] = getrs(lu, piv, rhs[:, j])[0]
        self._lu = (lu, piv, getrs)
        return W, sol[:, :g], sol[:, g]

    def state(self, x: np.ndarray, t: float) -> dict[str, Any]:
        """Everything at the state ``x = (y_i, z)``: ``y, yd, L, gamma, M, k, q, zd`` and the
        tree's ``M_tree, k_tree, q_tree``."""
        ni = len(self.choice.independent)
        yi, z = x[:ni], x[ni:]
        y = self.positions(yi, t)
        fn0 = self._f(y, np.zeros(self.n, dtype=self.dtype), t, (VEL,))
        W, L, l = self.velocity_map(fn0)
        yd = L @ z + l
        fn = self._f(y, yd, t, (VEL, TREE))
        ch = self.choice
        cc = fn["c"][list(ch.rows_v), 0]
        cY = (np.zeros(len(z), dtype=self.dtype) if ch.speed_coordinates is not None
              else fn["cY"][:, 0])
        lu, piv, getrs = self._lu
        gamma = -getrs(lu, piv, np.concatenate([cY, cc]))[0]
        Mt, kt, qt = fn["M"], fn["k"][:, 0], fn["q"][:, 0]
        M = L.T @ Mt @ L
        k = L.T @ (kt + Mt @ gamma)
        q = L.T @ qt
        return {"y": y, "yd": yd, "z": z, "L": L, "l": l, "gamma": gamma, "W": W, "M": M,
                "k": k, "q": q, "M_tree": Mt, "k_tree": kt, "q_tree": qt, "fn": fn}

    def accelerations(self, x: np.ndarray, t: float) -> dict[str, Any]:
        """:meth:`state` with ``zd = M⁻¹(q − k)``, ``ydd = L·zd + γ`` and ``xd`` (the state's
        derivative)."""
        s = self.state(x, t)
        try:
            zd = np.linalg.solve(s["M"], s["q"] - s["k"])
        except np.linalg.LinAlgError:
            raise SingularConfiguration(f"{self.system.name}: M in the generalized velocities "
                                        f"is singular at t = {t:.6g}", t=t,
                                        z=np.real(s["y"])) from None
        s["zd"] = zd
        s["ydd"] = s["L"] @ zd + s["gamma"]
        s["xd"] = np.concatenate([s["yd"][list(self.choice.independent)], zd])
        return s

    def residuals(self, s: dict[str, Any], t: float) -> tuple[np.ndarray, np.ndarray]:
        """The rows' residuals at the state ``s`` of :meth:`state`: ``Φ`` of the holonomic rows
        (r_h) and every row's ``A·ẏ + a`` (r)."""
        fn = s["fn"]
        Phi = self._f(s["y"], np.zeros(self.n, dtype=self.dtype), t, (POS,))["Phi"]
        return Phi.reshape(-1), fn["A"] @ s["yd"] + fn["a"][:, 0]

    def multipliers(self, s: dict[str, Any]) -> np.ndarray:
        """The rows' multipliers λ (contact forces along the rows' directions) from
        ``M_tree·ÿ + k_tree − q_tree = Aᵀλ``: the least-norm solution over all rows, so that
        redundant rows (two wheels on one axle, both held sideways) share their force
        evenly whatever the heading; :meth:`undetermined` names the rows whose share is
        not fixed by the equations (statically indeterminate)."""
        res = np.real(s["M_tree"] @ s["ydd"] + s["k_tree"] - s["q_tree"])
        A = np.real(s["fn"]["A"])
        if not A.size:
            return np.zeros(0)
        lam, self._null = least_norm(A, res, len(self.choice.rows_v))
        return lam

    def undetermined(self) -> list[str]:
        """Labels of the rows whose multipliers the equations leave open (they lie on a
        redundant combination of rows; only their sum along it is the force), after
        :meth:`multipliers`."""
        null = getattr(self, "_null", np.zeros((0, len(self.labels))))
        if not null.size:
            return []
        weight = np.sqrt(np.sum(null * null, axis=0))
        return [lab for lab, w in zip(self.labels, weight, strict=True) if w > math.sqrt(EPS)]

    def initial(self, y0: Any, yd0: Any, t: float) -> np.ndarray:
        """The state x from approximate coordinates ``y0`` (independent ones held) and rates
        ``yd0`` (the speeds taken from them: ``z = Y·ẏ0 + b``)."""
        y0 = np.asarray(y0, dtype=float).reshape(-1)
        yd0 = np.zeros(self.n) if yd0 is None else np.asarray(yd0, dtype=float).reshape(-1)
        y = self.positions(y0[list(self.choice.independent)], t, y0)
        ch = self.choice
        if ch.speed_coordinates is not None:
            z = yd0[list(ch.speed_coordinates)]
        else:
            fn = self._f(y, yd0, t, (VEL,))
            z = fn["Y"] @ yd0 + fn["b"][:, 0]
        return np.concatenate([y[list(ch.independent)], z])


__all__ = ["POS", "TREE", "VEL", "Functions", "GeneralEvaluator", "functions"]
