"""The command line on closed systems (issue 32): ``eval``, ``reactions``, ``eom``,
``simulate``, ``linearize`` and ``check`` give the closed system's numbers, checked against
references formed here apart from :func:`jourdain.loops.evaluation.evaluate_closed`: the
velocity map ``L = [E; −Φ_d⁻¹Φ_i]`` from the symbolic constraint rows (and, for the four-bar,
from its closed-form velocity ratios), ``M = LᵀM_treeL`` from the open tree's numbers, and the
multipliers from the augmented system ``[M_tree Φ_yᵀ; Φ_y 0]`` solved with NumPy."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import symengine as se

import jourdain as jd
from jourdain.cli import main
from jourdain.numeric import evaluate as tree_evaluate
from tests.test_loops import FB, _four_bar_closed_form
from tests.tolerance import EPS, cond, norm, solve_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"
CLOSED = ["four_bar", "double_four_bar"]


def run(capsys: pytest.CaptureFixture, *args: object) -> tuple[int, str, str]:
    code = main([str(a) for a in args])
    out = capsys.readouterr()
    return code, out.out, out.err


def constraint_numbers(system: jd.System, y: np.ndarray, yd: np.ndarray
                       ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Φ, Φ_y and the convective term c = (dΦ_y/dt)·ẏ at (y, ẏ), from the symbolic rows of
    ``system.constraints()`` (scleronomic rows: no Φ_t terms)."""
    con = system.constraints()
    coords = list(system.tree.coordinates)
    subs = {se.Symbol(k): v for k, v in system.tree.parameters}
    subs.update({c: float(v) for c, v in zip(coords, y, strict=True)})
    rows = [[con.Phi_y.rows[i][j] for j in range(len(coords))] for i in range(con.r)]
    Phi = np.array([float(con.Phi.rows[i][0].subs(subs)) for i in range(con.r)])
    Phi_y = np.array([[float(e.subs(subs)) for e in r] for r in rows])
    c = np.array([sum(float(se.diff(e, ck).subs(subs)) * yd[k] * yd[j]
                      for j, e in enumerate(r) for k, ck in enumerate(coords)) for r in rows])
    return Phi, Phi_y, c


def velocity_map(Phi_y: np.ndarray, names: list[str], independent: list[str]) -> np.ndarray:
    """``L`` with ``ẏ = L·ẏ_i``: identity rows for the independent coordinates, ``−Φ_d⁻¹Φ_i``
    for the dependent ones (every row of Φ_y independent in these examples)."""
    ind = [names.index(c) for c in independent]
    dep = [i for i in range(len(names)) if i not in ind]
    L = np.zeros((len(names), len(ind)))
    L[ind, range(len(ind))] = 1.0
    L[dep] = -np.linalg.solve(Phi_y[:, dep], Phi_y[:, ind])
    return L


@pytest.mark.parametrize("name", CLOSED)
def test_eval_json_is_the_closed_system(name: str, capsys: pytest.CaptureFixture) -> None:
    path = EXAMPLES / f"{name}.toml"
    code, out, err = run(capsys, "eval", path, "--json")
    assert code == 0, err
    doc = json.loads(out)
    system = jd.load_model(path).system
    assert doc["format"] == "jourdain-eval/1"
    assert "null" not in out and "NaN" not in out and "Infinity" not in out
    assert doc["not_available"] == {}
    ind = doc["independent"]
    assert ind == list(system.independent)
    assert doc["constraint_labels"] == system.constraints().labels
    v = {k: np.asarray(x, dtype=float) for k, x in doc["values"].items() if x is not None}
    y, yd = np.array(doc["y"]), np.array(doc["yd"])
    Phi, Phi_y, c = constraint_numbers(system, y, yd)
    names = system.coordinate_names
    dep = [i for i, n in enumerate(names) if n not in ind]
    # the state lies on the manifold: the residuals, as reported and as recomputed here
    Pd = Phi_y[:, dep]
    tol_Phi = solve_tol(Pd, 1.0 + norm(Phi_y) * norm(y))
    tol_dot = solve_tol(Pd, norm(Phi_y) * (1.0 + norm(yd)))
    assert doc["closure_residual"]["Phi"] <= tol_Phi
    assert doc["closure_residual"]["Phi_dot"] <= tol_dot
    assert np.max(np.abs(Phi)) <= tol_Phi and np.max(np.abs(Phi_y @ yd)) <= tol_dot
    # M = LᵀM_treeL, q = Lᵀq_tree with L from the constraint rows (not from evaluate)
    L = velocity_map(Phi_y, names, ind)
    tree = tree_evaluate(system.tree, y, yd)
    M_tree, k_tree, q_tree = (np.asarray(tree[k], dtype=float) for k in ("M", "k", "q"))
    k_tree, q_tree = k_tree.reshape(-1), q_tree.reshape(-1)
    scale = norm(M_tree) * norm(L) ** 2
    tol = solve_tol(Pd, scale)
    assert v["M"].shape == (len(ind), len(ind))
    assert np.max(np.abs(v["M"] - L.T @ M_tree @ L)) <= tol
    assert np.max(np.abs(v["L"] - L)) <= solve_tol(Pd, norm(L))
    assert np.max(np.abs(v["q"] - L.T @ q_tree)) <= solve_tol(Pd, norm(L) * norm(q_tree))
    assert np.max(np.abs(v["Phi_y"] - Phi_y)) <= 10 * EPS * (1 + norm(Phi_y)) * Phi_y.size
    # the closing rows of g are the multipliers of M_tree·ÿ + k_tree − q_tree = Φ_yᵀλ, with
    # ÿ and λ from the augmented system [M_tree Φ_yᵀ; Φ_y 0]·[ÿ; −λ] = [q_tree − k_tree; −c]
    r = Phi_y.shape[0]
    K = np.block([[M_tree, Phi_y.T], [Phi_y, np.zeros((r, r))]])
    x = np.linalg.solve(K, np.concatenate([q_tree - k_tree, -c]))
    lam = -x[len(names):]
    g = dict(zip(doc["g_names"], doc["values"]["g"], strict=True))
    closing = np.array([g[label] for label in doc["constraint_labels"]])
    tol = solve_tol(K, norm(x) + norm(q_tree) + norm(k_tree) + norm(c))
    assert np.max(np.abs(closing - lam)) <= tol
    assert np.max(np.abs(v["lambda"] - lam)) <= tol
    assert np.max(np.abs(v["ydd"] - x[:len(names)])) <= tol
    # J̄ of the closed system is J̄_tree·L; Q̄ has the closing rows' columns, orthogonal to it
    assert v["J_bar"].shape == (6 * len(system.bodies), len(ind))
    assert v["Q_bar"].shape[1] == len(doc["g_names"])
    ortho = np.max(np.abs(v["J_bar"].T @ v["Q_bar"]))
    assert ortho <= solve_tol(Pd, norm(v["J_bar"]) * norm(v["Q_bar"]))
    # the linearization about the state is the closed system's, in the independent coordinates
    nominal = {**dict(zip(names, y, strict=True)),
               **{f"{n}_d": float(d) for n, d in zip(names, yd, strict=True)}}
    lin = system.linearize(nominal)
    assert v["M_tilde"].shape == (len(ind), len(ind))
    for key in ("M_tilde", "P", "Q", "K"):
        ref = np.asarray(getattr(lin, key))
        assert np.max(np.abs(v[key] - ref)) <= 1e-8 * (1 + norm(ref)), key
    assert doc["units"]["k"] == ["N m"] * len(ind) or len(doc["units"]["k"]) == len(ind)


def test_four_bar_M_equals_the_closed_form_velocity_ratios(capsys: pytest.CaptureFixture
                                                           ) -> None:
    """M of the four-bar = 2T at θ̇1 = 1 with the rates of the closed-form circle
    intersection: θ̇2 = ω2 − 1 (relative), θ̇3 = ω3."""
    path = EXAMPLES / "four_bar.toml"
    code, out, err = run(capsys, "eval", path, "--at", "theta1=0.7, theta1_d=0.3", "--json")
    assert code == 0, err
    doc = json.loads(out)
    th1 = 0.7
    phi2, th3, w2, w3 = _four_bar_closed_form(th1, 1.0, FB)
    y = np.array([th1, phi2 - th1, th3])
    assert np.max(np.abs(np.array(doc["y"]) - y)) <= 1e-12
    L = np.array([1.0, w2 - 1.0, w3])
    M_tree = np.asarray(tree_evaluate(jd.load_model(path).system.tree, y, 0.3 * L)["M"])
    M = float(L @ M_tree @ L)
    assert doc["values"]["M"][0][0] == pytest.approx(M, rel=1e3 * EPS * cond(M_tree))


@pytest.mark.parametrize("name", CLOSED)
def test_reactions_json_has_the_closing_rows(name: str, capsys: pytest.CaptureFixture) -> None:
    path = EXAMPLES / f"{name}.toml"
    code, out, err = run(capsys, "reactions", path, "--json")
    assert code == 0, err
    doc = json.loads(out)
    system = jd.load_model(path).system
    labels = system.constraints().labels
    assert labels[0] in doc["g_names"] and doc["g_names"][-len(labels):] == labels
    units = dict(zip(doc["g_names"], doc["units"]["g"], strict=True))
    assert [units[lab] for lab in labels] == ["N"] * len(labels)
    code, out, _ = run(capsys, "eval", path, "--json")
    ev = json.loads(out)
    assert doc["g"] == ev["values"]["g"] and doc["g_names"] == ev["g_names"]
    code, out, _ = run(capsys, "reactions", path)
    assert code == 0 and f"{labels[0]}" in out and " N" in out
    if name == "four_bar":
        assert "closure.Fx" in doc["g_names"]


def test_simulate_writes_the_closed_motion(tmp_path: Path, capsys: pytest.CaptureFixture
                                          ) -> None:
    path = EXAMPLES / "four_bar.toml"
    model = jd.load_model(path)
    out = tmp_path / "fb.csv"
    code, text, err = run(capsys, "simulate", path, "--t-end", "0.5", "--samples", "51",
                          "--out", out)
    assert code == 0, err
    assert f"wrote {out}" in text
    lines = [ln for ln in out.read_text().splitlines() if not ln.startswith("#")]
    head = lines[0].split(",")
    last = np.array([float(x) for x in lines[-1].split(",")])
    s = model.simulation
    ref = model.system.simulate((0.0, 0.5), list(s.y0), list(s.yd0), method=s.method,
                                rtol=s.rtol, atol=s.atol, t_eval=np.linspace(0.0, 0.5, 51))
    names = model.system.coordinate_names
    got = last[[head.index(n) for n in names]]
    assert np.max(np.abs(got - ref.y[-1])) <= 4 * EPS * (1 + np.max(np.abs(ref.y[-1])))
    assert last[head.index("t")] == 0.5
    # --progress as for trees (lines on stderr; the same motion)
    code, text, err = run(capsys, "simulate", path, "--t-end", "0.5", "--samples", "51",
                          "--progress")
    assert code == 0, err
    assert f"theta1={ref.y[-1][0]:.6g}" in text


@pytest.mark.parametrize("name", CLOSED)
def test_eom_shows_the_constraints_and_multipliers(name: str, capsys: pytest.CaptureFixture
                                                   ) -> None:
    path = EXAMPLES / f"{name}.toml"
    code, out, err = run(capsys, "eom", path, "--max-ops", "50")
    assert code == 0, err
    assert "Φ_y" in out and "λ" in out and "M_tree" in out and "jourdain eval" in out
    assert "M (mass matrix, f×f) =" not in out  # not the open tree's M presented as the M
    code, out, err = run(capsys, "eom", path, "--format", "json")
    assert code == 0, err
    doc = json.loads(out)
    system = jd.load_model(path).system
    assert doc["closing_joints"] == [c.name for c in system.closing]
    assert doc["independent"] == list(system.independent)
    assert doc["constraint_labels"] == system.constraints().labels
    assert doc["matrices"]["Phi_y"]["shape"] == [len(doc["constraint_labels"]), system.f]
    assert "M" not in doc["matrices"]
    code, out, err = run(capsys, "eom", path, "--format", "latex")
    assert code == 0 and r"\Phi" in out


def test_linearize_eigenvalues_equal_system_linearize(capsys: pytest.CaptureFixture) -> None:
    path = EXAMPLES / "four_bar.toml"
    code, out, err = run(capsys, "linearize", path, "--json")
    assert code == 0, err
    doc = json.loads(out)
    system = jd.load_model(path).system
    lin = system.linearize(dict(doc["z_s"]))  # about the same equilibrium
    got = np.sort_complex(np.array([complex(*e) for e in doc["eigenvalues"]]))
    ref = np.sort_complex(np.asarray(lin.eigenvalues))
    # symbolic derivatives (the command) against central differences (error ~ ε^(2/3))
    assert np.max(np.abs(got - ref)) <= 1e-6 * np.max(np.abs(ref))
    assert doc["stability"]["verdict"] and doc["independent"] == ["theta1"]
    assert set(doc["matrices"]) >= {"M_tilde", "P", "Q", "h", "D", "G", "K", "N"}
    code, out, err = run(capsys, "linearize", path)
    assert code == 0, err
    assert "M_tilde" in out and "stability:" in out and "eigenvalues" in out
    # --periodic: the Floquet analysis about the same equilibrium, whose multipliers are the
    # exponentials of the eigenvalues over the period (a time-invariant system)
    code, out, err = run(capsys, "linearize", path, "--periodic", "2", "--json")
    assert code == 0, err
    fl = json.loads(out)["floquet"]
    mu = np.sort_complex(np.array([complex(*m) for m in fl["multipliers"]]))
    assert np.max(np.abs(mu - np.sort_complex(np.exp(2.0 * got)))) <= 10 * fl["tolerance"]
    assert "Traceback" not in err


def test_check_keeps_the_loop_summary(capsys: pytest.CaptureFixture) -> None:
    code, out, err = run(capsys, "check", EXAMPLES / "double_four_bar.toml")
    assert code == 0, err
    assert "loop1" in out and "loop2" in out
