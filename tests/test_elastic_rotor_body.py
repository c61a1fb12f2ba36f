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
from pathlib import Path

import numpy as np
import pytest
import scipy.linalg as sla
from scipy.optimize import brentq

import jourdain as jd
from jourdain.analysis.sweep import stability_boundary, sweep
from jourdain.elastic.rotor import campbell, eigenvalues
from jourdain.io.report.campbell import _frequencies
from jourdain.models.elastic import flexible_rotor, flexible_rotor_fe

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


def test_campbell_diagram_equals_ross(linearized) -> None:
    with redirect_stdout(io.StringIO()):  # CoolProp, which ROSS imports, prints about REFPROP
        rs = pytest.importorskip("ross", reason="ROSS is the elastic-ref extra")
    steel = rs.Material(name="steel_jourdain", rho=7810.0, E=211e9, Poisson=NU)
    shaft = [rs.ShaftElement(L=1.5 / 24, idl=ID, odl=OD, material=steel, shear_effects=True,
                             rotary_inertia=True, gyroscopic=True) for _ in range(24)]
    discs = [rs.DiskElement(n=8, m=32.59, Id=0.17809, Ip=0.32956),
             rs.DiskElement(n=16, m=25.0, Id=0.12, Ip=0.2)]
    bearings = [rs.BearingElement(n=0, kxx=1e6, kyy=8e5, kxy=2e5, kyx=-1e5, cxx=300.0,
                                  cyy=200.0),
                rs.BearingElement(n=24, kxx=1.5e6, kyy=7e5, cxx=150.0, cyy=250.0)]
    with redirect_stdout(io.StringIO()):
        camp = rs.Rotor(shaft, discs, bearings).run_campbell(SPEEDS, frequencies=6)
    theirs = np.sort(np.asarray(camp.wd), axis=1)
    mine = _frequencies(sweep(linearized, "Omega", SPEEDS).eigenvalues)[:, :6]
    rel = np.abs(mine / theirs - 1)
    assert rel[:, :4].max() < 5e-4, rel
    assert rel[:, 4:].max() < 5e-3, rel
