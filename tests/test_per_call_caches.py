"""What does not change between calls is computed once (issue 38, item 7): the cyclic
coordinates of a model, the linearization about a nominal motion, the graph of the same
expressions, the physical checks of the same parameter values. The caches are explicit
(:mod:`jourdain.graph.memo`), bounded and keyed by content; these tests count the work done
(never the time: benchmarks/per_call.py measures that) and check that a cached answer is the
answer: the same numbers, the same warnings, the same refusals.
"""

import warnings
from pathlib import Path

import numpy as np
import pytest

import jourdain as jd
from jourdain.analysis import cyclic
from jourdain.graph import evaluate_float
from jourdain.graph.memo import GRAPHS, Memo, clear_all, graph_of
from jourdain.numeric import state
from jourdain.numeric.linearization import with_numbers
from jourdain.stages.linearization import formation

ROOT = Path(__file__).resolve().parents[1]


def rotor() -> tuple[jd.System, dict]:
    model = jd.load_model(ROOT / "examples" / "rotor_internal_damping.toml")
    return model.system, dict(zip(model.system.coordinate_names, model.nominal_motion().y,
                                  strict=True))


def top() -> tuple[jd.System, dict]:
    model = jd.load_model(ROOT / "examples" / "precessing_top.toml")
    return model.system, dict(zip(model.system.coordinate_names, model.nominal_motion().y,
                                  strict=True))


@pytest.fixture(autouse=True)
def empty_caches():
    clear_all()
    yield
    clear_all()


def counting(monkeypatch, module, name: str) -> list[int]:
    calls: list[int] = []
    original = getattr(module, name)

    def counted(*args, **kwargs):
        calls.append(1)
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, counted)
    return calls


def test_stability_finds_the_cyclic_coordinates_once_per_model(monkeypatch):
    found = counting(monkeypatch, cyclic, "_find")
    s, nominal = top()
    lin = s.linearize(nominal)
    verdicts = [jd.stability(lin, parameters={"Op": 10.0 + 0.1 * i}) for i in range(5)]
    assert len(found) == 1
    assert all(v.cyclic == ("psi", "phi") for v in verdicts)
    # an equal model built anew is the same key: nothing found again
    s2, nominal2 = top()
    assert s2 is not s
    jd.stability(s2.linearize(nominal2))
    assert len(found) == 1
    # the answer is the uncached one
    assert cyclic._find(s) == verdicts[0].cyclic


def test_linearize_forms_once_and_warns_every_time(monkeypatch):
    formed = counting(monkeypatch, formation, "form")
    s, nominal = rotor()
    first = s.linearize(nominal)
    assert s.linearize(nominal) is first and s.linearize(dict(nominal)) is first
    assert len(formed) == 1
    # the answer is the uncached one (the stage's own function caches nothing)
    uncached = with_numbers(formation.linearization(s.equations_of_motion(), nominal))
    assert len(formed) == 2
    for name in ("M_tilde", "D", "G", "K", "N"):
        np.testing.assert_array_equal(first.evaluate()[name], uncached.evaluate()[name])
    # a nominal that is not an equilibrium: formed once, the warning at every call
    for _ in range(2):
        with pytest.warns(jd.NominalMotionWarning, match="is not a solution"):
            other = s.linearize({**nominal, "x": 0.01})
    assert other is not first and len(formed) == 3


def test_evaluate_builds_the_graph_of_the_same_expressions_once():
    s, nominal = rotor()
    lin = s.linearize(nominal)
    lin.evaluate()
    misses = GRAPHS.misses
    for i in range(5):
        lin.evaluate(parameters={"Omega": 50.0 + i})
    assert GRAPHS.misses == misses
    exprs = list(lin.K.entries())
    assert graph_of(exprs) is graph_of(list(exprs))
    # other objects, even equal ones, are another key (no expression is compared with ==)
    x = jd.symbols("x")
    assert graph_of([x + 1]) is not graph_of([x + 1])
    assert evaluate_float([x + 1], {"x": 2.0}) == [3.0]


def test_parameter_checks_are_cached_but_never_skip_a_refusal(monkeypatch):
    s, nominal = rotor()
    lin = s.linearize(nominal)
    jd.stability(lin)  # the model's first call: its cyclic coordinates found (checks of its own)
    checked = counting(monkeypatch, state, "_problem")
    jd.stability(lin, parameters={"m": 2.0})  # five parameter vectors, one check
    assert len(checked) == 1
    jd.stability(lin, parameters={"Omega": 33.0})  # the bodies' data do not use Omega
    assert len(checked) == 1
    for _ in range(2):  # refused every time, from the cache the second time
        with pytest.raises(jd.EvaluationError, match=r"with the parameters m=-1.0: .*mass"):
            jd.stability(lin, parameters={"m": -1.0})
    assert len(checked) == 2


def test_cached_and_uncached_stability_agree():
    s, nominal = rotor()
    lin = s.linearize(nominal)
    for omega in (10.0, 60.0, 120.0):
        cached = [jd.stability(lin, parameters={"Omega": omega}) for _ in range(2)]
        clear_all()
        fresh = jd.stability(s.linearize(nominal), parameters={"Omega": omega})
        assert cached[0].verdict == cached[1].verdict == fresh.verdict
        assert cached[0].max_real_part == fresh.max_real_part


def test_memo_is_bounded_and_least_recently_used_goes_first():
    memo: Memo[int] = Memo("test", 2)
    made: list[str] = []

    def make(k: str):
        return lambda: made.append(k) or len(made)

    assert memo.get("a", make("a")) == 1 and memo.get("b", make("b")) == 2
    assert memo.get("a", make("a")) == 1  # a used last: b goes first
    memo.get("c", make("c"))
    assert len(memo) == 2 and memo.get("a", make("a")) == 1
    assert memo.get("b", make("b")) == 4 and made == ["a", "b", "c", "b"]
    memo.clear()
    assert len(memo) == 0 and memo.hits == memo.misses == 0


def test_per_call_benchmark_runs(capsys):
    from benchmarks import per_call

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", jd.NominalMotionWarning)
        rows = per_call.main(["--repeat", "3"])
    assert [r["model"] for r in rows] == ["rotor (f = 2)", "precessing top (f = 3)"]
    assert all(ms > 0 for r in rows for ms in r["ms"].values())
    assert "| rotor (f = 2) |" in capsys.readouterr().out


def test_an_unhashable_key_is_computed_every_time():
    memo: Memo[int] = Memo("test", 4)
    made: list[int] = []
    assert memo.get(([1],), lambda: made.append(1) or 7) == 7
    assert memo.get(([1],), lambda: made.append(1) or 7) == 7
    assert made == [1, 1] and len(memo) == 0
