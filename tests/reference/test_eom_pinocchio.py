"""spatial_chain(n) against Pinocchio built from the same data: M equals CRBA and k - q (no
inputs) equals Pinocchio's nonlinear effects (Coriolis, centrifugal, gyroscopic and gravity).

Both are evaluated directly (no solve) by two different algorithms: they agree to the rounding
of sums of 6p products, relative to the magnitude of the summed terms (tests/tolerance.py)."""

import numpy as np
import pytest

from jourdain.models import spatial_chain, spatial_chain_data
from tests.reference.pinocchio_models import pin, spatial_chain_model
from tests.tolerance import assert_close_eval


@pytest.mark.parametrize("n, seed", [(6, 0), (7, 3)], ids=["chain-6", "arm-7"])
def test_spatial_chain_matches_crba_and_nonlinear_effects(n, seed, rng):
    system = spatial_chain(n, seed=seed)
    model = spatial_chain_model(spatial_chain_data(n, seed=seed))
    data = model.createData()
    assert model.nq == system.f
    for _ in range(5):
        q = rng.uniform(-np.pi, np.pi, system.f)
        v = rng.uniform(-3, 3, system.f)
        M_pin = pin.crba(model, data, q)
        M_pin = np.triu(M_pin) + np.triu(M_pin, 1).T  # crba fills the upper triangle
        nle = pin.nonLinearEffects(model, data, q, v)
        out = system.evaluate(q, v)
        J, Mb = np.abs(out["J_bar"]), np.abs(out["M_bar"])
        n6 = J.shape[0]
        assert_close_eval(out["M"], M_pin, n6, (J.T @ Mb @ J).max(), err_msg="M")
        terms = J.T @ (np.abs(out["q_c"]) + np.abs(out["q_e"]))
        assert_close_eval(out["k"] - out["q"], nle, n6, terms.max(), err_msg="k - q")
