"""An independent reference for the spin-up of a rotating cantilever of Kane, Ryan & Banerjee
(T. R. Kane, R. R. Ryan, A. K. Banerjee, "Dynamics of a cantilever beam attached to a moving
base", J. Guidance, Control, and Dynamics 10(2), 1987, 139–151), computed with
sympy.physics.mechanics (LagrangesMethod) and scipy.integrate.solve_ivp. It does not import
jourdain.

**Problem (KRB's example).** A uniform beam, L = 10 m, ρA = 1.2 kg/m, EI = 1.4e4 N·m²,
EA = 2.8e7 N (E = 7e10 Pa, A = 4e-4 m², I = 2e-7 m⁴), clamped on the rotation axis (no hub
radius), turning in a horizontal plane (no gravity) with the prescribed hub angle

    θ(t) = (Ω_s/T_s)·(t²/2 + (T_s/2π)²·(cos(2πt/T_s) − 1))   for t ≤ T_s,
    θ(t) = Ω_s·(t − T_s/2)                                   for t > T_s,

Ω_s = 6 rad/s, T_s = 15 s, from rest and undeformed. Output: the tip's transverse in-plane
deflection v_tip(t) = v(L, t) in the rotating frame (negative = lagging the rotation).

**Formulation.** B is the frame turning with the hub (b₁ along the undeformed beam, b₂ in the
plane of rotation). The material point at x has, in B,

    stiffening ("consistent", KRB):  r = (x + s(x) − ½∫₀ˣ (∂v/∂σ)² dσ)·b₁ + v(x)·b₂,
    linear (conventional):           r = (x + s(x))·b₁ + v(x)·b₂,

with the assumed modes v = Σ φ_i(x)·q_i (the clamped-free Euler–Bernoulli eigenfunctions,
∫φ_i² = L, φ_i(L) = ±2) and s = Σ sin((2j − 1)πx/(2L))·p_j (the clamped-free axial modes). The
kinetic energy T = ∫₀ᴸ ½ρA·|ṙ|² dx uses the inertial velocity ṙ = ᴺd r/dt (sympy.physics.vector:
the point located in B, B oriented by θ(t) about N.z) with every term of the foreshortening
kept (it makes T quartic in q); the strain energy is V = ½∫EA·s'² + EI·v''² dx. The spatial
integrals: the kinetic energy density is expanded symbolically in the coordinates and in the
values at x of the shape functions (x, φ_i, ψ_j, H_ij(x) = ∫₀ˣ φ_i'φ_j' dσ), and each monomial
of shape values is integrated by 64-point Gauss–Legendre quadrature (H_ij at the nodes by a
64-point rule on [0, x]); 128 points change the mass matrix and forcing by < 1e-13 relative.
Lagrange's equations of L = T − V come from LagrangesMethod (θ enters as a prescribed
dynamicsymbol: only θ̇ and θ̈ appear), M and F are lambdified (one function, common
subexpressions shared), and solve_ivp integrates M·[q̈; p̈] = F with Radau at rtol 1e-10,
atol 1e-12 (with 3 + 1 modes DOP853 and LSODA at 1e-10 and Radau at 1e-12 agree with it to
1e-10 m). The linear variant diverges here: beyond ω₁ = 3.798 rad/s (from t ≈ 8.5 s) its
centrifugal softening (ω² = ω₀² − Ω²) is not balanced by any stiffening.

**Convergence** (stiffening variant; peak = the extreme of v_tip on [0, 20] s, located on the
dense output to 1e-9 s; m):

    bending  axial   peak v_tip (t/s)         v_tip(10 s)   v_tip(15 s)   v_tip(20 s)
       2       0    −0.57501987 (6.7635)     −0.36065236   0.00126421    0.00115027
       2       1    −0.57504538 (6.7637)     −0.36070461   0.00127073    0.00114127
       3       1    −0.57594349 (6.7697)     −0.36372231   0.00160199    0.00059608
       4       0    −0.57581199 (6.7691)     −0.36356412   0.00164780    0.00050487
       4       1    −0.57583763 (6.7692)     −0.36361687   0.00165441    0.00049457
       4       2    −0.57583772 (6.7692)     −0.36361705   0.00165447    0.00049446
       4       3    −0.57583772 (6.7692)     −0.36361705   0.00165447    0.00049446
       5       1    −0.57588157 (6.7695)     −0.36377675   0.00167034    0.00046626
       5       2    −0.57588167 (6.7695)     −0.36377693   0.00167041    0.00046616
       6       1    −0.57586933 (6.7695)     −0.36375770   0.00167506    0.00045676
       7       1    −0.57587612 (6.7695)     −0.36378209   0.00167717    0.00045301

One axial mode suffices (the second changes nothing above 2e-7 m); the bending series
alternates and shrinks slowly (5 → 6 → 7 modes: 1.2e-5, 7e-6 m on the peak, 2e-5 on
v_tip(10 s), 5e-6 on v_tip(15 s), 1e-5, 4e-6 on v_tip(20 s)). The default, 5 bending modes and
1 axial mode, is therefore accurate to about 2e-5 m absolute (≈ 2e-5 relative on the peak
−0.57588 m; v_tip after the spin-up is a vibration of ≈ 2 mm whose digits beyond 1e-5 m are not
settled). One call at the default costs ≈ 10 s for the derivation (kept in memory, per
process) and ≈ 6 s for the integration on one core (measured on a shared 2-core machine);
4 bending modes cost about 2/3 of that and are off by 4e-5 m on the peak, 1.6e-4 m at 10 s.

**Checks without jourdain** (tests/reference/test_krb_reference.py): the linearization about
steady spin gives Southwell's ω₁² = ω₀² + (K₁ − 1)·Ω² with K₁ = 1.1933 (in the plane of
rotation the −Ω² of centrifugal softening comes on top of the flapwise coefficient; measured
1.19323, the 1e-4 below being the Coriolis coupling with the axial mode), the linear variant's
ω₁² = ω₀² − Ω², and the tabulated rotating-cantilever frequencies (Ω̄ = 1 and 6).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import sympy as sp
from scipy.integrate import solve_ivp
from scipy.optimize import brentq, minimize_scalar
from sympy.physics.mechanics import LagrangesMethod, Point, ReferenceFrame, dynamicsymbols

#: Kane, Ryan & Banerjee (1987), the spin-up example
L_BEAM = 10.0  # m
RHO_A = 1.2  # kg/m
EI = 1.4e4  # N·m²  (E = 7e10 Pa, I = 2e-7 m⁴)
EA = 2.8e7  # N     (E = 7e10 Pa, A = 4e-4 m²)
OMEGA_S = 6.0  # rad/s
T_S = 15.0  # s

#: the converged mode counts (module docstring)
N_BENDING = 5
N_AXIAL = 1


def hub_angle(t: float) -> tuple[float, float, float]:
    """The prescribed hub angle θ(t) and its rates θ̇, θ̈ (module docstring)."""
    if t <= T_S:
        a = 2.0 * math.pi / T_S
        theta = OMEGA_S / T_S * (t * t / 2.0 + (math.cos(a * t) - 1.0) / (a * a))
        return theta, OMEGA_S / T_S * (t - math.sin(a * t) / a), OMEGA_S / T_S * (
            1.0 - math.cos(a * t))
    return OMEGA_S * (t - T_S / 2.0), OMEGA_S, 0.0


@functools.cache
def cantilever_roots(n: int) -> tuple[float, ...]:
    """The first n roots βL of the clamped-free frequency equation 1 + cos z·cosh z = 0."""
    f = lambda z: math.cos(z) + 1.0 / math.cosh(z)  # noqa: E731  (the same roots, bounded)
    return tuple(brentq(f, (k - 1) * math.pi, k * math.pi, xtol=1e-15, rtol=1e-15)
                 for k in range(1, n + 1))


def bending_shape(i: int, x: np.ndarray, d: int = 0) -> np.ndarray:
    """The d-th x-derivative of the i-th (1-based) clamped-free Euler–Bernoulli eigenfunction
    φ_i = cosh βx − cos βx − σ(sinh βx − sin βx), ∫₀ᴸ φ_i² dx = L, φ_i(L) = ±2. The hyperbolic
    part is written ½((1 − σ)e^{βx} + (1 + σ)e^{−βx}) with 1 − σ formed without cancellation."""
    z = cantilever_roots(i)[-1]
    beta = z / L_BEAM
    one_minus_sigma = (math.sin(z) - math.cos(z) - math.exp(-z)) / (math.sinh(z) + math.sin(z))
    sigma = 1.0 - one_minus_sigma
    bx = beta * np.asarray(x, dtype=float)
    ep, em = np.exp(bx), np.exp(-bx)
    # d-th derivatives of cosh − σ sinh (even/odd swap) and of −cos + σ sin
    hyp = 0.5 * (one_minus_sigma * ep + (-1) ** d * (1.0 + sigma) * em)
    trig = [-np.cos(bx) + sigma * np.sin(bx), np.sin(bx) + sigma * np.cos(bx),
            np.cos(bx) - sigma * np.sin(bx), -np.sin(bx) - sigma * np.cos(bx)][d % 4]
    return beta ** d * (hyp + trig)


def axial_shape(j: int, x: np.ndarray, d: int = 0) -> np.ndarray:
    """The d-th x-derivative of the j-th (1-based) clamped-free axial mode sin(γx),
    γ = (2j − 1)π/(2L)."""
    g = (2 * j - 1) * math.pi / (2.0 * L_BEAM)
    gx = g * np.asarray(x, dtype=float)
    return g ** d * [np.sin(gx), np.cos(gx), -np.sin(gx), -np.cos(gx)][d % 4]


def _gauss(a: float, b: float, n: int) -> tuple[np.ndarray, np.ndarray]:
    z, w = np.polynomial.legendre.leggauss(n)
    return 0.5 * (b - a) * z + 0.5 * (b + a), 0.5 * (b - a) * w


@dataclass(frozen=True)
class BeamEquations:
    """M(x)·[q̈; p̈] = F(x, θ̇, θ̈) of the beam, lambdified. ``mf(q, p, qd, pd, w, wd)`` returns
    (M, F); ``tip`` the values φ_i(L) (v_tip = tip·q)."""

    n_bending: int
    n_axial: int
    stiffening: bool
    mf: Callable
    tip: np.ndarray

    @property
    def n(self) -> int:
        return self.n_bending + self.n_axial

    def rhs(self, x: np.ndarray, w: float, wd: float) -> np.ndarray:
        """ẋ of the state x = (q, p, q̇, ṗ) at the hub rates θ̇ = w, θ̈ = wd."""
        n, nb = self.n, self.n_bending
        M, F = self.mf(x[:nb], x[nb:n], x[n:n + nb], x[n + nb:], w, wd)
        return np.concatenate([x[n:], np.linalg.solve(M, np.ravel(F))])


@functools.cache
def beam_equations(n_bending: int, n_axial: int, stiffening: bool = True,
                   n_gauss: int = 64) -> BeamEquations:
    """Lagrange's equations of the beam on the prescribed hub, derived with
    sympy.physics.mechanics (see the module docstring)."""
    nb, na = n_bending, n_axial
    q = dynamicsymbols(f"q1:{nb + 1}")
    p = dynamicsymbols(f"p1:{na + 1}") if na else []
    theta = dynamicsymbols("theta")
    t = dynamicsymbols._t
    N = ReferenceFrame("N")
    B = N.orientnew("B", "Axis", (theta, N.z))
    O = Point("O")
    O.set_vel(N, 0)
    # the values at the material point x of the shape functions: X = x, phi_i = φ_i(x),
    # psi_j = ψ_j(x), h_ij = H_ij(x) = ∫₀ˣ φ_i'φ_j' dσ (i ≤ j)
    X = sp.Symbol("X")
    phi = sp.symbols(f"phi1:{nb + 1}")
    psi = sp.symbols(f"psi1:{na + 1}") if na else ()
    h = {(i, j): sp.Symbol(f"h{i}_{j}") for i in range(nb) for j in range(i, nb)}
    v = sum(f * qi for f, qi in zip(phi, q, strict=True))
    s = sum(f * pj for f, pj in zip(psi, p, strict=True))
    c = sp.Rational(1, 2) * sum(h[min(i, j), max(i, j)] * q[i] * q[j]
                                for i in range(nb) for j in range(nb))
    axial = X + s - c if stiffening else X + s
    P = O.locatenew("P", axial * B.x + v * B.y)
    vel = P.pos_from(O).dt(N)
    density = sp.expand(vel.dot(vel) / 2)  # kinetic energy per unit mass at x

    # ∫₀ᴸ ρA·density dx: every monomial of the shape values integrated by Gauss–Legendre
    xg, wg = _gauss(0.0, L_BEAM, n_gauss)
    values = {X: xg}
    values.update({f: bending_shape(i + 1, xg) for i, f in enumerate(phi)})
    values.update({f: axial_shape(j + 1, xg) for j, f in enumerate(psi)})
    for (i, j), sym in h.items():
        hv = np.empty(n_gauss)
        for k, xk in enumerate(xg):
            xs, ws = _gauss(0.0, xk, n_gauss)
            hv[k] = ws @ (bending_shape(i + 1, xs, 1) * bending_shape(j + 1, xs, 1))
        values[sym] = hv
    shape_syms = set(values)
    T_terms = []
    integrals: dict[sp.Expr, float] = {}
    for term in density.args if density.is_Add else (density,):
        coeff, shape_part = sp.S.One, sp.S.One
        for factor in sp.Mul.make_args(term):
            base = factor.as_base_exp()[0]
            if base in shape_syms:
                shape_part *= factor
            else:
                coeff *= factor
        if shape_part not in integrals:
            f = np.ones(n_gauss)
            for base, e in shape_part.as_powers_dict().items():
                if base != 1:
                    f = f * values[base] ** int(e)
            integrals[shape_part] = float(wg @ f)
        T_terms.append(RHO_A * integrals[shape_part] * coeff)
    T = sp.Add(*T_terms)
    # strain energy ½∫EA s'² + EI v''² dx (same quadrature)
    dphi2 = np.array([bending_shape(i + 1, xg, 2) for i in range(nb)])
    Kb = EI * (dphi2 * wg) @ dphi2.T
    V = sum(Kb[i, j] * q[i] * q[j] for i in range(nb) for j in range(nb)) / 2
    if na:
        dpsi = np.array([axial_shape(j + 1, xg, 1) for j in range(na)])
        Ka = EA * (dpsi * wg) @ dpsi.T
        V += sum(Ka[i, j] * p[i] * p[j] for i in range(na) for j in range(na)) / 2

    lm = LagrangesMethod(T - V, [*q, *p])
    lm.form_lagranges_equations()
    M, F = lm.mass_matrix, lm.forcing
    coords = [*q, *p]
    Q = sp.symbols(f"Q0:{nb + na}")
    U = sp.symbols(f"U0:{nb + na}")
    W, Wd = sp.symbols("W Wd")
    rep = {theta.diff(t, 2): Wd, theta.diff(t): W}
    rep.update({qi.diff(t): ui for qi, ui in zip(coords, U, strict=True)})
    rep2 = dict(zip(coords, Q, strict=True))
    M = M.xreplace(rep).xreplace(rep2)
    F = F.xreplace(rep).xreplace(rep2)
    assert not (M.free_symbols | F.free_symbols) - {*Q, *U, W, Wd}, "unexpected symbols"
    mf_flat = sp.lambdify([Q[:nb], Q[nb:], U[:nb], U[nb:], W, Wd], [M, F], modules="numpy",
                          cse=True)
    tip = np.array([bending_shape(i + 1, np.array([L_BEAM]))[0] for i in range(nb)])
    return BeamEquations(nb, na, stiffening, mf_flat, tip)


def _hub_rhs(eq: BeamEquations) -> Callable:
    def f(t, x):
        _, w, wd = hub_angle(t)
        return eq.rhs(x, w, wd)
    return f


def simulate(t_end: float = 20.0, *, stiffening: bool = True, n_bending: int = N_BENDING,
             n_axial: int = N_AXIAL, rtol: float = 1e-10, atol: float = 1e-12,
             method: str = "Radau", t_eval=None, dense_output: bool = False):
    """The spin-up from rest, undeformed, at t = 0 to ``t_end``: (equations, solve_ivp's
    result); the state is (q, p, q̇, ṗ)."""
    eq = beam_equations(n_bending, n_axial, stiffening)
    sol = solve_ivp(_hub_rhs(eq), (0.0, t_end), np.zeros(2 * eq.n), method=method,
                    t_eval=t_eval, rtol=rtol, atol=atol, dense_output=dense_output)
    return eq, sol


def krb_tip_deflection(t_eval, *, stiffening: bool = True, n_bending: int = N_BENDING,
                       n_axial: int = N_AXIAL, rtol: float = 1e-10, atol: float = 1e-12,
                       method: str = "Radau") -> np.ndarray:
    """The tip's transverse deflection v_tip(t) = v(L, t) (m, in the rotating frame; negative
    = lagging behind the hub's rotation) at the times ``t_eval`` (ascending, ≥ 0), from
    solve_ivp at ``rtol``, ``atol`` with ``method``. Where the integration stops early (a
    failure of solve_ivp) the times after its end get NaN."""
    t_eval = np.atleast_1d(np.asarray(t_eval, dtype=float))
    if t_eval.size == 0:
        return np.zeros(0)
    if np.any(np.diff(t_eval) < 0) or t_eval[0] < 0:
        raise ValueError("t_eval must be ascending and start at t >= 0")
    if t_eval[-1] == 0.0:
        return np.zeros(t_eval.size)
    eq, sol = simulate(float(t_eval[-1]), stiffening=stiffening, n_bending=n_bending,
                       n_axial=n_axial, rtol=rtol, atol=atol, method=method, t_eval=t_eval)
    out = np.full(t_eval.size, np.nan)
    out[:sol.y.shape[1]] = eq.tip @ sol.y[:n_bending]
    return out


def peak_tip_deflection(t_end: float = 20.0, **kwargs) -> tuple[float, float]:
    """(t, v_tip) where |v_tip| is largest on [0, t_end]: a 1 ms grid of the dense output,
    refined by a bounded scalar search around its best point (keyword arguments as for
    :func:`simulate`)."""
    eq, sol = simulate(t_end, dense_output=True, **kwargs)
    nb = eq.n_bending
    tip = lambda t: float(eq.tip @ sol.sol(t)[:nb])  # noqa: E731
    grid = np.linspace(0.0, t_end, int(round(t_end * 1000)) + 1)
    i = int(np.argmax(np.abs(eq.tip @ sol.sol(grid)[:nb])))
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, grid.size - 1)]
    sign = np.sign(tip(grid[i]))
    r = minimize_scalar(lambda t: -sign * tip(t), bounds=(lo, hi), method="bounded",
                        options={"xatol": 1e-9})
    return float(r.x), tip(r.x)


def spin_equilibrium(eq: BeamEquations, spin: float) -> np.ndarray:
    """The steady state at the constant hub rate θ̇ = ``spin``: straight (q = 0), at rest, with
    the centrifugal stretch p* solving F = 0 (Newton on the axial coordinates)."""
    x = np.zeros(2 * eq.n)
    nb, n = eq.n_bending, eq.n
    for _ in range(4):
        r = eq.rhs(x, spin, 0.0)[n + nb:]
        if not eq.n_axial or np.max(np.abs(r)) == 0.0:
            break
        J = np.empty((eq.n_axial, eq.n_axial))
        for j in range(eq.n_axial):
            xc = x.astype(complex)
            xc[nb + j] += 1e-30j
            J[:, j] = eq.rhs(xc, spin, 0.0)[n + nb:].imag / 1e-30
        x[nb:n] -= np.linalg.solve(J, r)
    return x


def state_matrix(eq: BeamEquations, spin: float) -> np.ndarray:
    """A = ∂ẋ/∂x at the steady state of the constant hub rate ``spin``, by the complex step
    (the lambdified equations are polynomials; exact to rounding)."""
    x0 = spin_equilibrium(eq, spin)
    m = x0.size
    A = np.empty((m, m))
    for j in range(m):
        xc = x0.astype(complex)
        xc[j] += 1e-30j
        A[:, j] = eq.rhs(xc, spin, 0.0).imag / 1e-30
    return A


def bending_frequencies(spin: float, *, stiffening: bool = True, n_bending: int = N_BENDING,
                        n_axial: int = N_AXIAL) -> np.ndarray:
    """The in-plane bending frequencies ω (rad/s, ascending) of the linearization about the
    steady state at the constant hub rate ``spin``: the n_bending smallest |Im λ| of the state
    matrix (the axial ones start at 759 rad/s, above the bending ones for n_bending ≤ 9). Where
    the steady state is unstable (the linear variant above ω₁) the divergent mode gives a real
    λ, reported as −λ."""
    eq = beam_equations(n_bending, n_axial, stiffening)
    lam = np.linalg.eigvals(state_matrix(eq, spin))
    tol = 1e-9 * np.max(np.abs(lam))
    oscillating = lam.imag[lam.imag > tol]
    diverging = lam.real[(np.abs(lam.imag) <= tol) & (lam.real > tol)]
    return np.sort(np.concatenate([-diverging, oscillating]))[:n_bending]
