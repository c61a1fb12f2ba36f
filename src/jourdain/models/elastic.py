"""Sample models with elastic bodies (:class:`jourdain.elastic.ElasticBody`), shared by the
tests and the benchmarks (the same models as ``examples/spinning_beam.toml`` and
``examples/flexible_rotor.toml``, with the mesh and the number of modes as arguments).

Imported by its full name (``jourdain.models.elastic``): it loads SciPy's sparse eigensolvers,
which the other sample models do not need.
"""

from __future__ import annotations

import math

import symengine as se

from ..elastic.beam import Beam
from ..elastic.body import ElasticBody
from ..elastic.rotor import Bearing, Disc, Rotor, rotor
from ..model.expressions import t
from ..model.joints import Fixed, General, Rot
from ..pipeline import System

__all__ = ["spinning_beam", "flexible_rotor", "flexible_rotor_fe", "rotor_shaft", "rotor_parts"]

#: Kane, Ryan & Banerjee's spin-up: final speed (rad/s) and its duration (s)
SPIN_UP = (6.0, 15.0)


def spinning_beam(n_elements: int = 10, n_modes: int = 3, stiffening: bool = True) -> System:
    """The rotating cantilever of Kane, Ryan & Banerjee (1987): L = 10 m, ρA = 1.2 kg/m,
    EI = 1.4e4 N·m², clamped to a hub spun from rest to Ω_s = 6 rad/s over T_s = 15 s by the
    prescribed angle (Ω_s/T_s)·(τ²/2 + (T_s/2π)²·(cos(2πτ/T_s) − 1)) + Ω_s·max(t − T_s, 0),
    τ = min(t, T_s); in-plane bending modes only. The body is ``system.groups[0]``."""
    Ws, Ts = SPIN_UP
    tau = se.Min(t, Ts)
    theta = ((Ws / Ts) * (tau**2 / 2 + (Ts / (2 * math.pi))**2
                          * (se.cos(2 * math.pi * tau / Ts) - 1))
             + Ws * se.Max(t - Ts, 0))
    beam = Beam(length=10.0, E=7e10, rho=3000.0, A=4e-4, I_y=2e-7, I_z=2e-7, J=4e-7, nu=0.3,
                n_elements=n_elements)
    body = ElasticBody.beam("beam", "world", General("hub", [Rot("z", theta)]), beam, n_modes,
                            keep=("uy", "rz"), stiffening=stiffening)
    return System([], [body], [], name="spinning beam")


# ROSS's own test rotor: a hollow steel shaft (1.5 m, 50/10 mm), two discs at a third and two
# thirds of its length, anisotropic bearings with cross-coupled stiffness at its ends
_OD, _ID, _NU = 0.05, 0.01, 0.3


def rotor_shaft(n_elements: int = 24) -> Beam:
    """The shaft (Timoshenko elements, Cowper's shear factor of the tube) along z."""
    A = math.pi * (_OD**2 - _ID**2) / 4
    I = math.pi * (_OD**4 - _ID**4) / 64  # noqa: E741 - the second moment of area
    m2 = (_ID / _OD) ** 2
    kappa = 6 * (1 + _NU) * (1 + m2) ** 2 / ((7 + 6 * _NU) * (1 + m2) ** 2 + (20 + 12 * _NU) * m2)
    return Beam(length=1.5, E=211e9, rho=7810.0, A=A, I_y=I, I_z=I, J=2 * I, nu=_NU,
                kappa=kappa, n_elements=n_elements, axis=(0.0, 0.0, 1.0))


def rotor_parts(n_elements: int = 24) -> tuple[list[Disc], list[Bearing]]:
    """The rotor's discs and bearings at the nodes of an ``n_elements`` mesh (a multiple of
    6: the discs at a third and two thirds of the shaft)."""
    if n_elements % 6:
        raise ValueError(f"the rotor's mesh must have a multiple of 6 elements, got {n_elements}")
    k = n_elements // 6
    return ([Disc(2 * k, 32.59, 0.17809, 0.32956), Disc(4 * k, 25.0, 0.12, 0.2)],
            [Bearing(0, 1e6, 8e5, 2e5, -1e5, 300.0, 200.0),
             Bearing(n_elements, 1.5e6, 7e5, c_yy=150.0, c_zz=250.0)])


def flexible_rotor(n_elements: int = 24, n_modes: int = 16, omega: float = 500.0) -> System:
    """The rotor as an elastic body of the method spinning by ``Omega*t`` (parameter
    ``Omega``, default ``omega``): ``examples/flexible_rotor.toml``."""
    discs, bearings = rotor_parts(n_elements)
    body = ElasticBody.rotor("shaft", "world", Fixed("frame"), rotor_shaft(n_elements),
                             n_modes, spin=se.Symbol("Omega") * t, discs=discs,
                             bearings=bearings)
    return System([], [body], [], parameters={"Omega": omega}, name="flexible rotor")


def flexible_rotor_fe(n_elements: int = 24) -> Rotor:
    """The same rotor as a finite-element rotor (:func:`jourdain.elastic.rotor.rotor`:
    consistent masses, the form ROSS uses)."""
    discs, bearings = rotor_parts(n_elements)
    return rotor(rotor_shaft(n_elements), discs, bearings)
