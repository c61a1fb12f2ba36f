"""The memoized run templates (jourdain.simulation.template) and the fast paths of simulate():
a run served from the memo gives the numbers of a fresh one to the bit, whatever changed since
the last call (initial state, parameters, inputs, events, method, tolerances, step limits,
output times), results never share memory, and every check of bad input still raises. No
timing is asserted (the suite runs on loaded machines; benchmarks/setup.py measures)."""

import threading

import numpy as np
import pytest

from jourdain.errors import EvaluationError
from jourdain.models import n_link_pendulum_on_cart
from jourdain.simulation import options, template
from jourdain.simulation.simulate import Event

#: what a Results carries from its run (and nothing computed later from the system)
FIELDS = ("t", "y", "yd", "ydd", "u", "W", "parameters", "method", "rtol", "atol", "status",
          "message", "nfev", "nsteps", "n_accepted", "n_rejected", "events",
          "coordinate_names", "input_names", "units", "name")


@pytest.fixture(scope="module")
def cart():
    return n_link_pendulum_on_cart(2)


def _same(a, b) -> bool:
    """Equal to the bit: arrays by dtype, shape and bytes, containers entry by entry."""
    if isinstance(a, np.ndarray):
        return (isinstance(b, np.ndarray) and a.dtype == b.dtype and a.shape == b.shape
                and a.tobytes() == b.tobytes())
    if isinstance(a, dict):
        return isinstance(b, dict) and a.keys() == b.keys() and all(_same(a[k], b[k]) for k in a)
    if isinstance(a, (list, tuple)):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    return a == b


def assert_bit_identical(res, ref) -> None:
    for name in FIELDS:
        assert _same(getattr(res, name), getattr(ref, name)), name


def fresh(call):
    """``call()`` with every memo of simulate() emptied first: the numbers of a first run."""
    template.clear_templates()
    options._checked_plain.cache_clear()
    return call()


def calls(s):
    """Runs that differ from the one before in one thing each (y0, parameters, inputs,
    events, method, tolerances, step limits, output times), the first ones repeated."""
    f = s.f
    y0, yd0 = np.full(f, 0.1), np.zeros(f)
    y1 = np.linspace(-0.3, 0.4, f)
    mass = s.parameters[0][0]
    q = s.coordinate_names[1]
    return [
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), y1, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), list(y1), [0] * f, inputs={"F": 0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.7}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.7}, parameters={mass: 2.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.7}, parameters={mass: 3.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.7}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": ([0, 0.5], [0.0, 1.0])}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, events=[Event(q)]),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0},
                           events=[Event(f"{q} - 0.2", direction=1, terminal=True,
                                         name="up")]),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, method="RK45"),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, method="Radau"),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, rtol=1e-6),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, rtol=1e-6, atol=1e-7),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, atol=np.full(2 * f, 1e-9)),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, max_step=0.01),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, first_step=1e-4),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, t_eval=[0.5]),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0},
                           t_eval=np.linspace(0, 0.5, 11)),
        lambda: s.simulate((0.1, 0.3), y0, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, method="LSODA"),
        lambda: s.simulate((0, 1e-9), y0, yd0, inputs={"F": 0.0}),
        lambda: s.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}),
    ]


def test_each_run_gives_the_numbers_of_a_fresh_run(cart):
    """Runs in a row, each differing from the last in one thing, the memo filled by the
    earlier ones: every one equals the same run with the memo emptied, to the bit."""
    runs = calls(cart)
    kept = [call() for call in runs]
    for call, res in zip(runs, kept, strict=True):
        assert_bit_identical(res, fresh(call))
    assert kept[0].nfev == kept[1].nfev and not _same(kept[0].y, kept[2].y)
    assert not _same(kept[4].y, kept[5].y) and not _same(kept[5].y, kept[6].y)
    assert kept[6].parameters[cart.parameters[0][0]] == 3.0
    assert kept[7].parameters == kept[4].parameters  # back to the defaults
    assert list(kept[9].events) == [str(cart.y[1])] and kept[10].status == "event"
    assert kept[11].events == {} and kept[12].method == "RK45" and kept[14].rtol == 1e-6


def test_the_memo_serves_equal_runs_and_only_those(cart):
    """One template for runs with the same parameters, number inputs and options; another as
    soon as any of them changes; none kept for runs with events or other kinds of inputs."""
    f = cart.f
    _, _, atol_x = options.checked_options("DOP853", 1e-8, 1e-10, 2 * f)

    def get(parameters=None, inputs=None, events=(), method="DOP853", rtol=1e-8, atol=atol_x,
            max_step=np.inf, first_step=0.0):
        return template.run_template(cart, parameters, inputs if inputs is not None else
                                     {"F": 0.0}, events, method, rtol, atol, max_step,
                                     first_step)

    base = get()
    assert get() is base and get(inputs={"F": 0}) is get(inputs={"F": 0})
    mass = cart.parameters[0][0]
    others = [get(parameters={mass: 2.0}), get(inputs={"F": 1.0}), get(method="RK45"),
              get(rtol=1e-7), get(atol=np.full(2 * f + 1, 1e-9)), get(max_step=0.1),
              get(first_step=1e-3)]
    assert all(t is not base for t in others)
    assert len({id(t) for t in others}) == len(others)
    assert get(parameters={mass: 2.0}) is others[0]  # parameters keyed by their values
    assert get(events=[Event(cart.y[1])]) is not get(events=[Event(cart.y[1])])
    table = {"F": ([0.0, 1.0], [0.0, 1.0])}
    assert get(inputs=table) is not get(inputs=table)
    template.clear_templates()
    assert get() is not base


def test_results_of_one_template_share_no_memory(cart):
    """Two runs from one template: writing to one's arrays and dicts leaves the other's be."""
    f = cart.f
    y0, yd0 = np.full(f, 0.1), np.zeros(f)
    for t_eval in (None, [0.25, 0.5]):
        a = cart.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, t_eval=t_eval)
        b = cart.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0}, t_eval=t_eval)
        for name in ("t", "y", "yd", "ydd", "u", "W", "atol"):
            assert not np.shares_memory(getattr(a, name), getattr(b, name)), name
            assert getattr(a, name).flags.writeable and getattr(a, name).flags.c_contiguous
        ref = fresh(lambda te=t_eval: cart.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0},
                                                    t_eval=te))
        a.y[:] = 7.0
        a.atol[:] = 1.0
        a.parameters["g"] = -1.0
        a.units.clear()
        a.coordinate_names.append("x")
        assert_bit_identical(b, ref)
        assert_bit_identical(cart.simulate((0, 0.5), y0, yd0, inputs={"F": 0.0},
                                           t_eval=t_eval), ref)


def test_threads_share_a_template(cart):
    """Runs in threads from one template (the problem is read only by the C loop) give the
    numbers of the same runs one after the other."""
    f = cart.f
    starts = [np.full(f, 0.05 * (k + 1)) for k in range(8)]
    serial = [cart.simulate((0, 0.5), y, np.zeros(f), inputs={"F": 0.1}) for y in starts]
    got: list = [None] * len(starts)

    def work(k: int) -> None:
        for _ in range(5):
            got[k] = cart.simulate((0, 0.5), starts[k], np.zeros(f), inputs={"F": 0.1})

    threads = [threading.Thread(target=work, args=(k,)) for k in range(len(starts))]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    for res, ref in zip(got, serial, strict=True):
        assert_bit_identical(res, ref)


@pytest.mark.parametrize("kwargs, error, match", [
    ({"y0": [0.1, float("nan"), 0.0]}, EvaluationError, r"y0 contains NaN or inf in \['q1'\]"),
    ({"yd0": np.array([0.0, np.inf, 0.0])}, EvaluationError, "yd0 contains NaN or inf"),
    ({"y0": np.zeros(2)}, EvaluationError, "y0 must have 3 entries"),
    ({"y0": np.zeros((3, 1))}, None, None),  # any shape of f numbers, as before
    ({"y0": np.full(3, 1e308)}, None, None),  # the sum overflows: the long way, accepted
    ({"method": "Euler"}, EvaluationError, "unknown method 'Euler'"),
    ({"rtol": True}, EvaluationError, "rtol must be a number"),
    ({"rtol": float("nan")}, EvaluationError, "relative tolerance"),
    ({"atol": True}, EvaluationError, "atol must be a number"),
    ({"atol": -1.0}, EvaluationError, "absolute tolerance must be positive"),
    ({"max_step": 0.0}, EvaluationError, "max_step must be positive"),
    ({"first_step": float("nan")}, EvaluationError, "first_step must be a positive number"),
    ({"t_span": (0, float("nan"))}, EvaluationError, "t_span must be finite"),
    ({"t_span": (0, 1, 2)}, EvaluationError, r"t_span must be \(t0, t1\)"),
    ({"t_eval": [0.2, float("nan")]}, EvaluationError, r"t_eval\[1\] = nan"),
    ({"t_eval": [float("nan")]}, EvaluationError, r"t_eval\[0\] = nan"),
    ({"t_eval": [0.3, 0.2]}, EvaluationError, "t_eval must be sorted"),
    ({"t_eval": [0.0, 1e300, 0.5]}, EvaluationError, "t_eval must be sorted"),
    ({"t_eval": [0.0, float("inf"), 0.5]}, EvaluationError, r"t_eval\[1\] = inf"),
    ({"t_eval": [0.6]}, EvaluationError, "t_eval must lie within t_span"),
    ({"t_eval": []}, EvaluationError, "t_eval holds 0 times"),
    ({"parameters": {"nope": 1.0}}, EvaluationError, "unknown parameter"),
    ({"parameters": {"g": float("nan")}}, EvaluationError, 'parameter "g"'),
    ({"inputs": {"F": float("nan")}}, EvaluationError, 'input "F" = nan is not finite'),
    ({"inputs": {"F": True}}, EvaluationError, 'input "F": expected a number'),
    ({"inputs": {"F": 0.0, "G": 1.0}}, EvaluationError, "unknown input"),
    ({"inputs": {}}, EvaluationError, r"input\(s\) \['F'\] not given"),
    ({"inputs": None}, EvaluationError, r"input\(s\) \['F'\] not given"),
    ({"formulation": "penalty"}, EvaluationError, "options of closed systems"),
    ({"rtool": 1e-6}, TypeError, "unexpected keyword argument 'rtool'"),
])
def test_bad_input_raises_after_good_runs_were_memoized(cart, kwargs, error, match):
    """The checks stand with the memo full of good runs: each bad value raises the error it
    raised before (and raises again: a check that fails leaves no entry)."""
    s = n_link_pendulum_on_cart(2)
    args = {"t_span": (0, 0.5), "y0": np.full(3, 0.1), "yd0": np.zeros(3),
            "inputs": {"F": 0.0}}
    for good in ({}, {"rtol": 1e-6, "atol": 1.0, "t_eval": [0.5]}, {"max_step": 0.1},
                 {"inputs": {"F": 1}}):
        s.simulate(**{**args, **good})
    args.update(kwargs)
    t_span, y0, yd0 = args.pop("t_span"), args.pop("y0"), args.pop("yd0")
    for _ in range(2):
        if error is None:
            assert s.simulate(t_span, y0, yd0, **args).status == "finished"
        else:
            with pytest.raises(error, match=match):
                s.simulate(t_span, y0, yd0, **args)


def test_a_recompiled_model_gets_a_template_of_its_own(cart):
    """The compiled M, k, q is part of the key: after the memoized functions are cleared, a run
    uses the new one (never an address of the old), with the same numbers."""
    from jourdain import numeric

    f = cart.f
    args = ((0, 0.5), np.full(f, 0.1), np.zeros(f))
    before = cart.simulate(*args, inputs={"F": 0.0})
    _, _, atol_x = options.checked_options("DOP853", 1e-8, 1e-10, 2 * f)
    old = template.run_template(cart, None, {"F": 0.0}, (), "DOP853", 1e-8, atol_x, np.inf, 0.0)
    numeric.clear_cache()
    new = template.run_template(cart, None, {"F": 0.0}, (), "DOP853", 1e-8, atol_x, np.inf, 0.0)
    assert new is not old and new.setup.mkq is numeric.mkq_function(cart)
    assert_bit_identical(cart.simulate(*args, inputs={"F": 0.0}), before)
