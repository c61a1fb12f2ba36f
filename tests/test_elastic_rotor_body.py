"""The flexible rotor as an elastic body of the method (examples/flexible_rotor.toml) against
the finite-element rotor of jourdain.elastic.rotor — which equals ROSS for the same elements
(tests/test_elastic_rotor.py: Campbell diagram to 3e-12) — and against ROSS itself where the
``elastic-ref`` extra is installed.

The body is the same shaft (24 Timoshenko elements), discs and anisotropic, cross-coupled
bearings, reduced to its 16 lowest bending modes on the bearings; its mass and the sections'
and discs' inertia are lumped at the nodes, which spin on the nodes' small tilts. The
difference to the consistent FE rotor is the lumping's (h², measured at Ω = 0 … 1000 rad/s:
the four lowest frequencies within 2.5e-4, the fifth and sixth within 3.5e-3; the consistent
elements themselves change by ≤ 1.3e-5 from 24 to 48 elements), so the tolerances are 5e-4
and 5e-3. The stability boundary over speed (the cross-coupled bearings destabilize the rotor)
measured 485.879 against 485.633 rad/s.
"""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
import symengine as se
from scipy.optimize import brentq

import jourdain as jd
from jourdain.analysis.sweep import stability_boundary, sweep
from jourdain.elastic.rotor import campbell, eigenvalues
from jourdain.io.report.campbell import _frequencies
from jourdain.model.expressions import t
from jourdain.models.elastic import flexible_rotor, flexible_rotor_fe, rotor_parts, rotor_shaft
from jourdain.study import loads_study, run_study
from jourdain.study.linear import VERDICTS

EXAMPLE = Path(__file__).parent.parent / "examples" / "flexible_rotor.toml"
SPEEDS = np.array([0.0, 250.0, 500.0, 750.0, 1000.0])
OD, ID, NU = 0.05, 0.01, 0.3


def _fe_rotor(n_el: int = 24):
    r = flexible_rotor_fe(n_el)
    lateral = [i for i, (_, n) in enumerate(r.fe.dofs) if n not in ("uz", "rz")]
    return r, lateral


@pytest.fixture(scope="module")
def linearized():
    system = jd.load_model(EXAMPLE).system
    return system.linearize({c: 0 for c in system.coordinate_names})


def test_the_example_is_the_sample_model() -> None:
    """examples/flexible_rotor.toml and jourdain.models.elastic.flexible_rotor: the same
    elastic body — masses, sections, spin, bearings' K_e and D_e, modes. The file writes the
    section's numbers to 17 digits, so the modes may differ by the eigenvectors' rounding:
    eps times the spread of the FE rotor's eigenvalues (measured 1e-12 relative)."""
    a, b = jd.load_model(EXAMPLE).system.groups[0], flexible_rotor().groups[0]
    r, lateral = _fe_rotor()
    ix = np.ix_(lateral, lateral)
    lam = sla.eigvalsh(0.5 * (r.K + r.K.T)[ix], r.M[ix])
    tol = 10 * np.finfo(float).eps * lam.max() / lam.min()
    assert str(a.spin[1]) == str(b.spin[1]) and a.spin[0] == b.spin[0]
    assert len(a.expand()[1]) == len(b.expand()[1])
    for x, y in ((a.node_mass, b.node_mass), (a.node_inertia, b.node_inertia),
                 (a.modal.omega, b.modal.omega), (a.modal.K_e, b.modal.K_e),
                 (a.modal.D_e, b.modal.D_e), (a.modal.Phi, b.modal.Phi)):
        assert np.abs(x - y).max() <= tol * np.abs(y).max()


def test_campbell_diagram_equals_the_fe_rotor(linearized) -> None:
    mine = _frequencies(sweep(linearized, "Omega", SPEEDS).eigenvalues)[:, :6]
    r, lateral = _fe_rotor()
    ref = campbell(r, SPEEDS, 6, lateral)
    rel = np.abs(mine / ref - 1)
    assert rel[:, :4].max() < 5e-4, rel
    assert rel[:, 4:].max() < 5e-3, rel


def test_stability_boundary_over_speed(linearized) -> None:
    r, lateral = _fe_rotor()
    ref = brentq(lambda w: eigenvalues(r, w, lateral).real.max(), 400.0, 600.0, xtol=1e-10)
    mine = stability_boundary(linearized, "Omega", 400.0, 600.0)
    assert abs(mine / ref - 1) < 1e-3


def _ross_rotor(rs, n_el: int):  # type: ignore[no-untyped-def]
    """ROSS's model of the same rotor: shaft of n_el Timoshenko elements, the discs and
    bearings at the nodes of jourdain.models.elastic.rotor_parts (a third and two thirds of
    the shaft, and its ends)."""
    steel = rs.Material(name="steel_jourdain", rho=7810.0, E=211e9, Poisson=NU)
    shaft = [rs.ShaftElement(L=1.5 / n_el, idl=ID, odl=OD, material=steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(n_el)]
    k = n_el // 6
    discs = [rs.DiskElement(n=2 * k, m=32.59, Id=0.17809, Ip=0.32956),
             rs.DiskElement(n=4 * k, m=25.0, Id=0.12, Ip=0.2)]
    bearings = [rs.BearingElement(n=0, kxx=1e6, kyy=8e5, kxy=2e5, kyx=-1e5, cxx=300.0,
                                  cyy=200.0),
                rs.BearingElement(n=n_el, kxx=1.5e6, kyy=7e5, cxx=150.0, cyy=250.0)]
    return rs.Rotor(shaft, discs, bearings)


def test_campbell_diagram_equals_ross(linearized) -> None:
    with redirect_stdout(io.StringIO()):  # CoolProp, which ROSS imports, prints about REFPROP
        rs = pytest.importorskip("ross", reason="ROSS is the elastic-ref extra")
    with redirect_stdout(io.StringIO()):
        camp = _ross_rotor(rs, 24).run_campbell(SPEEDS, frequencies=6)
    theirs = np.sort(np.asarray(camp.wd), axis=1)
    mine = _frequencies(sweep(linearized, "Omega", SPEEDS).eigenvalues)[:, :6]
    rel = np.abs(mine / theirs - 1)
    assert rel[:, :4].max() < 5e-4, rel
    assert rel[:, 4:].max() < 5e-3, rel


def _consistent_rotor(n_el: int, n_modes: int) -> jd.System:
    discs, bearings = rotor_parts(n_el)
    body = jd.ElasticBody.rotor("shaft", "world", jd.Fixed("frame"), rotor_shaft(n_el), n_modes,
                                spin=se.Symbol("Omega") * t, discs=discs, bearings=bearings,
                                mass="consistent")
    return jd.System([], [body], [], parameters={"Omega": 0.0})


def test_consistent_mass_equals_the_fe_rotor_on_its_modes() -> None:
    """mass="consistent": the shaft's mass and sections at the elements' Gauss points. The
    linearized body is then the FE rotor (consistent Timoshenko mass, Nelson's gyroscopic
    matrix) projected on the body's own modes — ΦᵀMΦ, Φᵀ(C + ΩG)Φ, ΦᵀKΦ — so the Campbell
    diagram agrees to round-off: eps times the spread of the reduced eigenvalues."""
    system = _consistent_rotor(6, 8)
    body = system.groups[0]
    lin = system.linearize({c: 0 for c in system.coordinate_names})
    mine = _frequencies(sweep(lin, "Omega", SPEEDS).eigenvalues)[:, :6]
    r = flexible_rotor_fe(6)
    Phi = body.modal.Phi
    reduced = replace(r, **{k: Phi.T @ getattr(r, k) @ Phi for k in ("M", "C", "G", "K")})
    ref = campbell(reduced, SPEEDS, 6)
    lam = sla.eigvalsh(0.5 * (reduced.K + reduced.K.T), reduced.M)
    tol = 100 * np.finfo(float).eps * lam.max() / lam.min()
    assert np.abs(mine / ref - 1).max() < tol, (np.abs(mine / ref - 1).max(), tol)


def test_consistent_mass_with_every_mode_equals_ross() -> None:
    """With every lateral mode kept (28 of the 6-element rotor), the consistent body is the
    full FE rotor: its Campbell diagram equals ROSS's for the same elements to the issue's
    1e-6 (measured 6e-13 against jourdain's FE rotor, which equals ROSS to 3e-12)."""
    with redirect_stdout(io.StringIO()):
        rs = pytest.importorskip("ross", reason="ROSS is the elastic-ref extra")
    system = _consistent_rotor(6, 28)
    lin = system.linearize({c: 0 for c in system.coordinate_names})
    mine = _frequencies(sweep(lin, "Omega", SPEEDS).eigenvalues)[:, :6]
    with redirect_stdout(io.StringIO()):
        camp = _ross_rotor(rs, 6).run_campbell(SPEEDS, frequencies=6)
    theirs = np.sort(np.asarray(camp.wd), axis=1)
    assert np.abs(mine / theirs - 1).max() < 1e-6


def test_a_parameter_study_over_speed(linearized) -> None:
    """A study of the example over the spin speed (jourdain.study: the compiled
    linearization, batched): its eigenvalues equal those of the linearization's state space
    at each speed, to the eigenvalues' accuracy (eps·‖A‖ times the spread of the modes), and
    its verdicts turn unstable past the boundary of test_stability_boundary_over_speed."""
    spec = loads_study(f'[study]\nmodel = "{EXAMPLE}"\ndesign = "list"\n[vary.Omega]\n'
                       'values = [0.0, 300.0, 600.0]\n[compute.linearize]\nabout = "spinning"\n')
    ds = run_study(spec, workers=1)
    assert (ds.error.values == "").all()
    for k, om in enumerate(ds.Omega.values):
        ss = jd.state_space(linearized, parameters={"Omega": float(om)})
        ref = np.linalg.eigvals(ss.A)
        w = np.abs(ref)
        tol = 1e3 * np.finfo(float).eps * np.abs(ss.A).max() * w.max() / w.min()
        lam = ds.eigenvalue_real.values[k] + 1j * ds.eigenvalue_imag.values[k]
        assert len(lam) == len(ref)
        assert max(float(np.abs(ref - z).min()) for z in lam) <= tol
    assert [VERDICTS[int(v)] for v in ds.verdict.values] == ["asymptotically stable"] * 2 + [
        "unstable"]
