"""The composite-body projection (jourdain.stages.composite) of the shared kinematics: the same
M, k, q as the body-by-body sums, on every kind of model, and expressions that grow like f²."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import symengine as se

from jourdain import models
from jourdain.graph import evaluate_float
from jourdain.io.modelfile.loader import load_model
from jourdain.model import (
    Body,
    General,
    Gravity,
    Revolute,
    Rot,
    SpringDamper,
    Trans,
    planar_inertia,
    symbols,
)
from jourdain.numeric.compiled import count_nodes
from jourdain.pipeline import System
from jourdain.stages.composite import composite_projection
from jourdain.stages.kinematics import kinematics
from jourdain.stages.kinematics.result import SHARED_FROM_F
from jourdain.stages.newton_euler import newton_euler
from jourdain.stages.projection import projection
from tests.tolerance import eval_tol

EXAMPLES = Path(__file__).resolve().parent.parent / "examples"
#: model files whose trees have springs, dampers, bushings, follower forces, inputs, rheonomic
#: steps and closing joints (cut open)
FILES = ("andrews_squeezer", "double_four_bar", "follower_double_pendulum", "four_bar",
         "gyroscopic_rotor", "heavy_top", "parametric_pendulum", "quarter_car",
         "rotor_internal_damping", "slider_crank", "slider_on_rotating_rod", "spatial_rssr",
         "vehicle_on_bushings", "wheel_creep")


def coupled() -> System:
    """A tree whose coordinates enter more than one step: ``a`` drives the root joint, the
    second joint (through ``b + 2a``) and a slider in the other branch; ``b`` both a rotation
    and a translation; a body with a planar inertia, a spring across the branches."""
    a, b, c, d = symbols("a b c d")
    m, l, k, g = symbols("m l k g")
    bodies = [
        Body("base", "world", Revolute("hinge", a, "z"), mass=m, com=(l, 0, 0),
             inertia=(1, 2, 3)),
        Body("arm", "base", General("coupled", [Rot("z", b + 2 * a), Trans("x", l * b)],
                                    coordinates=[b], position=(l, 0, 0)),
             mass=2 * m, com=(0, l / 2, 0), inertia=planar_inertia(m * l**2 / 12, "z")),
        Body("tip", "arm", General("pitch", [Rot("y", c)], coordinates=[c],
                                   position=(0, l, 0)), mass=m, com=(l / 3, 0, l / 4),
             inertia=(0.1, 0.2, 0.25)),
        Body("slider", "base", General("geared", [Trans(vector=(a * l, d, 0)), Rot("x", d)],
                                       coordinates=[d], position=(0, 0, l)),
             mass=m / 2, com=(0, 0, l / 5), inertia=(0.05, 0.05, 0.02)),
    ]
    forces = [Gravity((0, 0, -g)), SpringDamper("spring", "tip", (0, 0, 0), "slider",
                                                (0, 0, 0), stiffness=k, rest_length=l)]
    return System([a, b, c, d], bodies, forces, name="coupled",
                  parameters={"m": 1.3, "l": 0.7, "k": 40.0, "g": 9.81})


def _both(system: System):
    old = projection(newton_euler(kinematics(system, shared=False)))
    new = projection(newton_euler(kinematics(system, shared=True)))
    return old, new


def _values(system: System, rng: np.random.Generator) -> dict:
    v = dict(system.parameter_values)
    v.update({str(s): rng.uniform(-np.pi, np.pi) for s in system.y})
    v.update({str(s): rng.uniform(-3.0, 3.0) for s in system.yd})
    v.update({str(s): rng.uniform(-1.0, 1.0) for s in system.inputs})
    v["t"] = rng.uniform(0.0, 2.0)
    return v


def _numbers(m, values: dict) -> np.ndarray:
    n, k = m.shape
    return np.array(evaluate_float(m.entries(), values)).reshape(n, k)


def assert_same_equations(system: System, states: int = 3) -> None:
    """M, k, q of the composite bodies against the body-by-body sums at random states, within
    the evaluation tolerance of the projection's terms (tests/README.md)."""
    old, new = _both(system)
    assert composite_projection(new.newton_euler) is not None
    ne = old.newton_euler
    n_terms = 6 * len(system.bodies)
    rng = np.random.default_rng(35)
    for _ in range(states):
        v = _values(system, rng)
        J, Mb = np.abs(_numbers(ne.J_bar, v)), np.abs(_numbers(ne.M_bar, v))
        qc, qe = np.abs(_numbers(ne.q_c, v)), np.abs(_numbers(ne.q_e, v))
        scale_M = float((J.T @ Mb @ J).max())
        scale_f = float((J.T @ (qc + qe)).max(initial=0.0)) + scale_M
        for name, scale in (("M", scale_M), ("k", scale_f), ("q", scale_f)):
            ours, ref = _numbers(getattr(new, name), v), _numbers(getattr(old, name), v)
            d = float(np.abs(ours - ref).max())
            assert d <= eval_tol(n_terms, scale), (name, d, scale)
        # the kinematics' own results: J̄ of S·(local column) against the inertial sums
        J_new = _numbers(new.newton_euler.J_bar, v)
        assert np.abs(J_new - _numbers(ne.J_bar, v)).max() <= eval_tol(n_terms, J.max() + 1)


@pytest.mark.parametrize("name", ["double_pendulum", "heavy_top", "cart3", "robot_arm",
                                  "chain4", "tree6", "tree10", "coupled"])
def test_composite_bodies_give_the_same_equations(name):
    system = {"double_pendulum": models.double_pendulum, "heavy_top": models.heavy_top,
              "cart3": lambda: models.n_link_pendulum_on_cart(3),
              "robot_arm": models.robot_arm, "chain4": lambda: models.spatial_chain(4),
              "tree6": lambda: models.random_tree(6, seed=1),
              "tree10": lambda: models.random_tree(10, seed=2), "coupled": coupled}[name]()
    assert_same_equations(system)


@pytest.mark.parametrize("name", FILES)
def test_composite_bodies_of_the_example_files(name):
    system = load_model(EXAMPLES / f"{name}.toml").system
    assert_same_equations(system.tree if system.closing else system, states=2)


def test_small_systems_keep_the_textbook_sums():
    """Below SHARED_FROM_F coordinates the projection sums body by body (the double
    pendulum's M as a textbook writes it: tests/test_display_output.py); from there on, the
    composite bodies."""
    assert composite_projection(models.double_pendulum().newton_euler()) is None
    chain = models.spatial_chain(13)
    assert chain.f >= SHARED_FROM_F
    assert chain.kinematics().nodes is not None
    assert composite_projection(chain.newton_euler()) is not None


def test_expressions_grow_like_f_squared():
    """Distinct nodes of M, k, q for spatial chains of f = 31 and 63: at most 4.3 times as
    many for twice the coordinates (f² gives 4.1; the body-by-body sums grew like f³)."""
    sizes = []
    for n in (16, 32):
        eom = projection(newton_euler(kinematics(models.spatial_chain(n), shared=True)))
        exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
        sizes.append(count_nodes(exprs, 10**8))
    assert sizes[1] / sizes[0] <= 4.3, sizes


def test_mass_matrix_is_exactly_symmetric_and_shares_its_entries():
    eom = projection(newton_euler(kinematics(models.random_tree(5, seed=3), shared=True)))
    M = eom.M
    f = M.shape[0]
    assert all(M[i, j] is M[j, i] or M[i, j] == M[j, i] for i in range(f) for j in range(f))
    assert all(isinstance(e, se.Basic) for e in M.entries())


CHILD = r"""
import hashlib, sys
from jourdain import models
from jourdain.numeric.ccode import argument_names, function_source
from jourdain.stages.kinematics import kinematics
from jourdain.stages.newton_euler import newton_euler
from jourdain.stages.projection import projection
junk = [object() for _ in range(int(sys.argv[1]))]  # a different memory history per process
out = []
for system in (models.random_tree(9, seed=4), models.n_link_pendulum_on_cart(4)):
    eom = projection(newton_euler(kinematics(system, shared=True)))
    exprs = [*eom.M.entries(), *eom.k.entries(), *eom.q.entries()]
    names = argument_names(system.y, system.yd, system.t, system.parameter_symbols,
                           system.inputs)
    out.append(hashlib.sha256(function_source("jd_fn", exprs, names).encode()).hexdigest())
print(" ".join(out))
"""


@pytest.mark.own_hash_seeds
def test_composite_bodies_are_the_same_in_every_process():
    """The composite-body equations, as the C source of their graph, are the same whatever
    PYTHONHASHSEED and the memory layout (nothing keyed or ordered by id or hash)."""
    root = Path(__file__).resolve().parent.parent
    seen = set()
    for k, seed in enumerate(("0", "12345")):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        proc = subprocess.run([sys.executable, "-c", CHILD, str(1000 * (k + 1) ** 3)], env=env,
                              cwd=root, capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-3000:]
        seen.add(proc.stdout.strip().splitlines()[-1])
    assert len(seen) == 1, seen
