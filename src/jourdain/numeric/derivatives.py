"""First derivatives of the dynamics per state, compiled (issue 37): for model-predictive
control, trajectory optimization and estimation.

* inverse dynamics ``τ(y, ẏ, ÿ, u) = M·ÿ + k − q`` (the generalized force that, added to q,
  makes ÿ happen; with gravity only and no inputs Pinocchio's ``rnea``) with ``∂τ/∂y``,
  ``∂τ/∂ẏ``, ``∂τ/∂ÿ = M`` and ``∂τ/∂u``;
* forward dynamics ``ÿ = M⁻¹(q − k)`` with ``∂ÿ/∂y = −M⁻¹·∂τ/∂y`` (at that ÿ), ``∂ÿ/∂ẏ``,
  ``∂ÿ/∂u``.

The derivatives are exact (to rounding): the kinematic recursion of :mod:`.recursive` runs in
forward mode with prefix tangents (:mod:`.derivative_source`, ``derivative_engine.h``), in C
generated for the model and compiled once (cached on disk like every library of jourdain).
``M`` comes from the recursion's own library, linked into the same one. Many states go in one
call (the loop runs in C). The C entry points (``jd_inverse_derivatives``,
``jd_forward_derivatives`` and their ``_batch``) are written with a documented header by
:meth:`Derivatives.export_c`, for use outside Python.

Trees only: a closed system (closing joints, contacts, generalized velocities of its own) is
refused by name (:class:`jourdain.errors.ClosedSystemError`); its dynamics in independent
coordinates are :meth:`jourdain.System.linearize`'s (complex step) for now.
"""

from __future__ import annotations

import ctypes
import threading
from collections.abc import Mapping
from dataclasses import dataclass, field
from functools import lru_cache
from pathlib import Path
from types import SimpleNamespace
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy import copyto

from ..errors import EvaluationError, ModelError, SingularMassMatrix, refuse_closed
from .compiled import _GENERATOR_VERSION
from .derivative_screw import screw_columns, screw_source
from .derivative_source import derivative_layout
from .recursive import recursive_units
from .state import parameter_vector
from .toolchain import build, content_key

if TYPE_CHECKING:
    from ..model.system import System


@dataclass(frozen=True)
class ForwardDerivatives:
    """``ydd = M⁻¹(q − k)`` and its derivatives ``ydd_y = ∂ÿ/∂y``, ``ydd_yd = ∂ÿ/∂ẏ``,
    ``ydd_u = ∂ÿ/∂u`` (row i, column j: ∂ÿ_i/∂x_j); a leading axis per state for a batch."""

    ydd: np.ndarray
    ydd_y: np.ndarray
    ydd_yd: np.ndarray
    ydd_u: np.ndarray


@dataclass(frozen=True)
class InverseDerivatives:
    """``tau = M·ÿ + k − q`` and its derivatives ``tau_y``, ``tau_yd``, ``tau_ydd`` (= M) and
    ``tau_u``; a leading axis per state for a batch."""

    tau: np.ndarray
    tau_y: np.ndarray
    tau_yd: np.ndarray
    tau_ydd: np.ndarray
    tau_u: np.ndarray


@dataclass(frozen=True, eq=False)
class Derivatives:
    """The compiled derivatives of one system: :meth:`forward`, :meth:`inverse`."""

    system: Any
    lib: Any
    key: str
    #: the forward mode of every intermediate quantity, not the recursions of screw joints
    forward_mode: bool = False

    #: this thread's arrays for one state (:meth:`_buffers`)
    _local: threading.local = field(default_factory=threading.local, repr=False, compare=False)
    @property
    def f(self) -> int:
        return int(self.system.f)

    @property
    def n_u(self) -> int:
        return len(self.system.inputs)

    def _buffers(self) -> Any:
        """This thread's arrays for one state and their addresses (a call per state then
        converts no argument: microseconds, where a batch's checks take tens)."""
        b = getattr(self._local, "b", None)
        if b is None:
            f, nu = self.f, self.n_u
            p = parameter_vector(self.system, None)
            b = SimpleNamespace(f=f, nu=nu, y=np.zeros(f), yd=np.zeros(f), ydd=np.zeros(f),
                                u=np.zeros(max(nu, 1)), p=p if p.size else np.zeros(1),
                                inv=np.empty(f + 3 * f * f + f * nu),
                                fwd=np.empty(f + 2 * f * f + f * nu))
            for k in ("y", "yd", "ydd", "u", "p", "inv", "fwd"):
                setattr(b, k + "_at", getattr(b, k).ctypes.data)
            b.inverse_fn = self.lib.jd_inverse_derivatives
            b.forward_fn = self.lib.jd_forward_derivatives
            self._local.b = b
        return b

    def _one(self, inverse: bool, y: Any, yd: Any, ydd: Any, u: Any, t: Any) -> Any:
        """One state with the default parameters, or None where an argument does not fit
        (the general path then says what is wrong)."""
        b = self._buffers()
        try:
            copyto(b.y, y)
            copyto(b.yd, yd)
            if inverse:
                copyto(b.ydd, ydd)
            f, nu = b.f, b.nu
            if nu:
                if u is None:
                    return None
                copyto(b.u, u)
            elif u is not None:
                return None
            tv = float(t)
        except (ValueError, TypeError):
            return None
        FF = f * f
        if inverse:
            status = b.inverse_fn(b.y_at, b.yd_at, b.ydd_at, tv, b.p_at, b.u_at, b.inv_at)
            if status:
                return None
            o = b.inv.copy()
            return InverseDerivatives(tau=o[:f], tau_y=o[f:f + FF].reshape(f, f),
                                      tau_yd=o[f + FF:f + 2 * FF].reshape(f, f),
                                      tau_u=o[f + 2 * FF:f + 2 * FF + f * nu].reshape(f, nu),
                                      tau_ydd=o[f + 2 * FF + f * nu:].reshape(f, f))
        status = b.forward_fn(b.y_at, b.yd_at, tv, b.p_at, b.u_at, b.fwd_at)
        if status:
            return None
        o = b.fwd.copy()
        return ForwardDerivatives(ydd=o[:f], ydd_y=o[f:f + FF].reshape(f, f),
                                  ydd_yd=o[f + FF:f + 2 * FF].reshape(f, f),
                                  ydd_u=o[f + 2 * FF:].reshape(f, nu))

    def inverse(self, y: Any, yd: Any, ydd: Any, u: Any = None, t: Any = 0.0,
                parameters: Mapping[str, float] | None = None) -> InverseDerivatives:
        """τ and its derivatives at one state (``y``, ``yd``, ``ydd`` of shape (f,)) or at
        ``n`` states (shape (n, f); ``u`` (n_u,) shared or (n, n_u); ``t`` a number or (n,))."""
        if parameters is None and getattr(y, "ndim", 1) == 1:
            res = self._one(True, y, yd, ydd, u, t)
            if res is not None:
                return res
        f, nu = self.f, self.n_u
        n, one, Y, YD, T, P, U, us = self._states(y, yd, u, t, parameters)
        YDD = _array(ydd, n, f, "ydd")
        size = f + 3 * f * f + f * nu
        out = np.empty((n, size))
        status = ctypes.c_int(0)
        bad = self.lib.jd_inverse_derivatives_batch(
            n, Y.ctypes.data, YD.ctypes.data, YDD.ctypes.data, T.ctypes.data, P.ctypes.data,
            0, U.ctypes.data, us, out.ctypes.data, ctypes.byref(status))
        self._check(bad, status.value, Y, T)
        FF = f * f
        res = InverseDerivatives(
            tau=out[:, :f], tau_y=out[:, f:f + FF].reshape(n, f, f),
            tau_yd=out[:, f + FF:f + 2 * FF].reshape(n, f, f),
            tau_u=out[:, f + 2 * FF:f + 2 * FF + f * nu].reshape(n, f, nu),
            tau_ydd=out[:, f + 2 * FF + f * nu:].reshape(n, f, f))
        return _first(res) if one else res

    def forward(self, y: Any, yd: Any, u: Any = None, t: Any = 0.0,
                parameters: Mapping[str, float] | None = None) -> ForwardDerivatives:
        """ÿ and its derivatives at one state or at ``n`` states (as :meth:`inverse`);
        :class:`SingularMassMatrix` names the first state where M is not positive definite."""
        if parameters is None and getattr(y, "ndim", 1) == 1:
            res = self._one(False, y, yd, None, u, t)
            if res is not None:
                return res
        f, nu = self.f, self.n_u
        n, one, Y, YD, T, P, U, us = self._states(y, yd, u, t, parameters)
        size = f + 2 * f * f + f * nu
        out = np.empty((n, size))
        status = ctypes.c_int(0)
        bad = self.lib.jd_forward_derivatives_batch(
            n, Y.ctypes.data, YD.ctypes.data, T.ctypes.data, P.ctypes.data, 0,
            U.ctypes.data, us, out.ctypes.data, ctypes.byref(status))
        self._check(bad, status.value, Y, T)
        FF = f * f
        res = ForwardDerivatives(
            ydd=out[:, :f], ydd_y=out[:, f:f + FF].reshape(n, f, f),
            ydd_yd=out[:, f + FF:f + 2 * FF].reshape(n, f, f),
            ydd_u=out[:, f + 2 * FF:].reshape(n, f, nu))
        return _first(res) if one else res

    def export_c(self, folder: str | Path) -> list[Path]:
        """Write the C sources of these derivatives for use outside Python into ``folder``:
        ``jourdain_derivatives.h`` (the documented interface: sizes, the order of the
        coordinates, parameters with their default values and inputs, the layout of the
        outputs) and the translation units ``jd_local.c``, ``jd_engine.c``,
        ``jd_derivatives.c`` (compile and link the three, e.g. ``cc -O2 -c jd_*.c``; only the
        C standard library and libm are needed). Returns the paths written."""
        out = Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        names = ("jd_local.c", "jd_engine.c", "jd_derivatives.c")
        paths = []
        for name, text in zip(names, self.units(), strict=True):
            path = out / name
            path.write_text('#include "jourdain_derivatives.h"\n' + text, encoding="utf-8")
            paths.append(path)
        header = out / "jourdain_derivatives.h"
        header.write_text(c_header(self.system), encoding="utf-8")
        return [header, *paths]

    def units(self) -> tuple[str, ...]:
        """The C translation units of this library."""
        return derivative_units(self.system, self.forward_mode)

    def _states(self, y: Any, yd: Any, u: Any, t: Any,
                parameters: Mapping[str, float] | None) -> tuple:
        f, nu = self.f, self.n_u
        Yr = np.asarray(y, dtype=float)
        one = Yr.ndim <= 1
        n = 1 if one else Yr.shape[0]
        Y = _array(y, n, f, "y")
        YD = _array(yd, n, f, "yd")
        T = np.ascontiguousarray(np.broadcast_to(np.asarray(t, dtype=float), (n,)))
        if not np.all(np.isfinite(T)):
            raise EvaluationError("t contains NaN or inf")
        P = parameter_vector(self.system, parameters)
        P = np.ascontiguousarray(P if P.size else np.zeros(1))
        if nu == 0:
            if u is not None and np.asarray(u).size:
                raise EvaluationError(f"{self.system.name or 'the model'} has no inputs")
            return n, one, Y, YD, T, P, np.zeros(1), 0
        if u is None:
            raise EvaluationError(f"inputs {self.system.input_names} must be given")
        Ua = np.asarray(u, dtype=float)
        if Ua.ndim <= 1:
            U = _array(Ua, 1, nu, "u")[0]
            us = 0
        else:
            U = _array(Ua, n, nu, "u")
            us = nu
        return n, one, Y, YD, T, P, np.ascontiguousarray(U), us

    def _check(self, bad: int, status: int, Y: np.ndarray, T: np.ndarray) -> None:
        if bad < 0:
            return
        where = f"state {bad}: t = {T[bad]}, y = {Y[bad].tolist()}"
        if status == 1:
            raise SingularMassMatrix(f"M is not positive definite at {where}")
        if status == 3:
            raise MemoryError("no memory for the derivatives' work arrays")
        raise EvaluationError(f"the dynamics or their derivatives are not finite at {where}")


def c_header(system: System) -> str:
    """The documented interface of :meth:`Derivatives.export_c`'s sources."""
    f, nu = system.f, len(system.inputs)
    values = system.parameter_values
    lines = [f"  y[{i}] = {n}" for i, n in enumerate(system.coordinate_names)]
    plines = [f"  p[{i}] = {n} (default {values[n]!r})" for i, n in enumerate(values)]
    ulines = [f"  u[{i}] = {n}" for i, n in enumerate(system.input_names)] or ["  (none)"]
    return f"""/* jourdain: the first derivatives of the dynamics of {system.name or 'a model'}
   (generated; see jourdain.numeric.derivatives). M·ÿ + k = q with f = {f} coordinates.

   Coordinates (y, rates yd = ẏ, accelerations ydd = ÿ in the same order):
{chr(10).join(lines)}
   Parameters (p, by value; change them freely, nothing is recompiled):
{chr(10).join(plines) or "  (none)"}
   Inputs (u):
{chr(10).join(ulines)}

   Matrices are row-major: X_y[i*F + j] = ∂X_i/∂y_j. Return values: 0 ok, 1 M not positive
   definite, 2 a number not finite, 3 no memory. The functions are thread-safe: each thread
   allocates its work array on its first call and keeps it. */
#ifndef JOURDAIN_DERIVATIVES_H
#define JOURDAIN_DERIVATIVES_H
#define JOURDAIN_F {f}
#define JOURDAIN_NU {nu}
#define JOURDAIN_NP {len(values)}

/* inverse dynamics: out = [tau (F), tau_y (F*F), tau_yd (F*F), tau_u (F*NU), M (F*F)] with
   tau = M·ÿ + k − q, the generalized force that, added to q, makes ÿ happen */
int jd_inverse_derivatives(const double *y, const double *yd, const double *ydd, double t,
                           const double *p, const double *u, double *out);
/* forward dynamics: out = [ydd (F), ydd_y (F*F), ydd_yd (F*F), ydd_u (F*NU)],
   ÿ = M⁻¹(q − k), ∂ÿ/∂x = −M⁻¹·∂tau/∂x at that ÿ */
int jd_forward_derivatives(const double *y, const double *yd, double t, const double *p,
                           const double *u, double *out);
/* n states one after the other (y, yd, ydd: n*F; t: n; out: n times the size above); p and u
   advance by ps and us per state (0: one vector for all); returns -1, or the first state
   that failed with its code in *status */
long jd_inverse_derivatives_batch(long n, const double *y, const double *yd, const double *ydd,
                                  const double *t, const double *p, long ps, const double *u,
                                  long us, double *out, int *status);
long jd_forward_derivatives_batch(long n, const double *y, const double *yd, const double *t,
                                  const double *p, long ps, const double *u, long us,
                                  double *out, int *status);
/* M (F*F), k (F), q (F) at a state, one after the other in out */
void jd_fn(const double *y, const double *yd, double t, const double *p, const double *u,
           double *out);
#endif
"""


def _array(x: Any, n: int, m: int, what: str) -> np.ndarray:
    try:
        a = np.ascontiguousarray(np.asarray(x, dtype=float).reshape(n, m))
    except (TypeError, ValueError):
        raise EvaluationError(f"{what} must have shape ({m},) or ({n}, {m}), got "
                              f"{np.shape(x)}") from None
    if not np.all(np.isfinite(a)):
        raise EvaluationError(f"{what} contains NaN or inf")
    return a


def _first(res: Any) -> Any:
    return type(res)(**{k: v[0] for k, v in vars(res).items()})


def derivative_units(system: System, forward_mode: bool = False) -> tuple[str, ...]:
    """The translation units of the derivatives' library: the recursion (``jd_local``, the
    joints' local expressions, and ``jd_fn``: M, k, q) and the derivative unit, by the
    recursions of screw joints where the model qualifies (:mod:`.derivative_screw`), else (or
    with ``forward_mode``) by the forward mode (:mod:`.derivative_source`)."""
    local, engine = recursive_units(system)
    cols = None if forward_mode else screw_columns(system)
    unit = (screw_source(system, cols) if cols is not None
            else derivative_layout(system).source)
    return local, engine, unit


def derivatives(system: System) -> Derivatives:
    """The compiled first derivatives of ``system``'s forward and inverse dynamics (memoized
    per system; the library is cached on disk). Trees only (:class:`ClosedSystemError`)."""
    refuse_closed(system, "the derivatives of the dynamics cover trees",
                  "linearize the closed system with system.linearize (complex step)")
    if system.frictions:
        raise ModelError(f"{system.name}: the derivatives do not cover joint friction (its "
                         f"forces are set-valued at rest: {', '.join(fr.name for fr in system.frictions)})")
    return compiled_derivatives(system)


@lru_cache(maxsize=16)
def compiled_derivatives(system: System, forward_mode: bool = False) -> Derivatives:
    """The library of :func:`derivatives` (memoized); ``forward_mode``: the forward mode of
    ``derivative_engine.h`` even where the recursions of screw joints apply (the tests compare
    the two)."""
    units = derivative_units(system, forward_mode)
    # the derivative unit's loops over the variables (and the sparse solves' right-hand sides)
    # vectorize at -O3 (Talos, f = 38, batch per state: forward 125 -> 60 µs, inverse 37 -> 35;
    # Solo-12 forward 24 -> 7.7, inverse 9.5 -> 4.7; no reassociation: the same numbers)
    flags: tuple[tuple[str, ...], ...] = ((), (), ("-O3",))
    key = content_key(_GENERATOR_VERSION, "derivatives", *units, repr(flags))
    lib = build(key, units, unit_flags=flags)
    vp, lg = ctypes.c_void_p, ctypes.c_long
    lib.jd_inverse_derivatives_batch.restype = lg
    lib.jd_inverse_derivatives_batch.argtypes = [lg, vp, vp, vp, vp, vp, lg, vp, lg, vp, vp]
    lib.jd_forward_derivatives_batch.restype = lg
    lib.jd_forward_derivatives_batch.argtypes = [lg, vp, vp, vp, vp, lg, vp, lg, vp, vp]
    dbl = ctypes.c_double
    lib.jd_inverse_derivatives.restype = ctypes.c_int
    lib.jd_inverse_derivatives.argtypes = [vp, vp, vp, dbl, vp, vp, vp]
    lib.jd_forward_derivatives.restype = ctypes.c_int
    lib.jd_forward_derivatives.argtypes = [vp, vp, dbl, vp, vp, vp]
    return Derivatives(system, lib, key, forward_mode)


__all__ = ["Derivatives", "ForwardDerivatives", "InverseDerivatives", "derivatives",
           "derivative_units"]
