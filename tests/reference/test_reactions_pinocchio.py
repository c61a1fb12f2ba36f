"""Joint reaction forces of spatial_chain(n) against Pinocchio's RNEA.

After ``pin.rnea(model, data, q, v, a)`` with ``a`` = ÿ from jourdain's equations of motion,
``data.f[i]`` is the spatial force that the parent transmits to the sub-tree of Pinocchio joint
i, expressed in that joint's frame at its origin. For a jourdain joint made of several elementary
Pinocchio joints (universal: 2, spherical: 3) the last one's frame is the jourdain child body
frame, and the intermediate bodies are massless, so that force is the jourdain joint's wrench:
it must equal ``Σ_k g_k·w_k`` over the joint's constrained directions ``w_k``. The free
directions carry the joint torques, which vanish here (no actuators: τ = M·ÿ + nle = 0).

Tolerances (tests/tolerance.py): τ is the residual of jourdain's solve for ÿ evaluated by
Pinocchio (backward-error bound); the wrenches differ by the sub-tree's Newton–Euler residual,
whose bound grows with √cond(M) and √cond(N̂) at the state (cond(M) reaches 1e7..1e9 at some
random states of these chains).
"""

import numpy as np
import pytest

from jourdain.models import spatial_chain, spatial_chain_data
from jourdain.stages.reactions import graph_values
from tests.reference.pinocchio_models import pin, spatial_chain_model
from tests.tolerance import eom_terms, norm, residual_bound, subtree_tol, tree_extent


@pytest.mark.parametrize("n, seed", [(6, 0), (7, 3)], ids=["chain-6", "arm-7"])
def test_joint_forces_match_rnea(n, seed, rng):
    system = spatial_chain(n, seed=seed)
    model = spatial_chain_model(spatial_chain_data(n, seed=seed))
    data = model.createData()
    r = system.reactions()
    nq = {"revolute": 1, "universal": 2, "spherical": 3}
    last_ids = np.cumsum([nq[b.joint.kind] for b in system.bodies])  # Pinocchio joint ids
    params = {**{s: v for s, v in zip(system.parameter_symbols,
                                      system.parameter_values.values(), strict=True)}}
    for _ in range(4):
        q = rng.uniform(-np.pi, np.pi, system.f)
        v = rng.uniform(-3, 3, system.f)
        out = system.evaluate(q, v)
        a = np.linalg.solve(out["M"], out["q"] - out["k"])
        tau = pin.rnea(model, data, q, v, a)
        b_scale = sum(norm(t) for t in eom_terms(out))
        assert np.abs(tau).max() <= residual_bound(out["M"], a, None, b_scale)
        vals = {**params, **dict(zip(system.y, q, strict=True))}
        tol = subtree_tol(out, a, tree_extent(system, q))
        for jr, pid in zip(r.joints, last_ids, strict=True):
            W = np.array(graph_values([x for w in jr.wrenches for x in w], vals), dtype=float)
            W = W.reshape(len(jr.names), 6)
            g = out["g"][list(jr.columns)]
            f = data.f[int(pid)]
            ours = g @ W
            theirs = np.concatenate([f.linear, f.angular])
            assert np.abs(ours - theirs).max() <= tol, jr.joint.name
            # and component by component, in the constrained directions
            assert np.abs(W @ theirs - g).max() <= tol, jr.joint.name
