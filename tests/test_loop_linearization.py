"""The exact linearization of loop systems at rest (jourdain.loops.linearization.
linearize_loop_exact: symbolic derivatives and the constraint forces' geometric stiffness)
against the closed-form four-bar and the finite-difference linearization."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from jourdain.io.modelfile import load_model
from jourdain.loops.linearization import equilibrium, linearize_loop, linearize_loop_exact
from tests.test_loops import four_bar_at_rest
from tests.tolerance import EPS

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def test_exact_linearization_equals_closed_form_four_bar() -> None:
    """examples/four_bar.toml (torsion spring k = 20 on the crank, rest angle 1): M from the
    kinetic energy along the manifold in closed form, K = V''(θ1) of the closed-form
    potential by a five-point difference (error h⁴·V⁽⁶⁾/90 ≈ 1e-12·K at h = 1e-3)."""
    k_s = 20.0
    mf = load_model(EXAMPLES / "four_bar.toml")
    ref = four_bar_at_rest(mf.system, k_s)
    z, K_ref, M_ref, hh = ref.z, ref.K, ref.M, ref.h
    th = float(z[0])
    lin = linearize_loop_exact(mf.system, z)
    assert lin.names == ("theta1",)
    assert abs(lin.M_tilde[0, 0] - M_ref) <= 1e3 * EPS * M_ref
    # the difference quotient's rounding, ε·|V|/h², bounds the reference's error
    V_scale = max(abs(ref.V(th)), k_s)
    assert abs(lin.K[0, 0] - K_ref) <= 1e-9 * K_ref + 100 * EPS * V_scale / hh ** 2
    assert np.max(np.abs(lin.P)) == 0.0 and np.max(np.abs(lin.N)) <= 1e3 * EPS * K_ref
    w = math.sqrt(K_ref / M_ref)
    assert np.allclose(lin.eigenvalues, [-1j * w, 1j * w], rtol=1e-8, atol=1e-8 * w)


@pytest.mark.parametrize("name", ["double_four_bar", "slider_crank", "four_bar"])
def test_exact_and_finite_difference_linearizations_agree(name: str) -> None:
    """Central differences err by about ε^(2/3) relative (δ = ε^(1/3)): the two agree to
    100·ε^(2/3) of the matrices' scale."""
    mf = load_model(EXAMPLES / f"{name}.toml")
    z = equilibrium(mf.system, mf.simulation.y0)
    fd, ex = linearize_loop(mf.system, z), linearize_loop_exact(mf.system, z)
    assert fd.names == ex.names
    tol = 100 * EPS ** (2 / 3)
    for key in ("M_tilde", "K", "D", "G", "N"):
        A, B = getattr(fd, key), getattr(ex, key)
        scale = 1.0 + float(np.max(np.abs(fd.K))) + float(np.max(np.abs(fd.M_tilde)))
        assert np.max(np.abs(A - B)) <= tol * scale, key
