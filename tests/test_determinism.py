"""Bit-for-bit reproducibility across processes: the same model gives the same symbolic
equations (as the C source of their shared expression graph), the same generated C sources and
the same numbers whatever ``PYTHONHASHSEED`` and the
memory layout of the process (nothing keys, orders or compares by id(), address or hash; see
jourdain.identity). Each case runs in three fresh interpreters."""

import json
import os
import subprocess
import sys
from pathlib import Path

import pytest

CHILD = r"""
import hashlib, json, sys
import numpy as np
import jourdain as jd
from jourdain import models
from jourdain.numeric.ccode import argument_names, function_source
from jourdain.numeric.recursive import recursive_source
from jourdain.stages.reactions import joint_directions

def sha(text):
    return hashlib.sha256(text.encode()).hexdigest()

out = {}
junk = [object() for _ in range(int(sys.argv[1]))]  # a different memory history per process
for name, system in [("chain", models.spatial_chain(5)),
                     ("cart", models.n_link_pendulum_on_cart(3)),
                     ("tree", models.random_tree(8, seed=4))]:
    eom = system.equations_of_motion()
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    dirs = tuple(jr.wrenches for jr in joint_directions(system))
    lin = system.linearize({c: 0 for c in system.coordinate_names})
    y = np.linspace(-1, 1, system.f)
    values = system.evaluate(y, 0.5 * y[::-1], inputs=[0.3] * len(system.inputs) or None)
    out[name] = {
        "projection C": sha(function_source("jd_fn", exprs, names)),
        "recursive C": sha(recursive_source(system, True, dirs)),
        "linearization C": sha(function_source(
            "jd_lin", [e for m in (lin.M_tilde, lin.P, lin.Q, lin.h) for e in m.entries()],
            names)),
        "numbers": sha(repr({k: np.asarray(v).tobytes().hex() for k, v in values.items()
                             if k in ("M", "k", "q", "g", "J_bar", "Q_bar")})),
    }
print(json.dumps(out))
"""


@pytest.mark.own_hash_seeds
def test_same_sources_and_numbers_in_fresh_processes(tmp_path):
    root = Path(__file__).resolve().parent.parent
    results = []
    for k, seed in enumerate(("0", "1", "12345")):
        env = {**os.environ, "PYTHONHASHSEED": seed,
               "JOURDAIN_CACHE": str(tmp_path / f"cache{k}")}
        proc = subprocess.run([sys.executable, "-c", CHILD, str(1000 * (k + 1) ** 3)], env=env,
                              cwd=root, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-3000:]
        results.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert results[0] == results[1] == results[2]


STUDY_CHILD = r"""
import hashlib, json, sys
import numpy as np
from jourdain.study import load_study, run_study

junk = [object() for _ in range(int(sys.argv[1]))]
out = {}
for name in ("map", "montecarlo", "critical"):
    ds = run_study(load_study(f"tests/data/study/{name}.toml"), workers=1, quiet=True)
    out[name] = {k: hashlib.sha256(np.ascontiguousarray(v.values).tobytes()).hexdigest()
                 for k, v in ds.data_vars.items()}
    out[name]["coords"] = repr({k: v.values.tolist() for k, v in ds.coords.items()})
    out[name]["attrs"] = repr(sorted(ds.attrs.items()))
print(json.dumps(out))
"""


@pytest.mark.own_hash_seeds
def test_same_study_results_in_fresh_processes(tmp_path):
    """A grid map, a Monte-Carlo run (drawn from its seed, simulated) and critical values by
    bisection: every variable, coordinate and attribute of the datasets equal to the bit in
    fresh interpreters with other hash seeds, memory histories and compile caches."""
    root = Path(__file__).resolve().parent.parent
    results = []
    for k, seed in enumerate(("0", "4242")):
        env = {**os.environ, "PYTHONHASHSEED": seed,
               "JOURDAIN_CACHE": str(tmp_path / f"cache{k}")}
        proc = subprocess.run([sys.executable, "-c", STUDY_CHILD, str(1000 * (k + 1) ** 3)],
                              env=env, cwd=root, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-3000:]
        results.append(json.loads(proc.stdout.strip().splitlines()[-1]))
    assert results[0] == results[1]
    assert set(results[0]["montecarlo"]) > {"coords", "attrs"}
