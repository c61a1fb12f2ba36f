"""Compiled functions of a system: :class:`CompiledFunction` (machine code for named matrices,
one state or a batch in one call) and :class:`InterpretedFunction` (the same interface
without a C compiler).
"""

from __future__ import annotations

import ctypes
import os
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np
import symengine as se

from ..errors import EvaluationError, SingularMassMatrix
from .toolchain import CompilerError, cache_dir

if TYPE_CHECKING:
    pass



@dataclass(frozen=True, eq=False)
class CompiledFunction:
    """Machine code for named matrices of one system (generated C, compiled once, cached).

    Call ``fn(y, yd, t, p, u)`` with NumPy vectors (``p`` in the order of
    ``system.parameter_symbols``, ``u`` in the order of ``system.inputs``); returns a dict of
    arrays with the shapes of the symbolic matrices. :meth:`batch` evaluates many states in one
    call. Parameter values are arguments: changing them never recompiles.

    Attributes
    ----------
    names, shapes : the matrices, in the order of the output vector
    args : argument symbols ``(y, ẏ, t, parameters, inputs)``
    key : the content hash naming the cached library (``<cache_dir>/<key>.so``)
    size : total number of output entries
    """

    names: tuple[str, ...]
    shapes: tuple[tuple[int, int], ...]
    args: tuple[se.Symbol, ...]
    key: str
    f: int
    n_p: int
    n_u: int
    lib: Any = field(repr=False)
    symbol: str = "jd_fn"
    #: number of bodies (the joint wrenches of :meth:`dynamics`); 0 where not compiled with them
    n_bodies: int = 0

    @property
    def size(self) -> int:
        return sum(n * m for n, m in self.shapes)

    def lib_source(self) -> str:
        """The generated C source of this function (``<cache_dir>/<key>.c``; empty if gone)."""
        path = cache_dir() / f"{self.key}.c"
        return path.read_text() if path.exists() else ""

    @property
    def accel_address(self) -> int | None:
        """Address of ``int jd_accel(y, yd, t, p, u, ydd, power)`` when compiled with it."""
        try:
            return ctypes.cast(self.lib.jd_accel, ctypes.c_void_p).value
        except AttributeError:
            return None

    @property
    def accel_ctx_address(self) -> int | None:
        """The integrator's right-hand side with a context (``jd_problem.accel_ctx``): None
        here; where the model is interpreted
        (:class:`jourdain.numeric.interpreter.FirstFunction`), the interpreter's."""
        return None

    @property
    def ctx_address(self) -> int | None:
        """The context of :attr:`accel_ctx_address` (None here)."""
        return None

    @property
    def address(self) -> int:
        """Address of the C function ``void fn(y, yd, t, p, u, out)`` (for compiled loops)."""
        return ctypes.cast(getattr(self.lib, self.symbol), ctypes.c_void_p).value or 0

    def raw(self, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray, u: np.ndarray,
            out: np.ndarray | None = None) -> np.ndarray:
        """All outputs as one flat vector (no checks: arrays must be contiguous float64)."""
        if out is None:
            out = np.empty(self.size)
        getattr(self.lib, self.symbol)(y.ctypes.data, yd.ctypes.data, ctypes.c_double(t),
                                       p.ctypes.data, u.ctypes.data, out.ctypes.data)
        return out

    def split(self, flat: np.ndarray) -> dict[str, np.ndarray]:
        """Split outputs (last axis) into the named matrices."""
        res: dict[str, np.ndarray] = {}
        i = 0
        lead = flat.shape[:-1]
        for n, (r, c) in zip(self.names, self.shapes, strict=True):
            res[n] = flat[..., i:i + r * c].reshape(*lead, r, c)
            i += r * c
        return res

    def __call__(self, y: Any, yd: Any, t: float, p: Any, u: Any) -> dict[str, np.ndarray]:
        yv = _contig(y, self.f, "y")
        ydv = _contig(yd, self.f, "yd")
        pv = _contig(p, self.n_p, "parameters")
        uv = _contig(u, self.n_u, "inputs")
        return self.split(self.raw(yv, ydv, float(t), pv, uv))

    def batch(self, y: Any, yd: Any, t: Any = 0.0, p: Any = None, u: Any = None,
              out: np.ndarray | None = None) -> dict[str, np.ndarray]:
        """Evaluate ``n`` states in one call (the loop runs in C).

        Parameters
        ----------
        y, yd : array (n, f)
        t : float or array (n,)
        p : array (n_p,) shared by all states, or (n, n_p); None: zeros
        u : array (n_u,) shared, or (n, n_u); None: zeros
        out : optional preallocated array (n, size)

        Returns
        -------
        dict name -> array (n, rows, cols)
        """
        n, Y, YD, T, P, ps, U, us = self._states("batch", y, yd, t, p, u)
        if out is None:
            out = np.empty((n, self.size))
        elif out.shape != (n, self.size) or not out.flags.c_contiguous or out.dtype != float:
            raise EvaluationError(f"batch: out must be a C-contiguous float array {(n, self.size)}")
        self._batch(n, Y, YD, T, P, ps, U, us, out)
        return self.split(out)

    def _states(self, what: str, y: Any, yd: Any, t: Any, p: Any, u: Any) -> tuple:
        """Checked contiguous arrays of a batch of states: n, Y, YD, T, P, p_stride, U,
        u_stride (a stride 0 shares one vector between all states)."""
        Y = np.ascontiguousarray(y, dtype=float)
        YD = np.ascontiguousarray(yd, dtype=float)
        if Y.ndim != 2 or Y.shape[1] != self.f or YD.shape != Y.shape:
            raise EvaluationError(f"{what}: y and yd must have shape (n, {self.f}), got "
                                  f"{Y.shape} and {YD.shape}")
        n = Y.shape[0]
        T = np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=float), (n,)))
        P, ps = _shared_or_per_state(p, n, self.n_p, "parameters")
        U, us = _shared_or_per_state(u, n, self.n_u, "inputs")
        return n, Y, YD, T, P, ps, U, us

    def dynamics(self, y: Any, yd: Any, t: Any = 0.0, p: Any = None, u: Any = None
                 ) -> tuple[np.ndarray, np.ndarray]:
        """Forward dynamics and joint wrenches of ``n`` states in one call (the loop runs in C).

        ``ÿ = M⁻¹(q − k)`` (LDLᵀ), then for every body the wrench its parent transmits to the
        sub-tree it carries (the Newton–Euler equations of the sub-tree summed, as RNEA does),
        as ``(F_x, F_y, F_z, T_x, T_y, T_z)`` in the body's frame at its origin (the joint
        point). Arguments as for :meth:`batch`. Returns ``ydd`` (n, f) and ``wrenches``
        (n, p, 6); raises :class:`SingularMassMatrix` naming the first state where M is not
        positive definite.
        """
        fn = getattr(self.lib, "jd_dynamics_batch", None)
        if fn is None or not self.n_bodies:
            raise EvaluationError("this compiled function has no joint wrenches")
        n, Y, YD, T, P, ps, U, us = self._states("dynamics", y, yd, t, p, u)
        ydd = np.empty((n, self.f))
        W = np.empty((n, self.n_bodies, 6))
        bad = fn(n, self.f, Y.ctypes.data, YD.ctypes.data, T.ctypes.data, P.ctypes.data, ps,
                 U.ctypes.data, us, ydd.ctypes.data, W.ctypes.data)
        if bad >= 0:
            raise SingularMassMatrix(f"M is not positive definite (or not finite) at state {bad}: "
                                     f"t = {T[bad]}, y = {Y[bad].tolist()}")
        return ydd, W

    def _batch(self, n: int, Y: np.ndarray, YD: np.ndarray, T: np.ndarray, P: np.ndarray,
               ps: int, U: np.ndarray, us: int, out: np.ndarray) -> None:
        getattr(self.lib, self.symbol + "_batch")(
            ctypes.c_long(n), ctypes.c_long(self.f), Y.ctypes.data, YD.ctypes.data,
            T.ctypes.data, P.ctypes.data, ctypes.c_long(ps), U.ctypes.data, ctypes.c_long(us),
            out.ctypes.data)


@dataclass(frozen=True, eq=False)
class ProvisionalFunction(CompiledFunction):
    """A model's function for its first runs while its optimized library compiles in a thread
    (:func:`jourdain.numeric.first_run.run_function`): the same numbers to the bit, sooner.
    ``compiled`` receives the optimized function when the build is done, ``failed`` its error
    where it failed (``warned``: reported); ``pid``: the process whose thread builds (a forked
    child builds for itself)."""

    compiled: list = field(default_factory=list, repr=False)
    failed: list = field(default_factory=list, repr=False)
    warned: list = field(default_factory=list, repr=False)
    pid: int = field(default_factory=os.getpid)


@dataclass(frozen=True, eq=False)
class ContextFunction(ProvisionalFunction):
    """A provisional function whose entry points in ``lib`` (the integrator's library) take a
    context first, :attr:`ctx_address`: the interpreter's program
    (:class:`jourdain.numeric.interpreter.FirstFunction`) or an engine sized at run time
    (:class:`jourdain.numeric.runtime_engine.RuntimeFunction`). A subclass names them
    (:meth:`entries`) and its context; the integrator's right-hand side is
    ``jd_problem.accel_ctx`` with ``ctx``."""

    def entries(self) -> tuple[Any, Any, Any]:
        """``lib``'s M, k, q of one state, of a batch, and ÿ (each with the context first)."""
        raise NotImplementedError

    @property
    def address(self) -> int:
        return 0  # no function without its context: the problem takes accel_ctx

    @property
    def accel_address(self) -> int | None:
        return None

    @property
    def accel_ctx_address(self) -> int | None:
        return ctypes.cast(self.entries()[2], ctypes.c_void_p).value

    def raw(self, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray, u: np.ndarray,
            out: np.ndarray | None = None) -> np.ndarray:
        if out is None:
            out = np.empty(self.size)
        ctx = self.ctx_address
        assert ctx is not None
        self.entries()[0](ctx, y.ctypes.data, yd.ctypes.data, ctypes.c_double(t),
                          p.ctypes.data, u.ctypes.data, out.ctypes.data)
        return out

    def _batch(self, n: int, Y: np.ndarray, YD: np.ndarray, T: np.ndarray, P: np.ndarray,
               ps: int, U: np.ndarray, us: int, out: np.ndarray) -> None:
        ctx = self.ctx_address
        assert ctx is not None
        self.entries()[1](ctx, n, self.f, Y.ctypes.data, YD.ctypes.data, T.ctypes.data,
                          P.ctypes.data, ps, U.ctypes.data, us, out.ctypes.data)


@dataclass(frozen=True, eq=False)
class InterpretedFunction(CompiledFunction):
    """The same interface without a C compiler: SymEngine's ``Lambdify`` (its LLVM backend
    when available, else its interpreter). Slower; simulation needs the compiled form."""

    def _x(self, y: np.ndarray, yd: np.ndarray, t: Any, p: np.ndarray, u: np.ndarray
           ) -> np.ndarray:
        return np.concatenate([y, yd, t, p, u], axis=-1)

    def raw(self, y: np.ndarray, yd: np.ndarray, t: float, p: np.ndarray, u: np.ndarray,
            out: np.ndarray | None = None) -> np.ndarray:
        r = np.asarray(self.lib(self._x(y, yd, np.array([t]), p, u)), dtype=float).reshape(-1)
        if out is None:
            return r
        out[:] = r
        return out

    def _batch(self, n: int, Y: np.ndarray, YD: np.ndarray, T: np.ndarray, P: np.ndarray,
               ps: int, U: np.ndarray, us: int, out: np.ndarray) -> None:
        if n == 0:  # no states (a motion that failed at its start): Lambdify refuses them
            return
        Pn = np.broadcast_to(P[:self.n_p] if ps == 0 else P.reshape(n, self.n_p),
                             (n, self.n_p))
        Un = np.broadcast_to(U[:self.n_u] if us == 0 else U.reshape(n, self.n_u),
                             (n, self.n_u))
        # all states in one call: Lambdify loops over the rows itself, with the same numbers
        # as one state at a time
        X = np.concatenate([Y, YD, T[:, None], Pn, Un], axis=1)
        out[:] = np.asarray(self.lib(X), dtype=float).reshape(n, self.size)

    @property
    def address(self) -> int:
        raise CompilerError("this function was not compiled (no C compiler): simulation needs "
                            "a C compiler (gcc or clang, or set CC)")

    @property
    def accel_address(self) -> int | None:
        return None


class JitFunction(InterpretedFunction):
    """A small function evaluated once per sample of a motion (``lambdify(lean=True)``),
    compiled in this process by SymEngine's LLVM backend (no compiler process) and kept on
    disk like a library (``<cache_dir>/<key>.llvm``); a batch is one call over all states."""

    @property
    def address(self) -> int:
        raise CompilerError("this function was compiled by LLVM in this process (lambdify's "
                            "lean): it has no C address; compile it with lean=False")


def _contig(x: Any, n: int, what: str) -> np.ndarray:
    v = np.ascontiguousarray(x, dtype=float).reshape(-1)
    if v.size != n:
        raise EvaluationError(f"{what} must have {n} entries, got {v.size}")
    return v


def _shared_or_per_state(x: Any, n: int, m: int, what: str) -> tuple[np.ndarray, int]:
    if x is None:
        return np.zeros(max(m, 1)), 0
    a = np.ascontiguousarray(x, dtype=float)
    if a.ndim <= 1:
        if a.size != m:
            raise EvaluationError(f"batch: {what} must have {m} entries, got {a.size}")
        return (a.reshape(-1) if m else np.zeros(1)), 0
    if a.shape != (n, m):
        raise EvaluationError(f"batch: {what} must have shape ({m},) or ({n}, {m}), got {a.shape}")
    return (a if m else np.zeros(1)), m


