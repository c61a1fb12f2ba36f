"""jd.symbols follows SymPy's rules for sympy.symbols (the peer reference)."""

import pytest
import symengine as se
import sympy as sp

import jourdain as jd
from jourdain.errors import ModelError

CASES = ["x", " x ", "x,", "x y", "x, y", "x,y,", "phi1 phi2", "x:3", "x1:4", "a:d", "x:0",
         "x0:2, y", "m1 m2 l1 l2 g"]


def _names(result):
    if isinstance(result, (tuple, list)):
        return type(result), [_names(r) for r in result]
    return "symbol", str(result)


@pytest.mark.parametrize("text", CASES)
def test_symbols_as_sympy(text):
    """The same kind of result (one Symbol or a tuple) and the same names as sympy.symbols."""
    ours, ref = jd.symbols(text), sp.symbols(text)
    assert _names(ours) == _names(ref)
    assert _names(jd.symbols(text, seq=True)) == _names(sp.symbols(text, seq=True))
    if not isinstance(ours, tuple):
        assert isinstance(ours, se.Symbol)


def test_symbols_sequences_of_strings():
    assert _names(jd.symbols(["x", "y z"])) == _names(sp.symbols(["x", "y z"]))
    assert _names(jd.symbols(("x", "y"))) == _names(sp.symbols(("x", "y")))


@pytest.mark.parametrize(("text", "words"), [
    ("", "no symbol names"), ("  ", "no symbol names"), ("2x", "not a valid identifier"),
    ("x-y", "not a valid identifier"), ("x:2:3", "not supported"), ("x(:2)", "not supported"),
    (":3", "must read"), ("x:3b", "must read")])
def test_symbols_bad_names(text, words):
    with pytest.raises(ModelError, match=words):
        jd.symbols(text)
