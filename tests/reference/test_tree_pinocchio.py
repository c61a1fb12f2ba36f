"""Random branching trees (jourdain.models.random_tree) against Pinocchio built from the same
data (benchmarks/pinocchio_models.tree_model).

Per state: M against CRBA, k − q against the nonlinear effects, ÿ = M⁻¹(q − k) against ABA,
RNEA at that ÿ (zero: no actuators), and every joint's reaction wrench ``Σ g_k·w_k`` against
RNEA's ``data.f`` (see test_reactions_pinocchio.py); M symmetric positive definite. Tolerances
come from tests/tolerance.py (tests/reference/tree_crosscheck.py, :func:`judge`).

* Each joint kind alone (revolute, prismatic, universal about random axes; spherical joints
  in all twelve rotation sequences; free joints), in this process: the conventions of the Pinocchio
  twin (tree_model's docstring) hold joint by joint.
* Mixed trees of :data:`SIZES`, each in three fresh processes with different
  ``PYTHONHASHSEED`` and private, empty ``JOURDAIN_CACHE`` directories: besides the checks, the
  generated C sources and M and g at every state must be identical bit for bit (jourdain once
  returned a wrong, indefinite M at f = 48 that depended on the process's memory history).

Cost of one fresh process (derivation, code generation and C compilation, 5 states), measured
on 2 cores with the recursive code generation of issue 13 (commits 3b80ffa, 2516a8e, ebe142d):
small (f = 14) 0.9 s, medium (f = 30) 1.2 s, large (f = 66) 3.8 s; the three processes of a
size run side by side in 3, 4 and 14 s. (Before 2516a8e, with the symbolic N̂ of the reactions,
the large case took 26 s per process and 100 s for three.)
"""

from __future__ import annotations

from concurrent.futures import ThreadPoolExecutor

import numpy as np
import pytest

from benchmarks.crosscheck import build, compare, spawn
from jourdain.models import CARDAN, TREE_JOINTS, random_tree, random_tree_data
from jourdain.numeric import evaluate
from tests.reference.pinocchio_models import pin
from tests.reference.tree_crosscheck import judge
from tests.tolerance import EPS, eval_tol, norm

#: mixed trees checked in fresh processes: name -> (n_bodies, seed, f); every joint kind
#: appears, and the data's breadth-first order is not depth-first
SIZES = {"small": (6, 2, 14), "medium": (14, 2, 30), "large": (35, 0, 66)}
HASHSEEDS = ("0", "1", "12345")
ALL_SEQUENCES = (*CARDAN, "zxz", "xyx", "xzx", "yxy", "yzy", "zyz")

#: one kind of joint per tree (plus the default mix in creation order), in this process
KINDS = {
    "revolute": dict(n_bodies=4, joints=("revolute",)),
    "prismatic": dict(n_bodies=4, joints=("prismatic",)),
    "universal": dict(n_bodies=4, joints=("universal",)),
    "spherical": dict(n_bodies=len(ALL_SEQUENCES), joints=("spherical",)),  # one each
    "free": dict(n_bodies=3, joints=("free",), free_at=(0, 1, 2), sequences=ALL_SEQUENCES),
    "mixed-creation-order": dict(n_bodies=5, order="creation"),
}


def _tree(spec: dict, seed: int) -> tuple:
    """``(system, Pinocchio model, TreeIndex)``; a spherical-only tree has every sequence."""
    from benchmarks.pinocchio_models import tree_model
    from jourdain.models import tree_from_data

    opts = dict(spec)
    data = random_tree_data(opts.pop("n_bodies"), seed, **opts)
    if opts.get("joints") == ("spherical",):
        data = [{**d, "sequence": ALL_SEQUENCES[i % len(ALL_SEQUENCES)]}
                for i, d in enumerate(data)]
    return (tree_from_data(data), *tree_model(data))


def _check(c: dict, what: str) -> None:
    for name, (err, tol) in judge(c).items():
        assert err <= tol, f"{what}: {name} error {err:.3e} > tolerance {tol:.3e}"


def test_tree_data():
    for name, (n, seed, f) in SIZES.items():
        data = random_tree_data(n, seed)
        assert sum(TREE_JOINTS[d["joint"]] for d in data) == f, name
        assert {d["joint"] for d in data} == set(TREE_JOINTS), name
        assert data[0]["parent"] == -1 and data[0]["joint"] == "free"
        assert all(0 <= d["parent"] < i for i, d in enumerate(data) if i), name
        assert any(sum(d["parent"] == i for d in data) > 1 for i in range(n)), "branching"
        for d in data:
            for u in d["axes"]:
                assert abs(np.linalg.norm(u) - 1.0) <= 4 * EPS
            lam = np.linalg.eigvalsh(d["inertia"])
            assert lam[0] > 0 and lam[2] < lam[0] + lam[1]  # triangle inequality
        _, index = build("tree", n, seed)[1:]
        assert not np.array_equal(index.v, np.arange(f)), f"{name}: data order is depth-first"
    # the same seed, the same model; the numbers are the parameters' defaults
    a, b = random_tree(5, 3), random_tree(5, 3)
    assert a == b and a.parameter_values == b.parameter_values
    data = random_tree_data(5, 3)
    assert a.parameter_values["I4xy"] == data[4]["inertia"][0, 1]
    assert a.parameter_values["px2"] == data[2]["position"][0]
    with pytest.raises(ValueError, match="unknown joint kind"):
        random_tree_data(3, 0, joints=("revolute", "ball"))


def test_pinocchio_crba_needs_depth_first_order(rng):
    """Why tree_model adds joints depth-first: in list (breadth-first) order, Pinocchio's ABA
    and RNEA still agree, its CRBA does not."""
    from benchmarks.pinocchio_models import tree_model

    data = random_tree_data(*SIZES["small"][:2])
    (m1, i1), (m2, i2) = tree_model(data), tree_model(data, depth_first=False)
    y, yd = rng.uniform(-np.pi, np.pi, m1.nq), rng.uniform(-3, 3, m1.nq)
    res = []
    for m, i in ((m1, i1), (m2, i2)):
        d = m.createData()
        q, v = i.to_pinocchio(y), i.to_pinocchio(yd)
        M = pin.crba(m, d, q)
        res.append((i.from_pinocchio(np.triu(M) + np.triu(M, 1).T),
                    i.from_pinocchio(pin.aba(m, d, q, v, np.zeros(m.nv)))))
    (M1, a1), (M2, a2) = res
    assert np.abs(a1 - a2).max() <= 1e3 * EPS * np.abs(a1).max()
    assert np.abs(M1 - M2).max() > 1e-3 * np.abs(M1).max()


@pytest.mark.parametrize("kind", list(KINDS))
def test_joint_conventions_match_pinocchio(kind, rng):
    system, model, index = _tree(KINDS[kind], seed=5)
    assert {b.joint.kind for b in system.bodies} >= ({kind} if kind in TREE_JOINTS else set())
    for _ in range(3):
        y, yd = rng.uniform(-np.pi, np.pi, system.f), rng.uniform(-3, 3, system.f)
        _check(compare(system, model, index, y, yd), kind)


@pytest.mark.own_hash_seeds
@pytest.mark.parametrize("size", list(SIZES))
def test_fresh_processes_agree_with_pinocchio_and_each_other(size, tmp_path):
    n, seed, f = SIZES[size]
    spec = {"kind": "tree", "n": n, "seed": seed, "states": 4}
    with ThreadPoolExecutor(len(HASHSEEDS)) as pool:
        runs = list(pool.map(
            lambda h: spawn(spec, h, cache=tmp_path / f"cache-{h}", timeout=1800,
                            module="tests.reference.tree_crosscheck"), HASHSEEDS))
    for r in runs:
        assert r["f"] == f and not r["perm_identity"]
        for key, value in r.items():
            if key.endswith("_ratio"):
                name = key[:-len("_ratio")]
                assert value <= 1.0, (f"PYTHONHASHSEED={r['hashseed']}: {name} error "
                                      f"{r[name]:.3e} is {value:.2f} × its tolerance")
        assert r["eig_min"] > 0
    for key in ("source_sha256", "M_sha256", "g_sha256"):
        assert len({r[key] for r in runs}) == 1, f"{key} differs between processes: " + ", ".join(
            f"PYTHONHASHSEED={r['hashseed']}: {r[key][:12]}" for r in runs)


@pytest.mark.parametrize("seed", range(4))
def test_mass_matrix_symmetric_positive_definite(seed, rng):
    """M = J̄ᵀM̄J̄ is symmetric and positive definite at random states, for default mixed trees
    of several seeds and for the single-kind trees above."""
    specs = [dict(n_bodies=5)] + ([] if seed else list(KINDS.values()))
    for spec in specs:
        system = _tree(spec, seed)[0]
        for _ in range(20):
            y = rng.uniform(-np.pi, np.pi, system.f)
            out = evaluate(system, y, rng.uniform(-3, 3, system.f))
            M, Jb = out["M"], np.abs(out["J_bar"])
            tol = eval_tol(Jb.shape[0], float((Jb.T @ np.abs(out["M_bar"]) @ Jb).max()))
            assert np.abs(M - M.T).max() <= tol
            lam = np.linalg.eigvalsh(0.5 * (M + M.T))
            assert lam[0] > 10 * system.f * EPS * norm(M), (spec, seed, lam[0])
            np.linalg.cholesky(M)
