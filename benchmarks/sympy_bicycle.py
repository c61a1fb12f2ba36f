"""The Whipple bicycle of the benchmark (Meijaard et al. 2007) with ``sympy.physics.mechanics``:
Kane's method with the rear wheel's rolling built into its kinematics, the front wheel's
three contact-velocity rows as velocity constraints (dependent speeds) and the front contact's
height as the configuration constraint (the rear frame's pitch dependent), as in sympy's own
bicycle test; written here in the benchmark's own axes and data (x forward, y right, z down,
Table 1 as it is printed), with the coordinates and signs of
:func:`jourdain.models.rolling.benchmark_bicycle` so that the two states compare entry by entry.

Coordinates: yaw ``psi``, lean ``phi``, steer ``delta`` (independent) and the rear frame's pitch
``theta`` (dependent); speeds ``u_phi, u_delta, u_R`` (lean rate, steer rate, rear wheel rate
relative to the rear frame; independent) and ``u_psi, u_theta, u_F`` (dependent). The position
on the ground and the wheel angles are ignorable: the benchmark integrates them beside
(``aux``: the rear wheel centre's velocity and the wheel rates).
"""

from __future__ import annotations

from typing import Any

import sympy as sp
import sympy.physics.mechanics as me

from jourdain.models.rolling import BENCHMARK_BICYCLE

#: the parameters of the model (the forward speed ``v`` enters the nominal state only)
PARAMETERS = tuple(k for k in BENCHMARK_BICYCLE if k != "v")


def whipple_kane(numeric: bool = False) -> dict[str, Any]:
    """Kane's equations of the bicycle (``kanes_equations`` done). ``numeric``: Table 1's values
    put in before the derivation (smaller expressions, a quick check), else symbols.

    Returns ``KM``, the coordinates ``q = [psi, phi, delta, theta]``, the speeds
    ``u = [u_phi, u_delta, u_R, u_psi, u_theta, u_F]`` (independent first), the parameter
    symbols ``par`` (empty when numeric), ``values`` (symbol → number), the velocity-constraint
    rows ``vc`` and the holonomic row ``hol``, and ``aux``: the rear wheel centre's ground
    velocity (x, y) in q, u."""
    sym = {k: sp.Symbol(k) for k in PARAMETERS}
    num = {k: (sp.pi / 10 if k == "lam" else sp.Float(BENCHMARK_BICYCLE[k])) for k in PARAMETERS}
    p = num if numeric else sym
    w, c, lam, g, rR, rF = (p[k] for k in ("w", "c", "lam", "g", "rR", "rF"))
    psi, phi, delta, theta = me.dynamicsymbols("psi phi delta theta")
    u_phi, u_delta, u_R, u_psi, u_theta, u_F = me.dynamicsymbols(
        "u_phi u_delta u_R u_psi u_theta u_F")
    t = me.dynamicsymbols._t

    N = me.ReferenceFrame("N")                        # the ground: z down
    Yf = N.orientnew("Yf", "Axis", (psi, N.z))        # heading
    Lf = Yf.orientnew("Lf", "Axis", (phi, Yf.x))      # lean: Lf.z stays in the wheel's plane
    Bf = Lf.orientnew("Bf", "Axis", (theta, Lf.y))    # rear frame (pitch)
    axis = sp.sin(lam) * Bf.x + sp.cos(lam) * Bf.z    # steer axis: down, tilted back by lam
    Hf = Bf.orientnew("Hf", "Axis", (delta, axis))    # front frame
    Rw, Fw = me.ReferenceFrame("Rw"), me.ReferenceFrame("Fw")  # wheels: spin only matters
    Yf.set_ang_vel(N, u_psi * N.z)
    Lf.set_ang_vel(Yf, u_phi * Yf.x)
    Bf.set_ang_vel(Lf, u_theta * Lf.y)
    Hf.set_ang_vel(Bf, u_delta * axis)
    Rw.set_ang_vel(Bf, u_R * Bf.y)
    Fw.set_ang_vel(Hf, u_F * Hf.y)

    # the rear wheel's material contact point is at rest (its rolling); the centre is rR above
    # it along the lean frame's z (the axle Bf.y = Lf.y is normal to it, the ground's normal in
    # the wheel's plane)
    PR = me.Point("PR")
    PR.set_vel(N, 0)
    CR = PR.locatenew("CR", -rR * Lf.z)
    s0x = w + c - rF * sp.tan(lam)
    S = CR.locatenew("S", s0x * Bf.x + (rR - rF) * Bf.z)          # on the steer axis
    GB = CR.locatenew("GB", p["xB"] * Bf.x + (p["zB"] + rR) * Bf.z)
    GH = S.locatenew("GH", (p["xH"] - s0x) * Hf.x + (p["zH"] + rF) * Hf.z)
    CF = S.locatenew("CF", (rF * sp.tan(lam) - c) * Hf.x)
    # the front contact: from the centre along the ground's downward normal with its part along
    # the axle taken out, normalized, times rF
    k = Yf.z & Hf.y
    PF = CF.locatenew("PF", rF * (Yf.z - k * Hf.y) / sp.sqrt(1 - k**2))
    CR.v2pt_theory(PR, N, Rw)
    GB.v2pt_theory(CR, N, Bf)
    S.v2pt_theory(CR, N, Bf)
    GH.v2pt_theory(S, N, Hf)
    CF.v2pt_theory(S, N, Hf)
    PF.v2pt_theory(CF, N, Fw)

    vc = [PF.vel(N) & Yf.x, PF.vel(N) & Yf.y, PF.vel(N) & Yf.z]
    hol = PF.pos_from(PR) & Yf.z
    bodies = [
        me.RigidBody("B", GB, Bf, p["mB"],
                     (me.inertia(Bf, p["IBxx"], p["IByy"], p["IBzz"], 0, 0, p["IBxz"]), GB)),
        me.RigidBody("H", GH, Hf, p["mH"],
                     (me.inertia(Hf, p["IHxx"], p["IHyy"], p["IHzz"], 0, 0, p["IHxz"]), GH)),
        me.RigidBody("R", CR, Rw, p["mR"], (me.inertia(Bf, p["IRxx"], p["IRyy"], p["IRxx"]), CR)),
        me.RigidBody("F", CF, Fw, p["mF"], (me.inertia(Hf, p["IFxx"], p["IFyy"], p["IFxx"]), CF)),
    ]
    loads = [(pt, b.mass * g * N.z) for pt, b in zip((GB, GH, CR, CF), bodies, strict=True)]
    q = [psi, phi, delta, theta]
    u = [u_phi, u_delta, u_R, u_psi, u_theta, u_F]
    kd = [psi.diff(t) - u_psi, phi.diff(t) - u_phi, delta.diff(t) - u_delta,
          theta.diff(t) - u_theta]
    KM = me.KanesMethod(N, q_ind=q[:3], u_ind=u[:3], kd_eqs=kd, q_dependent=q[3:],
                        configuration_constraints=[hol], u_dependent=u[3:],
                        velocity_constraints=vc, constraint_solver="CRAMER")
    KM.kanes_equations(bodies, loads)
    vel = CR.vel(N)
    return {"KM": KM, "q": q, "u": u, "vc": vc, "hol": hol,
            "par": [] if numeric else [sym[k] for k in PARAMETERS],
            "values": {sym[k]: num[k] for k in PARAMETERS},
            "aux": [vel & N.x, vel & N.y]}


def linear_A(model: dict[str, Any], solver: str = "CRAMER") -> tuple[Any, Any]:
    """``KanesMethod.linearize(A_and_B=True)`` about upright straight running at speed ``v``
    (the wheels' rates ``-v/rR``, ``-v/rF``), as sympy's bicycle test; returns the 6×6 ``A`` in
    ``[psi, phi, delta, u_phi, u_delta, u_R]`` (Table 1's numbers put in) and the symbol ``v``.
    The lean and steer block is ``A[1:5, 1:5]``."""
    KM, q, u = model["KM"], model["q"], model["u"]
    t = me.dynamicsymbols._t
    v = sp.Symbol("v")
    vals = model["values"]
    rR, rF = (sp.Symbol("rR"), sp.Symbol("rF")) if model["par"] else (
        vals[sp.Symbol("rR")], vals[sp.Symbol("rF")])
    op = {**dict.fromkeys(q, 0), **dict.fromkeys(u, 0),
          **{ui.diff(t): 0 for ui in u}, u[2]: -v / rR, u[5]: -v / rF}
    A, _, _ = KM.linearize(op_point=op, A_and_B=True, linear_solver=solver)
    return A.xreplace(vals), v


def rhs_functions(model: dict[str, Any]) -> dict[str, Any]:
    """The nonlinear equations lambdified (NumPy, common subexpressions shared), Table 1's
    numbers put in: ``MM(q, u)``, ``F(q, u)`` (Kane's ``mass_matrix`` and ``forcing``: the three
    dynamic rows and the three acceleration constraints, u̇ for all six speeds), the velocity
    constraints' matrix ``Avc(q)`` (``Avc·u = 0``), the holonomic row ``hol(q)`` and the rear
    centre's ground velocity ``aux(q, u)``."""
    KM, q, u, vals = model["KM"], model["q"], model["u"], model["values"]
    plain_q = [sp.Symbol(f"q_{i}") for i in range(len(q))]
    plain_u = [sp.Symbol(f"u_{i}") for i in range(len(u))]
    t = me.dynamicsymbols._t
    sub = {**dict(zip(q, plain_q, strict=True)), **dict(zip(u, plain_u, strict=True))}
    # q̇ → u (the kinematic equations are q̇ = u here) before plain symbols replace q, u
    kd = {qi.diff(t): ui for qi, ui in zip(q, [u[3], u[0], u[1], u[4]], strict=True)}

    def lam(args: list, expr: Any) -> Any:
        return sp.lambdify(args, sp.Matrix(expr).xreplace(kd).xreplace(vals).xreplace(sub),
                           "numpy", cse=True)

    Avc = sp.Matrix(model["vc"]).jacobian(u)
    return {"MM": lam([plain_q, plain_u], KM.mass_matrix),
            "F": lam([plain_q, plain_u], KM.forcing),
            "Avc": lam([plain_q], Avc),
            "hol": lam([plain_q], [model["hol"]]),
            "aux": lam([plain_q, plain_u], model["aux"])}


def make_rhs(fns: dict[str, Any]) -> Any:
    """``ẋ(t, x)`` in ``x = (psi, phi, delta, theta, u_phi, u_delta, u_R, x, y, thetaR,
    thetaF)``: the dependent speeds solved from the velocity constraints at each call, then
    ``MM·u̇ = F``; the rear centre's position and the wheel angles integrated beside."""
    import numpy as np

    MM, F, Avc, aux = fns["MM"], fns["F"], fns["Avc"], fns["aux"]

    def rhs(_t: float, x: Any) -> Any:
        q, ui = x[:4], x[4:7]
        A = np.asarray(Avc(q), dtype=float)
        ud = np.linalg.solve(A[:, 3:], -A[:, :3] @ ui)
        u = np.concatenate([ui, ud])
        udot = np.linalg.solve(np.asarray(MM(q, u), dtype=float),
                               np.asarray(F(q, u), dtype=float).reshape(-1))
        vel = np.asarray(aux(q, u), dtype=float).reshape(-1)
        return np.concatenate([[u[3], u[0], u[1], u[4]], udot[:3], vel, [u[2], u[5]]])

    return rhs
