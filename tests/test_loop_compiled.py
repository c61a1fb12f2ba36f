"""The compiled right-hand side of closed-loop systems (jourdain.loops.compiled, loop_c.h) and
its C-integrator driver: equal to the Python evaluator at states of three mechanisms, the same
motion as the SciPy-stepped route, on the manifold over a long run, singular positions
reported by the C kernel's condition estimate."""

from __future__ import annotations

import math
from contextlib import nullcontext
from pathlib import Path

import numpy as np
import pytest

from jourdain.errors import JourdainWarning
from jourdain.io.modelfile import loads_model
from jourdain.loops import LoopEvaluator
from jourdain.loops.compiled import LoopKernel
from jourdain.models.loops import four_bar, n_four_bar, slider_crank
from tests.tolerance import EPS, cond, solve_tol

EXAMPLES = Path(__file__).resolve().parents[1] / "examples"


def _rssr() -> tuple:
    mf = loads_model((EXAMPLES / "spatial_rssr.toml").read_text(), "spatial_rssr.toml")
    return mf.system, np.asarray(mf.simulation.y0, float), np.asarray(mf.simulation.yd0, float)


CASES = {
    "four_bar": lambda: (four_bar(), np.array([0.5, 0.8, 1.9]), np.array([1.0, 0.0, 0.0])),
    "slider_crank": lambda: (slider_crank(), None, None),
    "spatial_rssr": _rssr,
}


def _dependent_rates(ev: LoopEvaluator, zd0: np.ndarray) -> bool:
    return bool(np.any(np.asarray(zd0)[list(ev.part.dependent)] != 0))


@pytest.mark.parametrize("name", sorted(CASES))
def test_compiled_state_equals_python_evaluator(name: str) -> None:
    """z, ż, z̈, Φ̇ and λ of the C kernel equal LoopEvaluator's (Newton, linear solves and the
    projection in NumPy/LAPACK) at states along a sweep of the independent coordinates."""
    loop, z0, zd0 = CASES[name]()
    n = loop.f
    z0 = np.zeros(n) if z0 is None else z0
    zd0 = np.ones(n) if zd0 is None else zd0
    ev = LoopEvaluator(loop, z0)
    with pytest.warns(JourdainWarning) if _dependent_rates(ev, zd0) else nullcontext():
        asm = ev.assemble(z0, zd0)  # rates given to dependent coordinates are warned of
    kernel = LoopKernel(ev)
    kernel.restart(asm.z, asm.z[list(ev.part.independent)])
    ind = list(ev.part.independent)
    f = len(ind)
    y0, yd0 = asm.z[ind], asm.zd[ind]
    steps = np.linspace(0.0, 0.3, 7)
    X = np.array([np.concatenate([y0 + s, yd0 * (1 + s)]) for s in steps])
    got, bad = kernel.samples(np.zeros(len(steps)), X)
    assert bad == -1
    for k, x in enumerate(X):
        s = ev.accelerations(x[:f], x[f:], 0.0)
        lam = ev.multipliers(s)
        rows, dep = list(ev.part.rows), list(ev.part.dependent)
        Pd = s["Phi_z"][np.ix_(rows, dep)]
        scale = 1.0 + float(np.max(np.abs(s["z"])))
        # the two Newton solutions differ by their stopping residual mapped by ‖Φ_d⁻¹‖
        tol_z = solve_tol(Pd, scale) + 10 * float(np.linalg.norm(np.linalg.inv(Pd), 2)) \
            * ev.newton_tol * scale
        assert np.max(np.abs(got["z"][k] - s["z"])) <= tol_z
        mag = 1.0 + float(np.max(np.abs(s["zd"]))) + float(np.max(np.abs(s["zdd"]))) \
            + float(np.max(np.abs(lam)))
        K = np.block([[s["M_tree"], s["Phi_z"][rows].T],
                      [s["Phi_z"][rows], np.zeros((len(rows), len(rows)))]])
        # the outputs are smooth in z (unit-size links): their change by tol_z, plus the
        # rounding of the bordered solve
        tol = solve_tol(K, mag) + 10 * tol_z * mag ** 2
        assert np.max(np.abs(got["zd"][k] - s["zd"])) <= tol
        assert np.max(np.abs(got["zdd"][k] - s["zdd"])) <= tol
        assert np.max(np.abs(got["lam"][k] - lam)) <= tol
        assert np.max(np.abs(got["Phi_dot"][k])) <= tol
        # the kernel's condition number (Hager's estimate of the 1-norm one) is a lower
        # bound within the order of Φ_d of the exact value
        c1 = float(np.linalg.cond(Pd, 1))
        assert c1 / len(dep) <= got["cond"][k] <= c1 * (1 + 1e3 * EPS * cond(Pd))


def test_c_engine_and_scipy_engine_give_the_same_motion() -> None:
    loop = four_bar()
    kw = dict(samples=11, rtol=1e-11, atol=1e-13)
    c = loop.simulate((0.0, 1.0), [0.5, 0.8, 1.9], [1.0, 0, 0], **kw)
    s = loop.simulate((0.0, 1.0), [0.5, 0.8, 1.9], [1.0, 0, 0], method="scipy:DOP853", **kw)
    assert c.method == "DOP853" and s.method == "scipy:DOP853"
    assert c.status == s.status == "finished"
    # both within their tolerance of the exact motion: rtol times the motion's scale, per
    # unit time, amplified by at most the rates (|ż| ≲ 3 here) over 1 s
    scale = 1.0 + float(np.max(np.abs(c.y)))
    assert np.max(np.abs(c.y - s.y)) <= 1e3 * 1e-11 * scale
    lam_scale = 1 + float(np.max(np.abs(c.multipliers)))
    assert np.max(np.abs(c.multipliers - s.multipliers)) <= 1e3 * 1e-11 * lam_scale


def test_long_run_stays_on_the_manifold() -> None:
    """200 s of the four-bar (about 160 000 right-hand sides): |Φ| and |Φ̇| at rounding,
    the energy drift that of the integration error alone."""
    res = four_bar().simulate((0.0, 200.0), [0.5, 0.8, 1.9], [1.0, 0, 0], samples=2001,
                        rtol=1e-10, atol=1e-12)
    assert res.status == "finished"
    assert res.closure_residual[0] <= 1e-10 and res.closure_residual[1] <= 1e-10
    # 1e-9 per 10 s (the bound), growing at most linearly
    assert res.energy_drift <= 20 * 1e-9


def test_flat_position_of_the_n_four_bar_is_reported() -> None:
    """Coordinate partitioning cannot pass the N four-bar's flat positions (Φ_z loses rank):
    the run stops before the crank reaches π, naming the time and the lost rank, with the
    motion up to there equal to the exact one (benchmarks/n_four_bar.py)."""
    from benchmarks.n_four_bar import initial_state, reference

    n = 3
    loop = n_four_bar(n)
    z, zd = initial_state(n)
    res = loop.simulate((0.0, 4.0), z, zd, samples=41, rtol=1e-10, atol=1e-12)
    assert res.status == "singular" and res.constraints.singular is not None
    th0 = res.coordinate("th0")
    t_flat = float(res.constraints.singular.t)
    assert 0.0 < t_flat < 4.0 and len(res.t) >= 2
    assert float(th0[-1]) < math.pi < float(reference(n, np.array([0.0, t_flat + 0.1]))[-1])
    assert "singular configuration at t =" in res.message
    assert np.max(np.abs(th0 - reference(n, res.t))) <= 1e-7


def _driven_four_bar():  # noqa: ANN202
    """The four-bar of jourdain.models.loops with an input torque tau on the crank."""
    import jourdain as jd

    base = four_bar()
    tau = jd.symbols("tau")
    tree = base.tree
    driven = jd.System(tree.coordinates, list(tree.bodies),
                       [*tree.forces, jd.GeneralizedForce("drive", tree.coordinates[0], tau)],
                       parameters=dict(tree.parameters), inputs=[tau], name="driven four-bar")
    return driven.closed_by(base.closing, independent=("theta1",)), tau


def test_input_expressions_drive_the_c_engine() -> None:
    """A crank torque τ = 3·sin(2t) given as an expression (compiled, evaluated in C at every
    right-hand side) gives the motion of the same torque as a Python function (SciPy engine),
    and the energy balance E(t) − E(0) = ∫ τ θ̇1 dt (Simpson's rule on the samples)."""
    import symengine as se

    loop, _ = _driven_four_bar()
    t = loop.tree.t
    kw = dict(samples=401, rtol=1e-11, atol=1e-13)
    c = loop.simulate((0.0, 2.0), [0.5, 0.8, 1.9], [1.0, 0, 0],
                      inputs={"tau": 3 * se.sin(2 * t)}, **kw)
    s = loop.simulate((0.0, 2.0), [0.5, 0.8, 1.9], [1.0, 0, 0],
                      inputs=lambda tt: np.array([3 * math.sin(2 * tt)]),
                      method="scipy:DOP853", **kw)
    assert c.status == s.status == "finished" and c.method == "DOP853"
    scale = 1.0 + float(np.max(np.abs(c.y)))
    assert np.max(np.abs(c.y - s.y)) <= 1e3 * 1e-11 * scale
    from scipy.integrate import simpson

    power = 3 * np.sin(2 * c.t) * c.yd[:, 0]
    work = np.array([simpson(power[:k + 1], x=c.t[:k + 1]) for k in range(0, 401, 40)])
    E = c.total_energy[::40] - c.total_energy[0]
    # Simpson's error h⁴/180·max|P⁗|·T with h = 5 ms: below 1e-8 of the work's scale here
    assert np.max(np.abs(E - work)) <= 1e-6 * (1 + float(np.max(np.abs(work))))
    with pytest.raises(Exception, match="t and the parameters only"):
        loop.simulate((0.0, 1.0), [0.5, 0.8, 1.9], None,
                      inputs={"tau": loop.tree.coordinates[0]})


def test_penalty_form_in_c_equals_its_scipy_run() -> None:
    """The augmented-Lagrangian form's C right-hand side (jd_penalty_accel) in the C
    integrator gives SciPy's run of the same formula in NumPy, through the flat position."""
    n = 2
    loop = n_four_bar(n)
    from benchmarks.n_four_bar import initial_state, reference

    z, zd = initial_state(n)
    kw = dict(samples=21, rtol=1e-10, atol=1e-12, formulation="penalty")
    c = loop.simulate((0.0, 2.0), z, zd, **kw)
    s = loop.simulate((0.0, 2.0), z, zd, method="scipy:DOP853", **kw)
    assert c.method == "DOP853" and s.method == "scipy:DOP853"
    assert c.status == s.status == "finished"
    assert float(c.coordinate("th0")[-1]) > math.pi  # through the flat position
    # both within their tolerance of the same motion (and of the exact one)
    assert np.max(np.abs(c.y - s.y)) <= 1e4 * 1e-10
    assert np.max(np.abs(c.coordinate("th0") - reference(n, c.t))) <= 1e-5


def test_the_loop_library_is_compiled_ahead_once(cache, monkeypatch) -> None:
    """A closed system's simulate starts the loop kernel's build in a thread (build_soon) while the tree's
    M, k, q and the constraints compile: the kernel is compiled once, by that thread (the
    simulation's own call waits for it instead of generating and compiling it again), and
    the motion is the same as with the kernel built beforehand."""
    import threading

    from jourdain import numeric
    from jourdain.loops import compiled
    from jourdain.numeric import toolchain

    reference = four_bar().simulate((0.0, 0.5), [0.5, 0.8, 1.9], [1.0, 0.0, 0.0],
                                    samples=11, rtol=1e-10, atol=1e-12)
    monkeypatch.setattr(toolchain, "_loaded", {})
    monkeypatch.setenv("JOURDAIN_CACHE", str(cache / "second"))
    compiled._loop_library.cache_clear()
    numeric.clear_cache()
    kernels: list[str] = []  # the threads that compiled a loop kernel
    real = toolchain.compile_shared

    def counted(sources, units, out, flags, unit_flags=None):
        if any("jd_loop_samples" in str(v) for v in sources.values()):
            kernels.append(threading.current_thread().name)
        real(sources, units, out, flags, unit_flags)

    monkeypatch.setattr(toolchain, "compile_shared", counted)
    res = four_bar().simulate((0.0, 0.5), [0.5, 0.8, 1.9], [1.0, 0.0, 0.0], samples=11,
                              rtol=1e-10, atol=1e-12)
    assert kernels == ["jourdain-loop-build"]
    assert res.y.tobytes() == reference.y.tobytes()
