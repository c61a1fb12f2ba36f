"""Pinocchio's derivatives of the dynamics mapped to jourdain's coordinates (issue 37).

jourdain's coordinates ``y`` and Pinocchio's configuration ``q`` and velocity ``ν`` are related
by a chart ``q = q(y)`` whose tangent map is a matrix ``T(y)`` (nv × f, square here):

    ν = T(y)·ẏ,      ν̇ = T(y)·ÿ + c(y, ẏ),      c = Ṫ(y, ẏ)·ẏ.

For a random tree (:func:`benchmarks.pinocchio_models.tree_model`) every Pinocchio joint has one
coordinate and ``T`` is the permutation of the :class:`~benchmarks.pinocchio_models.TreeIndex`
(``c = 0``). For a URDF robot (:class:`tests.reference.test_urdf_pinocchio.Twin`) revolute and
continuous joints map 1:1 (a continuous joint's ``q = (cos θ, sin θ)`` has the tangent ``θ̇``),
and the free flyer's ``q = (p, quaternion)``, ``ν = (Rᵀṗ, ω_body)`` against jourdain's
``y = (p, yaw, pitch, roll)``, ``R = Rz·Ry·Rx``, gives the block ``diag(Rᵀ, E(θ))``
(``ω = E·θ̇``, :func:`tests.reference.test_urdf_pinocchio.zyx_rates`) and
``c = (−ω × Rᵀṗ, Ė·θ̇)``.

**Tangent-space convention.** Pinocchio differentiates with respect to ``q`` along its tangent
space: ``dtau_dq·δ`` is the change of τ from ``q`` to ``q ⊕ δ = integrate(q, δ)`` (for the free
flyer ``M(q)·exp(δ)`` in SE(3), δ in the body frame). The claim that ``T`` is also the tangent
map of the *configuration*, ``q(y + δy) = q(y) ⊕ (T(y)·δy + O(|δy|²))``, holds because
``M(y)⁻¹·∂M/∂y_j = (Rᵀ·∂p/∂y_j, (Rᵀ·∂R/∂y_j)^∨) = T[:, j]``; :func:`tangent_map_error` checks it
with ``pin.difference`` (the test does, for Solo-12).

**Inverse dynamics.** jourdain's ``τ_j = M·ÿ + k − q`` (the generalized force that makes ÿ
happen) and Pinocchio's ``τ_p = rnea(q, ν, ν̇)`` are related by ``M = TᵀM_pT``,
``k − q = Tᵀ(nle_p + M_p·c)``, so

    τ_j(y, ẏ, ÿ) = T(y)ᵀ·τ_p(q(y), T(y)·ẏ, T(y)·ÿ + c(y, ẏ))

and by the chain rule, with ``∂_j = ∂/∂y_j``, ``D_q, D_v`` Pinocchio's ``dtau_dq, dtau_dv``:

    ∂τ_j/∂y_j = (∂_jT)ᵀ·τ_p + Tᵀ·(D_q·T[:, j] + D_v·(∂_jT)·ẏ + M_p·((∂_jT)·ÿ + ∂_jc))
    ∂τ_j/∂ẏ  = Tᵀ·(D_v·T + M_p·∂c/∂ẏ)
    ∂τ_j/∂ÿ  = Tᵀ·M_p·T = M

**Forward dynamics** under a generalized force ``τ_j`` held fixed (jourdain's ``B·u`` of
inputs; 0 without): ``ÿ = T⁻¹·(a_p − c)``, ``a_p = aba(q, T·ẏ, τ_p)``, ``τ_p = T⁻ᵀ·τ_j``, so
``∂_jτ_p = −T⁻ᵀ·(∂_jT)ᵀ·τ_p``, and with ``A_q, A_v`` Pinocchio's ``ddq_dq, ddq_dv``:

    ∂ÿ/∂y_j = T⁻¹·(A_q·T[:, j] + A_v·(∂_jT)·ẏ + M_p⁻¹·∂_jτ_p − ∂_jc − (∂_jT)·ÿ)
    ∂ÿ/∂ẏ  = T⁻¹·(A_v·T − ∂c/∂ẏ)
    ∂ÿ/∂τ_j = M⁻¹ = T⁻¹·M_p⁻¹·T⁻ᵀ     (so ∂ÿ/∂u = M⁻¹·B)

``∂_jT``, ``∂_jc`` and ``∂c/∂ẏ`` come from the closed forms of T and c by the complex step
``∂g/∂x_j = Im g(x + i·h·e_j)/h`` (:func:`complex_step`): no subtraction, so exact to rounding
for any small ``h``.

Pinocchio's ``computeRNEADerivatives``/``computeABADerivatives`` fill ``data.M`` and
``data.Minv`` in full (symmetric), and like ``crba`` they assume joints added depth-first, which
``tree_model`` does.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

#: step of the complex step: far below any rounding, since nothing is subtracted
COMPLEX_STEP = 1e-30

TangentFn = Callable[[np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]


def complex_step(fn: Callable[[np.ndarray], np.ndarray], x: np.ndarray) -> np.ndarray:
    """``∂fn/∂x`` by the complex step, stacked along a new last axis (``fn`` analytic and
    written with complex-safe operations)."""
    x = np.asarray(x, dtype=float)
    cols = []
    for j in range(x.size):
        xc = x.astype(complex)
        xc[j] += 1j * COMPLEX_STEP
        cols.append(np.imag(fn(xc)) / COMPLEX_STEP)
    return np.stack(cols, axis=-1)


@dataclass(frozen=True)
class Chart:
    """Pinocchio's state at one jourdain state ``(y, ẏ)`` and the tangent map's derivatives.

    q: Pinocchio's configuration ``q(y)``; T: (nv, f), ``ν = T·ẏ``; c: (nv,) ``Ṫ·ẏ``;
    T_y: (nv, f, f), ``T_y[:, :, j] = ∂T/∂y_j``; c_y, c_yd: (nv, f), ``∂c/∂y``, ``∂c/∂ẏ``.
    """

    y: np.ndarray
    yd: np.ndarray
    q: np.ndarray
    T: np.ndarray
    c: np.ndarray
    T_y: np.ndarray
    c_y: np.ndarray
    c_yd: np.ndarray

    @property
    def v(self) -> np.ndarray:
        """Pinocchio's velocity ``ν = T·ẏ``."""
        return self.T @ self.yd

    @classmethod
    def at(cls, q: np.ndarray, tangent: TangentFn, y: np.ndarray, yd: np.ndarray) -> Chart:
        """The chart at ``(y, ẏ)`` from ``q = q(y)`` and ``tangent(y, ẏ) -> (T, c)`` (closed
        forms, complex-safe)."""
        y, yd = np.asarray(y, dtype=float), np.asarray(yd, dtype=float)
        T, c = tangent(y, yd)
        return cls(y, yd, np.asarray(q, dtype=float), np.real(T), np.real(c),
                   complex_step(lambda x: tangent(x, yd.astype(complex))[0], y),
                   complex_step(lambda x: tangent(x, yd.astype(complex))[1], y),
                   complex_step(lambda x: tangent(y.astype(complex), x)[1], yd))


def inverse_dynamics(model: Any, data: Any, chart: Chart, ydd: np.ndarray) -> dict[str, np.ndarray]:
    """``tau, tau_y, tau_yd, tau_ydd`` of ``τ_j = M·ÿ + k − q`` in jourdain's coordinates from
    ``pin.computeRNEADerivatives`` (module docstring); ``tau_ydd`` is ``TᵀM_pT = M``."""
    import pinocchio as pin

    T, T_y, yd = chart.T, chart.T_y, chart.yd
    a = T @ ydd + chart.c
    tau_p = pin.rnea(model, data, chart.q, chart.v, a).copy()
    Dq, Dv, Mp = (np.array(x) for x in pin.computeRNEADerivatives(model, data, chart.q,
                                                                      chart.v, a))
    Ty_yd = np.einsum("ikj,k->ij", T_y, yd)   # column j: (∂_jT)·ẏ
    Ty_ydd = np.einsum("ikj,k->ij", T_y, ydd)  # column j: (∂_jT)·ÿ
    tau_y = (np.einsum("ikj,i->kj", T_y, tau_p)
             + T.T @ (Dq @ T + Dv @ Ty_yd + Mp @ (Ty_ydd + chart.c_y)))
    return {"tau": T.T @ tau_p, "tau_y": tau_y, "tau_yd": T.T @ (Dv @ T + Mp @ chart.c_yd),
            "tau_ydd": T.T @ Mp @ T, "M_p": Mp}


def forward_dynamics(model: Any, data: Any, chart: Chart, tau: np.ndarray | None = None
                     ) -> dict[str, np.ndarray]:
    """``ydd, ydd_y, ydd_yd, Minv`` of ``ÿ = M⁻¹(q − k + τ)`` in jourdain's coordinates from
    ``pin.computeABADerivatives`` (module docstring); ``tau`` (f,) a generalized force in
    jourdain's coordinates held fixed (``B·u``; None: 0). ``Minv`` is ``∂ÿ/∂τ``."""
    import pinocchio as pin

    T, T_y, yd = chart.T, chart.T_y, chart.yd
    nv = T.shape[0]
    Tinv = np.linalg.inv(T)
    tau_p = np.zeros(nv) if tau is None else Tinv.T @ np.asarray(tau, dtype=float)
    a_p = pin.aba(model, data, chart.q, chart.v, tau_p).copy()
    Aq, Av, Minv_p = (np.array(x) for x in pin.computeABADerivatives(
        model, data, chart.q, chart.v, tau_p))
    ydd = Tinv @ (a_p - chart.c)
    Ty_yd = np.einsum("ikj,k->ij", T_y, yd)
    Ty_ydd = np.einsum("ikj,k->ij", T_y, ydd)
    tau_p_y = -Tinv.T @ np.einsum("ikj,i->kj", T_y, tau_p)  # column j: ∂_jτ_p
    return {"ydd": ydd,
            "ydd_y": Tinv @ (Aq @ T + Av @ Ty_yd + Minv_p @ tau_p_y - chart.c_y - Ty_ydd),
            "ydd_yd": Tinv @ (Av @ T - chart.c_yd), "Minv": Tinv @ Minv_p @ Tinv.T,
            "Minv_p": Minv_p}


# --- the charts ------------------------------------------------------------------------------
def tree_tangent(index: Any) -> TangentFn:
    """``(T, c)`` of a :func:`~benchmarks.pinocchio_models.tree_model` twin: one Pinocchio
    coordinate per jourdain coordinate, ``q[index.v] = y``, so T is a constant permutation."""
    f = len(index.v)
    P = np.zeros((f, f))
    P[index.v, np.arange(f)] = 1.0

    def tangent(y: np.ndarray, yd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dtype = np.result_type(y, yd)
        return P.astype(dtype), np.zeros(f, dtype=dtype)

    return tangent


def _rot(axis: str, a: Any) -> np.ndarray:
    """Elementary rotation (complex-safe)."""
    c, s = np.cos(a), np.sin(a)
    o, z = np.ones_like(c), np.zeros_like(c)
    return {"x": np.array([[o, z, z], [z, c, -s], [z, s, c]]),
            "y": np.array([[c, z, s], [z, o, z], [-s, z, c]]),
            "z": np.array([[c, -s, z], [s, c, z], [z, z, o]])}[axis]


def free_flyer_block(angles: np.ndarray, pd: np.ndarray, angd: np.ndarray
                     ) -> tuple[np.ndarray, np.ndarray]:
    """The free flyer's 6×6 block of T and its 6 entries of ``c = Ṫẏ`` for jourdain's
    ``(p, yaw a, pitch b, roll c)``, ``R = Rz(a)·Ry(b)·Rx(c)``: ``T = diag(Rᵀ, E)``,
    ``c = (−ω × Rᵀṗ, Ė·θ̇)`` with ``ω = E·θ̇`` (complex-safe)."""
    a, b, c = angles
    ad, bd, cd = angd
    R = _rot("z", a) @ _rot("y", b) @ _rot("x", c)
    sb, cb, sc, cc = np.sin(b), np.cos(b), np.sin(c), np.cos(c)
    z, o = 0.0 * b, 1.0 + 0.0 * b
    E = np.array([[-sb, z, o], [sc * cb, cc, z], [cc * cb, -sc, z]])
    Edot = (bd * ad * np.array([-cb, -sc * sb, -cc * sb])
            + cd * (ad * np.array([z, cc * cb, -sc * cb]) + bd * np.array([z, -sc, -cc])))
    omega = E @ angd
    T = np.zeros((6, 6), dtype=np.result_type(R, E))
    T[:3, :3], T[3:, 3:] = R.T, E
    return T, np.concatenate([-np.cross(omega, R.T @ pd), Edot])


def urdf_tangent(twin: Any) -> TangentFn:
    """``(T, c)`` of a :class:`~tests.reference.test_urdf_pinocchio.Twin` (one-coordinate
    joints and a free flyer; the same closed forms as ``Twin.state``, complex-safe)."""
    f = twin.system.f
    blocks = []
    for jid, ix in twin.blocks:
        jm = twin.pin.joints[jid]
        kind = "one" if jm.nv == 1 else jm.shortname()
        if kind not in ("one", "JointModelFreeFlyer"):
            raise NotImplementedError(f"no closed-form tangent map for {kind}")
        blocks.append((kind, jm.idx_v, list(ix)))

    def tangent(y: np.ndarray, yd: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        dtype = np.result_type(y, yd)
        T, c = np.zeros((f, f), dtype=dtype), np.zeros(f, dtype=dtype)
        for kind, iv, ix in blocks:
            if kind == "one":
                T[iv, ix[0]] = 1.0
                continue
            Tb, cb = free_flyer_block(y[ix[3:]], yd[ix[:3]], yd[ix[3:]])
            T[iv:iv + 6, ix] = Tb
            c[iv:iv + 6] = cb
        return T, c

    return tangent


def tangent_map_error(model: Any, q_of_y: Callable[[np.ndarray], np.ndarray], T: np.ndarray,
                      y: np.ndarray, h: float) -> float:
    """``max|(q(y + h·e_j) ⊖ q(y − h·e_j))/(2h) − T[:, j]|`` over j, ``⊖`` Pinocchio's
    ``difference`` (its tangent space): O(h²) if T is the tangent map of ``q(y)``."""
    import pinocchio as pin

    err = 0.0
    for j in range(len(y)):
        e = np.zeros(len(y))
        e[j] = h
        d = pin.difference(model, q_of_y(y - e), q_of_y(y + e)) / (2 * h)
        err = max(err, float(np.abs(d - T[:, j]).max()))
    return err
