"""Shared fixtures. The compiled libraries of the tests go to a temporary cache (or to
``$JOURDAIN_TEST_CACHE``, as ``make test`` sets it), never to the user's ~/.cache/jourdain; child
processes started by the tests inherit it. The libraries compiled at install time
(``setup.py``: the integrator) are not used (``JOURDAIN_PREBUILT`` empty), so that every test
compiles what it uses, whether the install compiled or not; tests/test_prebuilt.py checks them."""

import os
import shutil
import tempfile

import numpy as np
import pytest

_given = os.environ.get("JOURDAIN_TEST_CACHE")
_temporary = None if _given else tempfile.mkdtemp(prefix="jourdain-test-cache-")
os.environ["JOURDAIN_CACHE"] = _given or _temporary
os.environ["JOURDAIN_PREBUILT"] = ""


def pytest_configure(config: pytest.Config) -> None:
    config.addinivalue_line(
        "markers", "own_hash_seeds: the test starts child processes with PYTHONHASHSEEDs of "
        "its own, so the suite's second pass under another seed (make test) adds nothing")
    config.addinivalue_line(
        "markers", "no_jourdain: the test checks an external reference and does not import "
        "jourdain, so the suite's second pass under another seed adds nothing")


def pytest_collection_modifyitems(config: pytest.Config, items: list) -> None:
    """Tests marked ``own_hash_seeds`` or ``no_jourdain`` run once per ``make test``: in its
    first pass (PYTHONHASHSEED=0) or where no seed is set, and are skipped, with the reason,
    in the second."""
    seed = os.environ.get("PYTHONHASHSEED", "")
    if seed in ("", "0", "random"):
        return
    skip = pytest.mark.skip(reason="spawns its own PYTHONHASHSEEDs: runs in the pass with "
                                   "PYTHONHASHSEED=0 (or none)")
    external = pytest.mark.skip(reason="an external reference's own check (jourdain not "
                                       "imported): runs in the pass with PYTHONHASHSEED=0")
    for item in items:
        if "own_hash_seeds" in item.keywords:
            item.add_marker(skip)
        elif "no_jourdain" in item.keywords:
            item.add_marker(external)


def pytest_unconfigure(config: pytest.Config) -> None:
    if _temporary:
        shutil.rmtree(_temporary, ignore_errors=True)


@pytest.fixture
def cache(tmp_path, monkeypatch):
    """An empty compile cache of the test's own (the memoized functions and loaded libraries
    forgotten before and after)."""
    from jourdain import numeric
    from jourdain.numeric import toolchain

    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    numeric.clear_cache()
    toolchain._loaded.clear()
    yield tmp_path / "cache"
    numeric.clear_cache()


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(12345)
