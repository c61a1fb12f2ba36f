"""n_link_pendulum_on_cart(n) linearized at the upright equilibrium against
sympy.physics.mechanics' KanesMethod.linearize on sympy's own model (A and B of x = [q, u],
u = q̇, input F). The lower blocks of A and B come from solves with M̃ on both sides (sympy's
symbolic inverse, jourdain's factorization), so they agree to cond(M̃)·eps (tests/tolerance.py);
the eigenvalues to their condition numbers times that difference."""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols
from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart
from tests.tolerance import assert_close_solved, eig_with_tol, norm, solve_scale


@pytest.mark.parametrize("n", [1, 2, 3])
def test_upright_A_B_match_kanes_linearize(n, rng):
    kane = sympy_model(n, cart_force=True)
    op = {**{q: 0 for q in kane.q}, **{u: 0 for u in kane.u}}
    A_sym, B_sym, r = kane.linearize(A_and_B=True, op_point=op, new_method=True)
    assert list(r) == [dynamicsymbols("F")]
    m = sp.symbols(f"m:{n + 1}")
    l = sp.symbols(f"l:{n}")
    g = sp.Symbol("g")
    f_A = sp.lambdify([*m, *l, g], A_sym)
    f_B = sp.lambdify([*m, *l, g], B_sym)
    system = n_link_pendulum_on_cart(n)
    lin = system.linearize({c: 0 for c in system.coordinate_names})
    for _ in range(3):
        vals = rng.uniform(0.5, 2.0, 2 * n + 2)
        pars = {str(s): float(v) for s, v in zip([*m, *l, g], vals, strict=True)}
        A_ref = np.array(f_A(*vals), dtype=float)
        B_ref = np.array(f_B(*vals), dtype=float)
        ss = jd.state_space(lin, parameters=pars)
        f, M = n + 1, ss.M_tilde
        assert_close_solved(ss.A, A_ref, [M, M], solve_scale(M, A_ref[f:], (ss.Q, ss.P)),
                            err_msg="A")
        assert_close_solved(ss.B, B_ref, [M, M], solve_scale(M, B_ref[f:], (ss.B_u,)),
                            err_msg="B")
        # upright: divergence (one real eigenvalue > 0 per link), as both agree
        st = jd.stability(ss)
        assert st.verdict == "unstable" and "divergence" in st.reason
        lam_ref, tol = eig_with_tol(A_ref, norm(ss.A - A_ref))
        lam = np.sort_complex(np.linalg.eigvals(ss.A))
        assert np.all(np.abs(lam - lam_ref) <= 2 * tol), (lam, lam_ref, tol)  # two eigensolves


def test_benchmark_script_runs_on_a_tiny_case(tmp_path):
    """benchmarks/linearization.py --quick: both tools run and their A, B agree."""
    import json

    from benchmarks.linearization import main

    out = tmp_path / "lin.json"
    assert main(["--quick", "--repeat", "1", "--timeout", "120", "--json", str(out)]) == 0
    rows = json.loads(out.read_text())["pendulum_on_cart"]
    assert [r["n"] for r in rows] == [1, 2]
    for r in rows:
        assert r["sympy_op_s"] is not None and r["AB_max_rel_diff"] < 1e-12
        assert r["jourdain_ops_op"] > 0 and r["sympy_ops_op"] > 0
