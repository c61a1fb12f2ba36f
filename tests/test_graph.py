"""The shared expression graph (jourdain.graph): one node store, its merged view, and the walks
over it (CSE, symbolic and floating-point forward mode) against SymPy as the reference."""

import math

import numpy as np
import pytest
import symengine as se
import sympy as sp

import jourdain.graph.identity as identity
from jourdain.errors import JourdainError
from jourdain.graph import Graph, cse, evaluate_float, evaluate_float_many, jet, jet_float
from jourdain.models import spatial_chain

EPS = np.finfo(float).eps


def _shared_expressions():
    """Expressions that share sub-expressions and contain each kind of node the walks handle."""
    x, y, z = se.symbols("x y z")
    s = se.sin(x + y)
    c = se.cos(x - 2 * z)
    shared = s * c + se.exp(z) / (1 + y**2)
    return [x, shared, shared**2 - se.atan2(y, x), se.tanh(shared) * se.log(2 + x * x),
            se.sqrt(1 + s * s) + se.Abs(c) * z**3], (x, y, z)


def test_store_reads_each_shared_node_once_and_merged_view_joins_equal_ones():
    """Two separately built equal products are two nodes of the store (by address) and one of the
    merged view; x + y and -x - y (equal SymEngine hashes) stay apart in both."""
    x, y = se.symbols("x y")
    a, b = se.sin(x) * y, se.sin(x) * y  # equal, built separately
    exprs = [a + b * x, a, x + y, -x - y]
    g = Graph(exprs)
    muls = [k for k in g.order if g.kind[k] == "Mul" and g.node[k] == a]
    assert len(muls) >= 1
    m = g.merged()
    assert sum(1 for i in m.order if m.node[i] == a) == 1
    r = m.root_ids
    assert r[2] != r[3]
    # a is a root and a factor of the first root's term b*x: two uses in the merged view
    assert m.uses[r[1]] == 2
    assert m.root_ids == Graph(exprs).merged().root_ids  # reproducible


def test_cse_output_gives_the_same_numbers_as_sympy(rng):
    exprs, syms = _shared_expressions()
    res = cse(exprs)
    assert res.temporaries  # the shared sub-expressions became temporaries
    point = dict(zip(syms, rng.uniform(0.2, 0.9, 3), strict=True))
    env = {sp.Symbol(str(k)): v for k, v in point.items()}
    for sym, e in res.temporaries:
        env[sp.Symbol(str(sym))] = float(sp.sympify(str(e)).subs(env))
    for orig, red in zip(exprs, res.outputs, strict=True):
        want = float(sp.sympify(str(orig)).subs({sp.Symbol(str(k)): v for k, v in point.items()}))
        got = float(sp.sympify(str(red)).subs(env))
        assert got == pytest.approx(want, rel=100 * EPS, abs=100 * EPS)


@pytest.mark.parametrize("pointers", [True, False], ids=["addresses", "hash-fallback"])
def test_jets_match_sympy_derivatives(pointers, monkeypatch, rng):
    """Values and Jacobians of the symbolic (jet) and floating-point (jet_float) forward mode
    against SymPy's derivatives, with node identity by address and by the hash fallback."""
    monkeypatch.setattr(identity, "POINTERS", pointers and identity.POINTERS)
    exprs, syms = _shared_expressions()
    vals = dict(zip(syms, rng.uniform(0.2, 0.9, 3), strict=True))
    names = {str(k): float(v) for k, v in vals.items()}
    sp_syms = [sp.Symbol(str(s), real=True) for s in syms]
    sp_exprs = [sp.sympify(str(e), locals={str(s): t for s, t in zip(syms, sp_syms, strict=True)})
                for e in exprs]
    sp_point = dict(zip(sp_syms, names.values(), strict=True))
    want_v = np.array([float(e.subs(sp_point)) for e in sp_exprs])
    want_j = np.array([[float(sp.diff(e, s).subs(sp_point)) for s in sp_syms] for e in sp_exprs])
    scale = np.abs(want_j).max() + np.abs(want_v).max()
    tol = 1e3 * EPS * scale  # a few hundred rounded operations per entry

    fj = jet_float(exprs, list(syms), names)
    np.testing.assert_allclose(fj.values, want_v, rtol=0, atol=tol)
    np.testing.assert_allclose(fj.jacobian, want_j, rtol=0, atol=tol)
    np.testing.assert_allclose(evaluate_float(exprs, names), want_v, rtol=0, atol=tol)

    j = jet(exprs, list(syms), {})  # no substitution: symbolic gradients, evaluated here
    subs = {se.Symbol(k): v for k, v in names.items()}
    got_j = np.array([[float(se.sympify(row.get(i, 0)).subs(subs)) for i in range(3)]
                      for row in j.gradients])
    np.testing.assert_allclose(got_j, want_j, rtol=0, atol=tol)


def test_jet_at_a_point_substitutes_while_differentiating():
    """At x = 0 the gradient of x*sin(x)*y with respect to y vanishes (two zero factors) and that
    of sin(x)*y is y·cos(0) = y w.r.t. x: the point's substitutions enter the derivatives."""
    x, y = se.symbols("x y")
    j = jet([x * se.sin(x) * y, se.sin(x) * y], [x, y], {x: se.Integer(0)})
    assert j.values == (0, 0)
    assert j.gradients[0] == {}
    assert j.gradients[1] == {0: y}


def test_one_graph_walked_at_many_points_matches_fresh_graphs(rng):
    """A prebuilt graph (as the equilibrium search uses it) gives the numbers of a fresh one."""
    eom = spatial_chain(2).equations_of_motion()
    exprs = eom.k.entries() + eom.q.entries()
    g = Graph(exprs)
    variables = list(eom.y)
    names = sorted(g.symbol_names())
    for _ in range(3):
        values = dict(zip(names, rng.uniform(-1, 1, len(names)), strict=True))
        a, b = jet_float(g, variables, values), jet_float(exprs, variables, values)
        assert np.array_equal(a.values, b.values) and np.array_equal(a.jacobian, b.jacobian)


def test_missing_value_and_non_real_results_name_the_cause():
    x, y = se.symbols("x y")
    with pytest.raises(JourdainError, match='no value for the symbol "y"'):
        evaluate_float([x + y], {"x": 1.0})
    with pytest.raises(JourdainError, match="no real value"):
        evaluate_float([se.log(x)], {"x": -1.0})
    assert evaluate_float([se.exp(x)], {"x": 1.0}) == [math.e]


def test_many_sets_in_one_walk_equal_one_set_at_a_time(rng):
    """evaluate_float_many: the numbers of evaluate_float at each set, to the rounding of its
    left-to-right sums (evaluate_float sums exactly: fsum); a value that is not real falls
    back to evaluate_float, which names it."""
    eom = spatial_chain(3).equations_of_motion()
    exprs = [*eom.M.entries(), *eom.k.entries(), se.Max(eom.y[0], eom.y[1]), se.Abs(eom.y[2])]
    names = sorted(Graph(exprs).symbol_names())
    sets = [dict(zip(names, rng.uniform(-1, 1, len(names)), strict=True)) for _ in range(5)]
    many = evaluate_float_many(exprs, sets)
    one = np.array([evaluate_float(exprs, v) for v in sets])
    assert many.shape == (5, len(exprs))
    assert np.abs(many - one).max() <= 1e3 * EPS * np.abs(one).max()
    x = se.Symbol("x")
    with pytest.raises(JourdainError, match="no real value"):
        evaluate_float_many([se.log(x)], [{"x": 1.0}, {"x": -1.0}])
