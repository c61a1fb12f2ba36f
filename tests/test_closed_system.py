"""One System for trees and closed mechanisms (issue 32): the constraint stage's invariants
(``J̄_treeᵀ·Q̄_c = Φ_yᵀ``, ``Φ_y·L = 0``, ``L̄ᵀ·Q̄ = 0``), the closed system's reactions against
the multipliers solved independently from the tree's equations, the Newton–Euler residual
with every joint's reactions, zero rows for a tree, and that nothing uses the open tree
silently: tree-only functions refuse a closed system, and the closed motion is not the
open tree's."""

from __future__ import annotations

import pickle
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.errors import ClosedSystemError
from jourdain.models import double_pendulum, four_bar, slider_crank
from jourdain.numeric import evaluate as tree_only_evaluate
from jourdain.numeric import lambdify, mkq_function
from tests.tolerance import EPS, eval_tol, norm, solve_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CLOSED = ["four_bar.toml", "slider_crank.toml", "double_four_bar.toml", "spatial_rssr.toml"]


def _closed(name: str) -> tuple[jd.System, np.ndarray, np.ndarray]:
    mf = jd.load_model(EXAMPLES / name)
    sim = mf.simulation
    y0 = np.asarray(sim.y0, float) if sim.y0 else np.zeros(mf.system.f)
    yd0 = np.asarray(sim.yd0, float) if sim.yd0 else np.zeros(mf.system.f)
    return mf.system, y0, yd0


@pytest.mark.parametrize("name", CLOSED)
def test_closing_columns_are_the_constraint_gradients(name: str) -> None:
    """By the virtual work of the constraint forces the closing rows' wrench columns map to
    the gradients of Φ: ``J̄_treeᵀ·Q̄_c = Φ_yᵀ`` at any configuration (not only on the
    manifold), compiled from the two symbolic stages independently."""
    system, y0, _ = _closed(name)
    con = system.constraints()
    ne = system.tree.newton_euler()
    keep = [i for i, r in enumerate(con.rows) if r.kind != "generic"]
    fn = lambdify(system.tree, {"J": ne.J_bar, "Qc": con.Q_bar, "Py": con.Phi_y})
    rng = np.random.default_rng(3)
    p = np.array(list(system.parameter_values.values()))
    for _ in range(3):
        y = y0 + rng.uniform(-0.3, 0.3, system.f)
        out = fn(y, np.zeros(system.f), 0.0, p, np.zeros(len(system.inputs)))
        lhs = out["J"].T @ out["Qc"][:, keep]
        rhs = out["Py"][keep].T
        scale = float(np.max(np.abs(out["J"]).T @ np.abs(out["Qc"][:, keep])))
        assert np.max(np.abs(lhs - rhs)) <= eval_tol(6 * len(system.bodies), scale)


@pytest.mark.parametrize("kind,axis", [("revolute", "z"), ("universal", "z"),
                                       ("prismatic", "x"), ("point_on_line", "x"),
                                       ("point_on_plane", "y"), ("spherical", None)])
def test_closing_columns_of_every_kind_with_both_bodies_moving(kind: str, axis: str | None
                                                               ) -> None:
    """The same virtual-work identity ``J̄_treeᵀ·Q̄_c = Φ_yᵀ`` for every kind of closing joint
    between two moving bodies, off-centre points (a row (p_B − p_A)·w with w fixed in A acts
    on A at the point coinciding with p_B: the column must say so)."""
    fb = four_bar()
    b, c = jd.symbols("b c")
    cj = jd.ClosingJoint("cj", kind, "coupler", "rocker", point_a=(0.3 * b, 0.1, 0.02),
                         point_b=(c, 0.05, -0.01), **({"axis": axis} if axis else {}))
    system = fb.tree.closed_by([cj])
    con = system.constraints()
    ne = system.tree.newton_euler()
    fn = lambdify(system.tree, {"J": ne.J_bar, "Qc": con.Q_bar, "Py": con.Phi_y})
    p = np.array(list(system.parameter_values.values()))
    for y in ([0.4, 0.7, 1.3], [-1.1, 2.0, 0.2]):
        out = fn(np.array(y), np.zeros(3), 0.0, p, np.zeros(0))
        scale = float(np.max(np.abs(out["J"]).T @ np.abs(out["Qc"])))
        assert np.max(np.abs(out["J"].T @ out["Qc"] - out["Py"].T)) <= eval_tol(
            6 * len(system.bodies), scale), con.labels


@pytest.mark.parametrize("name", CLOSED)
def test_closed_evaluate_invariants_and_reactions(name: str) -> None:
    """At the assembled state: Φ_y·L = 0, L̄ᵀ·Q̄ = 0 (J̄ of the closed system against every
    joint's constrained directions), the closing rows' g equal to the multipliers of the
    tree's equations ``M_tree·ÿ + k_tree − q_tree = Φ_yᵀλ`` solved here by least squares, and
    the Newton–Euler equations ``M̄·J̄_tree·ÿ + q̄^c = q̄^e + Q̄·g`` met by g."""
    system, y0, yd0 = _closed(name)
    ind = [system.coordinate_names.index(c) for c in system.independent or ()]
    yd = yd0.copy()
    yd[ind] += 0.3  # the independent rates (the others follow: given, they would be warned of)
    out = system.evaluate(y0, yd)
    L, Py = out["L"], out["Phi_y"]
    assert out["M"].shape == (L.shape[1], L.shape[1])
    assert np.max(np.abs(Py @ L)) <= solve_tol(Py, norm(Py) * norm(L)) * 10
    JtQ = out["J_bar"].T @ out["Q_bar"]
    assert np.max(np.abs(JtQ)) <= eval_tol(out["Q_bar"].shape[0],
                                           norm(out["J_bar"]) * norm(out["Q_bar"])) * 1e3
    # λ from the tree's own equations, independently of the reactions stage
    tree = tree_only_evaluate(system.tree, out["y"], out["yd"])
    r = tree["M"] @ out["ydd"] + tree["k"] - tree["q"]
    lam, *_ = np.linalg.lstsq(Py.T, r, rcond=None)
    labels = out["constraint_labels"]
    names = out["g_names"]
    g = out["g"]
    scale = norm(tree["M"]) * norm(out["ydd"]) + norm(tree["k"]) + norm(tree["q"])
    tol = solve_tol(Py.T @ Py, scale / max(norm(Py), 1e-300)) * 1e3
    assert not out["g_undetermined"] or name == "spatial_rssr.toml"
    for i, lab in enumerate(labels):
        if lab in names and np.isfinite(g[names.index(lab)]):
            assert abs(g[names.index(lab)] - lam[i]) <= tol * (1 + abs(lam[i])), lab
    # the Newton–Euler equations with every joint's reactions
    gg = np.nan_to_num(g)
    res = out["M_bar"] @ tree["J_bar"] @ out["ydd"] + out["q_c"] - out["q_e"] - out["Q_bar"] @ gg
    terms = (np.abs(out["M_bar"]) @ np.abs(tree["J_bar"]) @ np.abs(out["ydd"])
             + np.abs(out["q_c"]) + np.abs(out["q_e"]) + np.abs(out["Q_bar"]) @ np.abs(gg))
    if not out["g_undetermined"]:
        bound = solve_tol(out["N_hat"], float(np.max(terms))) * 10
        assert np.max(np.abs(res)) <= bound
    assert out["closure_residual"]["Phi"] <= 1e3 * EPS * (1 + float(np.max(np.abs(out["y"]))))


def test_a_tree_has_zero_rows_and_unchanged_numbers() -> None:
    system = double_pendulum()
    con = system.constraints()
    assert con.r == 0 and con.labels == [] and system.tree is system and not system.closing
    out = system.evaluate([0.3, -0.2], [0.1, 0.4])
    ref = tree_only_evaluate(system, [0.3, -0.2], [0.1, 0.4])
    for k in ("M", "k", "q", "J_bar"):
        assert np.array_equal(out[k], ref[k])
    res = system.simulate((0, 0.5), [0.3, -0.2], [0.1, 0.4])
    assert res.Phi.shape == (len(res.t), 0) and res.constraint_labels == []


def test_tree_only_functions_refuse_a_closed_system() -> None:
    """Nothing uses the open tree silently: the tree's functions raise, naming the closing
    joints; the open tree is there by name."""
    system = four_bar()
    for call in (lambda: jd.kinematics(system), lambda: tree_only_evaluate(system, [0.5, 0, 0],
                                                                             [0, 0, 0]),
                 lambda: mkq_function(system), system.equations_of_motion,
                 system.newton_euler, system.reactions):
        with pytest.raises(ClosedSystemError, match="closure"):
            call()
    assert system.tree.equations_of_motion().M.shape == (3, 3)


@pytest.mark.parametrize("name", ["four_bar.toml", "double_four_bar.toml"])
def test_the_closed_motion_is_not_the_open_trees(name: str) -> None:
    system, y0, yd0 = _closed(name)
    closed = system.simulate((0.0, 0.5), y0, yd0, t_eval=[0.0, 0.5])
    opened = system.tree.simulate((0.0, 0.5), closed.y[0], closed.yd[0], t_eval=[0.0, 0.5])
    assert closed.status == "finished" and closed.constraints is not None
    assert np.max(np.abs(closed.y[-1] - opened.y[-1])) > 1e-3
    phi, phid = closed.closure_residual
    assert phi <= 1e-9 and phid <= 1e-8
    # the one Results type with every joint's reactions along the motion, closing rows included
    assert isinstance(closed, jd.Results)
    assert set(closed.constraint_labels) & set(closed.g_names)


def test_closed_system_is_data_equal_hashable_and_pickles() -> None:
    a, b = four_bar(), four_bar()
    assert a == b and hash(a) == hash(b) and a != a.tree
    c = pickle.loads(pickle.dumps(a))
    assert c == a and c.closing == a.closing and c.independent == ("theta1",)
    assert slider_crank().closing[0].name == "wrist"
    with pytest.raises(jd.ModelError, match="unknown body"):
        a.tree.closed_by([jd.ClosingJoint("x", "spherical", "coupler", "nope")])


def test_closed_run_shows_progress_and_keeps_its_motion_on_ctrl_c(tmp_path: Path) -> None:
    """Ctrl-C during a closed system's run (SIGINT sent from the progress callback, as a user
    would press it) stops it between two calls of the step loop: the results say
    "interrupted", hold the motion up to there on the manifold, and the output file has it."""
    import os
    import signal

    system = four_bar()
    seen: list[float] = []

    def progress(t: float, t1: float) -> None:
        seen.append(t)
        if len(seen) == 2:
            os.kill(os.getpid(), signal.SIGINT)

    out = tmp_path / "run.csv"
    res = system.simulate((0.0, 5000.0), [0.5, 0, 0], [1.0, 0, 0], progress=progress,
                          output=str(out), t_eval=np.linspace(0.0, 5000.0, 100001))
    assert res.status == "interrupted" and "Ctrl-C" in res.message
    assert 0 < res.t[-1] < 5000.0 and len(seen) >= 2 and all(np.diff(seen) > 0)
    assert res.closure_residual[0] <= 1e-9
    kept = jd.Results.load(out)
    assert len(kept.t) == len(res.t)
    assert np.allclose(kept.y[-1], res.y[-1], rtol=1e-15, atol=0)
    with pytest.raises(ClosedSystemError, match="events"):
        system.simulate((0.0, 1.0), [0.5, 0, 0], [1.0, 0, 0],
                        events=[jd.Event("theta1 - 1")])
