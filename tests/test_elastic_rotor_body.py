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
from scipy.optimize import brentq

import jourdain as jd
from jourdain.analysis.sweep import stability_boundary, sweep
from jourdain.elastic import Beam
from jourdain.elastic.rotor import Bearing, Disc, campbell, eigenvalues, rotor
from jourdain.io.report.campbell import _frequencies

EXAMPLE = Path(__file__).parent.parent / "examples" / "flexible_rotor.toml"
SPEEDS = np.array([0.0, 250.0, 500.0, 750.0, 1000.0])
OD, ID, NU = 0.05, 0.01, 0.3


def _fe_rotor(n_el: int = 24):
    A = np.pi * (OD**2 - ID**2) / 4
    I = np.pi * (OD**4 - ID**4) / 64
    m2 = (ID / OD) ** 2
    kappa = 6 * (1 + NU) * (1 + m2) ** 2 / ((7 + 6 * NU) * (1 + m2) ** 2 + (20 + 12 * NU) * m2)
    beam = Beam(length=1.5, E=211e9, rho=7810.0, A=A, I_y=I, I_z=I, J=2 * I, nu=NU,
                kappa=kappa, n_elements=n_el, axis=(0.0, 0.0, 1.0))
    k = n_el // 6
    r = rotor(beam, [Disc(2 * k, 32.59, 0.17809, 0.32956), Disc(4 * k, 25.0, 0.12, 0.2)],
              [Bearing(0, 1e6, 8e5, 2e5, -1e5, 300.0, 200.0),
               Bearing(n_el, 1.5e6, 7e5, c_yy=150.0, c_zz=250.0)])
    lateral = [i for i, (_, n) in enumerate(r.fe.dofs) if n not in ("uz", "rz")]
    return r, lateral


@pytest.fixture(scope="module")
def linearized():
    system = jd.load_model(EXAMPLE).system
    return system.linearize({c: 0 for c in system.coordinate_names})


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
