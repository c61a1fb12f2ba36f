"""n_link_pendulum_on_cart(n) against sympy.physics.mechanics' KanesMethod on sympy's own model:
M equals sympy's mass matrix and q - k equals its forcing vector, both evaluated directly (no
solve), to the rounding of sums of 6p products relative to the summed terms
(tests/tolerance.py)."""

import numpy as np
import pytest
import sympy as sp
from sympy.physics.mechanics import dynamicsymbols
from sympy.physics.mechanics.models import n_link_pendulum_on_cart as sympy_model

from jourdain.models import n_link_pendulum_on_cart
from tests.tolerance import assert_close_eval


@pytest.mark.parametrize("n", range(1, 7))
def test_cart_pendulum_matches_kanes_method(n, rng):
    kane = sympy_model(n, cart_force=True)
    m = sp.symbols(f"m:{n + 1}")
    l = sp.symbols(f"l:{n}")
    g = sp.Symbol("g")
    F = dynamicsymbols("F")
    args = [*kane.q, *kane.u, *m, *l, g, F]
    f_M = sp.lambdify(args, kane.mass_matrix)
    f_F = sp.lambdify(args, kane.forcing)
    system = n_link_pendulum_on_cart(n)
    for _ in range(5):
        pars = {str(s): v for s, v in zip([*m, *l, g], rng.uniform(0.5, 2.0, 2 * n + 2),
                                          strict=True)}
        y, yd, force = rng.uniform(-3, 3, n + 1), rng.uniform(-3, 3, n + 1), rng.uniform(-2, 2)
        vals = [*y, *yd, *(pars[str(s)] for s in [*m, *l, g]), force]
        M_ref = np.array(f_M(*vals), dtype=float)
        F_ref = np.array(f_F(*vals), dtype=float).ravel()
        out = system.evaluate(y, yd, parameters=pars, inputs={"F": force})
        J, Mb = np.abs(out["J_bar"]), np.abs(out["M_bar"])
        n6 = J.shape[0]
        assert_close_eval(out["M"], M_ref, n6, (J.T @ Mb @ J).max(), err_msg="M")
        terms = J.T @ (np.abs(out["q_c"]) + np.abs(out["q_e"]))
        assert_close_eval(out["q"] - out["k"], F_ref, n6, terms.max(), err_msg="q - k")
