"""The compiled right-hand side of a closed-loop system (issue 11): generated C for ``Φ``,
``Φ_z``, ``Φ_t`` (``jd_con``) and the convective term ``c`` of ``Φ̈ = Φ_z z̈ + c`` (``jd_gam``),
joined with the hand-written loop of ``loop_c.h`` (Newton on the dependent coordinates, the LU
of ``Φ_d`` and its condition number, ``J_z`` and ``γ`` by linear solves, ``M = J_zᵀ M_tree
J_z``, ``ÿ`` by Cholesky), which calls the tree's compiled ``M, k, q``
(:func:`jourdain.numeric.mkq_function`) through a function pointer.

:class:`LoopKernel` holds the C-side state (a ``jd_loop`` struct: the partition, the last
configuration solved, the work array) for one :class:`~jourdain.loops.closed_loop.LoopEvaluator`.
Its :attr:`LoopKernel.accel_address` and :attr:`LoopKernel.state_address` are the integrator's
``jd_accel`` hook and the ``p`` it passes along (:mod:`jourdain.loops.simulate` drives
jourdain's C integrator with them: one C call per step loop, no Python per right-hand side).
"""

from __future__ import annotations

import ctypes
from collections.abc import Mapping
from functools import lru_cache
from importlib import resources
from typing import Any

import numpy as np
import symengine as se

from ..errors import EvaluationError
from ..model import System
from ..numeric import CompiledFunction, lambdify, mkq_function
from ..numeric.ccode import HEADER, argument_names, function_source
from ..numeric.toolchain import build, build_lock, build_soon, content_key
from ..simulation.problem import address
from ..symbolic import SymMatrix
from .closed_loop import LoopEvaluator, Partition, constraints

_VERSION = "loop-c4"
#: reasons in ``info[2]`` (``loop_c.h``)
REASONS = {1: "Newton found no configuration on the manifold (Φ_d singular or divergence)",
           2: "the condition number of Φ_d passed the limit",
           3: "M in the independent coordinates is not positive definite",
           4: "Newton's solution left the branch of the motion (a correction far beyond the "
              "first-order prediction: near a singular position or a step too large)"}


class _Loop(ctypes.Structure):
    _fields_ = [("tree", ctypes.c_void_p), ("p", ctypes.c_void_p), ("n", ctypes.c_long),
                ("m", ctypes.c_long), ("f", ctypes.c_long), ("r", ctypes.c_long),
                ("ind", ctypes.c_void_p), ("dep", ctypes.c_void_p), ("rows", ctypes.c_void_p),
                ("z", ctypes.c_void_p), ("y_last", ctypes.c_void_p), ("work", ctypes.c_void_p),
                ("piv", ctypes.c_void_p), ("info", ctypes.c_void_p),
                ("newton_tol", ctypes.c_double), ("cond_limit", ctypes.c_double),
                ("max_newton", ctypes.c_long), ("uexpr", ctypes.c_void_p),
                ("u_buf", ctypes.c_void_p)]


def loop_library(loop: System) -> ctypes.CDLL:
    """The compiled constraint functions and loop kernel of ``loop`` (cached by content).
    One at a time: a call while a build started ahead (:func:`build_loop_library_soon`)
    generates the source waits for it instead of generating it again."""
    with build_lock("loop library"):
        return _loop_library(loop)


def build_loop_library_soon(loop: System) -> None:
    """Start :func:`loop_library` in a thread (:func:`jourdain.numeric.toolchain.build_soon`):
    its source generated and compiled while the caller compiles the tree's functions."""
    build_soon(loop_library, loop, name="jourdain-loop-build")


def loop_source(loop: System) -> str:
    """The C source of ``loop``'s kernel: the generated ``jd_con`` (Φ, Φ_y, Φ_t) and
    ``jd_gam`` (the convective term c) in the tree's arguments, then ``loop_c.h`` (what the
    library here and the FMU of a closed system compile)."""
    tree = loop.tree
    con = constraints(loop)
    names = argument_names(tree.y, tree.yd, tree.t, tree.parameter_symbols, tree.inputs)
    kernel = (resources.files(__package__) / "dense_c.h").read_text() + (
        resources.files(__package__) / "loop_c.h").read_text()
    return (HEADER + function_source("jd_con", [*con.Phi.entries(), *con.Phi_y.entries(),
                                                *con.Phi_t.entries()], names)
            + function_source("jd_gam", con.c.entries(), names) + kernel)


@lru_cache(maxsize=16)
def _loop_library(loop: System) -> ctypes.CDLL:
    source = loop_source(loop)
    lib = build(content_key(_VERSION, source), source, ("-O2",))
    vp, lg = ctypes.c_void_p, ctypes.c_long
    lib.jd_loop_samples.restype = lg
    lib.jd_loop_samples.argtypes = [vp, lg, vp, vp, lg, vp, vp]
    lib.jd_loop_work.restype = lg
    lib.jd_loop_work.argtypes = [lg, lg, lg]
    return lib


def input_function(loop: System, inputs: Mapping[str, Any]) -> CompiledFunction:
    """The inputs of ``loop``'s tree as compiled expressions of t and the parameters (an
    input not given is 0); an expression in anything else is refused, naming it."""
    tree = loop.tree
    names = tree.input_names
    unknown = sorted(set(inputs) - set(names))
    if unknown:
        raise EvaluationError(f"unknown input(s) {unknown}; inputs are {names}")
    allowed = {tree.t, *tree.parameter_symbols}
    exprs = []
    for name in names:
        v = inputs.get(name, 0.0)
        if isinstance(v, bool) or not isinstance(v, (int, float, se.Basic)):
            raise EvaluationError(f'input "{name}": expected a number or an expression, got '
                                  f"{type(v).__name__}")
        e = se.Float(float(v)) if isinstance(v, (int, float)) else v
        extra = sorted(str(s) for s in e.free_symbols - allowed)
        if extra:
            raise EvaluationError(f'input "{name}" = {e}: the inputs of a loop model may depend '
                                  f"on t and the parameters only, not on {', '.join(extra)}")
        exprs.append(e)
    return lambdify(tree, {"u": SymMatrix.column(exprs)})


class LoopKernel:
    """The C-side state of one evaluator: call :meth:`set_partition` after the evaluator's
    partition changes; :meth:`samples` evaluates states on the manifold."""

    def __init__(self, ev: LoopEvaluator, cond_limit: float = np.inf) -> None:
        self.ev = ev
        self.lib = loop_library(ev.loop)
        self.tree = mkq_function(ev.loop.tree)
        n, m = ev.n, len(ev.labels)
        self.n, self.m = n, m
        self.z = ev.z_guess.astype(float).copy()
        self.info = np.zeros(7)
        self.struct = _Loop()
        self.cond_limit = float(cond_limit)
        self.set_partition(ev.part)
        self.set_inputs(None)

    def set_partition(self, part: Partition) -> None:
        n, m = self.n, self.m
        self.part = part
        self.ind = np.array(part.independent, dtype=np.int_)
        self.dep = np.array(part.dependent, dtype=np.int_)
        self.rows = np.array(part.rows, dtype=np.int_)
        f, r = len(self.ind), len(self.dep)
        self.y_last = np.zeros(max(f, 1))
        self.work = np.zeros(int(self.lib.jd_loop_work(n, m, f)))
        self.piv = np.zeros(max(r, 1), dtype=np.int_)
        self.info[:] = 0.0
        s = self.struct
        s.tree, s.p = self.tree.address, address(self.ev.p)
        s.n, s.m, s.f, s.r = n, m, f, r
        s.ind, s.dep, s.rows = address(self.ind), address(self.dep), address(self.rows)
        s.z, s.y_last, s.work = address(self.z), address(self.y_last), address(self.work)
        s.piv, s.info = address(self.piv), address(self.info)
        s.newton_tol, s.cond_limit, s.max_newton = self.ev.newton_tol, self.cond_limit, \
            self.ev.max_newton

    def set_inputs(self, fn: CompiledFunction | None) -> None:
        """Inputs as compiled expressions of t and the parameters (``fn(·, ·, t, p, ·)``,
        one output per input; :func:`input_function`), or None: the constant ``ev.u``."""
        self.inputs_fn = fn
        self.u_buf = np.zeros(max(len(self.ev.loop.tree.inputs), 1))
        self.struct.uexpr = None if fn is None else fn.address
        self.struct.u_buf = address(self.u_buf)

    def restart(self, z: np.ndarray, y: np.ndarray) -> None:
        """Start the next solve from the configuration ``z`` with independent coordinates
        ``y`` (on the manifold): no prediction, continuation from ``y``."""
        self.z[:] = z
        self.y_last[:len(y)] = y
        self.info[4] = 0.0
        self.info[6] = 1.0

    def set_cond_limit(self, limit: float) -> None:
        self.cond_limit = float(limit)
        self.struct.cond_limit = self.cond_limit

    @property
    def accel_address(self) -> int:
        return int(ctypes.cast(self.lib.jd_loop_accel, ctypes.c_void_p).value or 0)

    @property
    def state_address(self) -> int:
        """The ``p`` the integrator passes to :attr:`accel_address`: the ``jd_loop``."""
        return ctypes.addressof(self.struct)

    @property
    def cond(self) -> float:
        """The 1-norm condition number of Φ_d at the last state solved."""
        return float(self.info[0])

    def reason(self) -> str:
        return REASONS.get(int(self.info[2]), "")

    def samples(self, t: np.ndarray, x: np.ndarray, u: np.ndarray | None = None
                ) -> tuple[dict[str, np.ndarray], int]:
        """States ``x`` (N × ≥2f: y, ẏ) at times ``t`` on the manifold: ``z, zd, zdd, Phi,
        Phi_dot, lam, cond`` (N rows each) and the index of the first state that failed
        (-1: none; the rows from there on are NaN)."""
        n, m = self.n, self.m
        t = np.ascontiguousarray(t, dtype=float)
        x = np.ascontiguousarray(x, dtype=float)
        N = t.size
        w = 3 * n + 3 * m + 1
        out = np.full((N, w), np.nan)
        uu = self.ev.u if u is None else np.ascontiguousarray(u, dtype=float)
        bad = int(self.lib.jd_loop_samples(self.state_address, N, address(t), address(x),
                                           x.shape[1] if x.ndim == 2 else 0, address(uu),
                                           address(out)))
        if bad >= 0:
            out[bad:] = np.nan
        cols = {"z": (0, n), "zd": (n, 2 * n), "zdd": (2 * n, 3 * n),
                "Phi": (3 * n, 3 * n + m), "Phi_dot": (3 * n + m, 3 * n + 2 * m),
                "lam": (3 * n + 2 * m, 3 * n + 3 * m)}
        res = {k: out[:, a:b] for k, (a, b) in cols.items()}
        res["cond"] = out[:, w - 1]
        return res, bad

    def __getstate__(self) -> Any:  # ctypes structures do not pickle
        raise TypeError("LoopKernel holds C pointers and cannot be pickled")


__all__ = ["LoopKernel", "input_function", "loop_library"]
