"""jourdain.System (the pipeline) over jourdain.model.System (the description), issue 16: the
model has no stage methods; the pipeline's stages are computed once per instance, also under
concurrent first calls, and travel through pickle without what it kept."""

import pickle
import threading

import numpy as np
import pytest

import jourdain as jd
import jourdain.model
import jourdain.pipeline
from jourdain.models import double_pendulum
from jourdain.stages.kinematics import kinematics
from jourdain.stages.newton_euler import newton_euler
from jourdain.stages.projection import projection

STAGES = ("kinematics", "newton_euler", "equations_of_motion", "reactions")


def test_the_public_system_is_the_pipeline_over_the_model():
    assert jd.System is jourdain.pipeline.System
    assert issubclass(jd.System, jourdain.model.System)
    for name in (*STAGES, "linearize", "evaluate", "simulate"):
        assert hasattr(jd.System, name)
        assert not hasattr(jourdain.model.System, name), f"the model still has {name}()"


def test_builders_give_the_pipeline_system():
    assert type(double_pendulum()) is jd.System
    model = jd.load_model("examples/double_pendulum.toml")
    assert type(model.system) is jd.System


def _base(system):
    """The same description as a plain model System."""
    s = system
    return jourdain.model.System(s.coordinates, s.bodies, s.forces, dict(s.parameters),
                                 s.inputs, dict(s.units), s.name)


def test_stages_run_once_per_system_and_match_the_free_functions():
    s = double_pendulum()
    for name in STAGES:
        assert getattr(s, name)() is getattr(s, name)(), f"{name}() computed twice"
    assert s.newton_euler().kinematics is s.kinematics()
    assert s.equations_of_motion().newton_euler is s.newton_euler()
    # the stages of the plain description, by the free functions, give the same equations
    eom = projection(newton_euler(kinematics(_base(s))))
    assert eom.M.entries() == s.equations_of_motion().M.entries()
    assert eom.k.entries() == s.equations_of_motion().k.entries()
    # another, equal system keeps its own
    other = double_pendulum()
    assert other == s and hash(other) == hash(s)
    assert other.kinematics() is not s.kinematics()


def test_concurrent_first_calls_compute_each_stage_once(monkeypatch):
    import jourdain.pipeline.system as ps

    calls = []
    real = ps.kinematics

    def counted(system):
        calls.append(threading.get_ident())
        return real(system)

    monkeypatch.setattr(ps, "kinematics", counted)
    s = double_pendulum()
    barrier = threading.Barrier(8)
    got = []

    def work():
        barrier.wait()
        got.append(s.equations_of_motion())

    threads = [threading.Thread(target=work) for _ in range(8)]
    for th in threads:
        th.start()
    for th in threads:
        th.join()
    assert len(calls) == 1
    assert len(got) == 8 and all(g is got[0] for g in got)


def test_pickle_leaves_the_kept_stages_and_hash_behind():
    s = double_pendulum()
    s.equations_of_motion()
    hash(s)
    state = s.__getstate__()
    assert not [k for k in state if k.startswith("_")]
    copy = pickle.loads(pickle.dumps(s))
    assert type(copy) is jd.System and copy == s
    assert not [k for k in vars(copy) if k.startswith("_")]
    # the copy derives its own stages, the same equations
    assert copy.equations_of_motion().M.entries() == s.equations_of_motion().M.entries()


def test_evaluate_and_simulate_on_the_pipeline():
    s = double_pendulum()
    y, yd = [0.3, -0.2], [0.1, 0.4]
    out = s.evaluate(y, yd)
    # M·ÿ + k = q and Newton–Euler M̄·J̄·ÿ + q̄^c = q̄^e + Q̄·g hold with the reactions g
    ydd = np.linalg.solve(out["M"], out["q"] - out["k"])
    lhs = out["M_bar"] @ out["J_bar"] @ ydd + out["q_c"]
    rhs = out["q_e"] + out["Q_bar"] @ out["g"]
    scale = np.abs(out["M_bar"]).max() * np.abs(out["J_bar"]).max() * np.abs(ydd).max() \
        + np.abs(out["q_e"]).max()
    assert np.allclose(lhs, rhs, rtol=0, atol=1e3 * np.finfo(float).eps * scale)
    res = s.simulate((0.0, 0.1), y, yd)
    assert res.t[-1] == pytest.approx(0.1)
