"""An elastic body in the method: the floating frame of reference with nodal masses.

A material point of the body is at ``R = r + S·(c + u(c, q_e))``: ``r``, ``S`` are the body's
reference frame, moved by its joint like any rigid body's frame, and ``u`` the elastic
displacement from the elastic coordinates ``q_e`` (issue 36; Schwertassek & Wallrapp 1999).
Here the body's mass sits at its nodes (lumped masses ``m_n``, point masses), each at

    R_n = r + S·(c_n + Φ_t,n·q_e + ½·q_eᵀ·Ψ_n·q_e),

with the modes' nodal translations ``Φ_t,n`` and, for beams, the foreshortening ``Ψ_n`` that
carries the geometric stiffening (:mod:`jourdain.elastic.stiffening`). The body is expanded
into the method's own bodies (:class:`jourdain.model.bodies.BodyGroup`):

- ``<name>``: its reference frame (massless), hanging from the parent by the given joint;
- ``<name>_n<k>``: one point mass per node with mass, on a General joint whose translation is
  the node's position above (so every node's Jacobian columns carry the elastic coordinates);
- ``<name>_<label>``: a massless frame at each node named in ``attach``, translated as the node
  and turned by its small rotation ``θ_n = Φ_r,n·q_e`` (three elementary rotations), from which
  joints and force elements of the rest of the model hang;
- ``<name>_q<k>``: a massless carrier per elastic coordinate, displaced along the frame's x
  axis by ``q_k``, on which the elastic forces ``−K_e·q_e − D_e·q̇_e`` act as generalized
  forces (a force pair across the carrier's joint; J̄ᵀ projects it onto ``q_k`` alone).

So M̄, J̄, q̄^c, q̄^e hold the body's nodes as rows; ``M = J̄ᵀ·M̄·J̄`` is the exact mass matrix of
the discretized body (all orders in q_e, so energy is conserved exactly where the model is
conservative), and every stage (reactions, linearization, simulation, FMU, reports) takes the
body as it takes rigid ones. The invariants of the SID (m, m·c, J, C_t, C_r, M_e, ...) are the
sums over these nodes (:func:`jourdain.elastic.modal.modal_data` of the lumped mass gives them;
``tests/test_elastic_body.py`` checks that the projected M at q_e = 0 equals them). Nodes may
carry sections (rotary inertia, spinning with a rotor). With ``mass="consistent"`` (beams and
rotors) the distributed mass sits instead at the elements' Gauss points, ``<name>_g<k>``, moved
by the interpolated field: the consistent FE mass and its invariants exactly
(:mod:`jourdain.elastic.quadrature`). A body costs in proportion to its nodes or points, which
the invariant form's cost (∝ n_q²) would not.
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping, Sequence
from dataclasses import dataclass, replace

import numpy as np
import symengine as se

from jourdain.elastic.beam import Beam, FEModel, assemble, frame_of_axis
from jourdain.elastic.modal import ModalData
from jourdain.elastic.quadrature import MassPoints, gauss_points, lumped_masses, mass_kind
from jourdain.elastic.reduction import clamped_basis, modal_damping, modal_truncation
from jourdain.elastic.rotor import Bearing, Disc, rotor
from jourdain.elastic.stiffening import foreshortening
from jourdain.errors import ModelError
from jourdain.model.bodies import Body, BodyGroup
from jourdain.model.expressions import as_expr
from jourdain.model.forces import GeneralizedForce
from jourdain.model.joints import General, Joint, Rot, Trans

__all__ = ["ElasticBody", "lumped_masses"]

_ZERO = se.Integer(0)


def _num(x: float) -> se.Basic:
    return _ZERO if x == 0.0 else se.RealDouble(float(x))


def _linear(coefs: np.ndarray, q: Sequence[se.Symbol], const: float = 0.0,
            quad: np.ndarray | None = None) -> se.Basic:
    """const + Σ coefs_k·q_k (+ ½ Σ_jk quad_jk·q_j·q_k), zero coefficients left out."""
    terms: list[se.Basic] = [] if const == 0.0 else [_num(const)]
    terms += [_num(c) * qk for c, qk in zip(coefs, q, strict=True) if c != 0.0]
    if quad is not None:
        for j in range(len(q)):
            for k in range(j, len(q)):
                c = quad[j, k] * (0.5 if j == k else 1.0)
                if c != 0.0:
                    terms.append(_num(c) * q[j] * q[k])
    return se.Add(*terms) if terms else _ZERO


@dataclass(frozen=True, eq=False)
class ElasticBody(BodyGroup):
    """An elastic body (module docstring) hanging from ``parent`` by ``joint``.

    ``modal`` gives the nodes, the modes' nodal translations and rotations (``Phi_t``,
    ``Phi_r``), K_e and D_e; ``node_mass`` (one per node) the lumped masses; ``Psi``
    (n_nodes, 3, n_q, n_q) the second-order field (geometric stiffening) or None;
    ``attach`` maps labels to node indices for the frames ``<name>_<label>``. Build one from a
    beam with :meth:`beam`.
    """

    name: str
    parent: str
    joint: Joint
    modal: ModalData
    node_mass: np.ndarray
    Psi: np.ndarray | None = None
    attach: tuple[tuple[str, int], ...] = ()
    node_inertia: np.ndarray | None = None
    spin: tuple[tuple[float, float, float], se.Basic] | None = None
    points: MassPoints | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ModelError(f"elastic body name {self.name!r} must be an identifier")
        n = len(self.modal.nodes)
        m = np.asarray(self.node_mass, dtype=float)
        if self.points is not None:
            self.points.check(f'elastic body "{self.name}"', self.n_q)
        distributed = 0.0 if self.points is None else float(np.sum(self.points.mass))
        if (m.shape != (n,) or not np.all(np.isfinite(m)) or np.any(m < 0)
                or not m.sum() + distributed > 0):
            raise ModelError(f'elastic body "{self.name}": node_mass must be {n} finite '
                             "non-negative masses, not all zero (without mass points)")
        for label, node in self.attach:
            if not (isinstance(label, str) and label.isidentifier()):
                raise ModelError(f'elastic body "{self.name}": attachment label {label!r} must '
                                 "be an identifier")
            if not 0 <= int(node) < n:
                raise ModelError(f'elastic body "{self.name}": attachment "{label}" at node '
                                 f"{node}, but the body has nodes 0 … {n - 1}")
        sections: list[tuple[str, np.ndarray]] = []
        if self.node_inertia is not None:
            I_n = np.asarray(self.node_inertia, dtype=float)
            if I_n.shape != (n, 3, 3) or not np.all(np.isfinite(I_n)):
                raise ModelError(f'elastic body "{self.name}": node_inertia must be {n} finite '
                                 "3×3 tensors")
            sections += [(f"node {k}", Ik) for k, Ik in enumerate(I_n)]
        if self.points is not None:
            sections += [(f"mass point {k}", np.asarray(Ik, dtype=float))
                         for k, Ik in enumerate(self.points.inertia)]
        if self.spin is not None:
            a = np.asarray(self.spin[0], dtype=float)
            a = a / np.linalg.norm(a)
            P = np.eye(3) - np.outer(a, a)
            for what, Ik in sections:  # axisymmetric about the spin axis
                scale = max(float(np.abs(Ik).max()), 1e-300)
                side = P @ Ik @ P
                iso = np.trace(side) / 2 * P
                if (np.abs(Ik @ a - (a @ Ik @ a) * a).max() > 1e-12 * scale
                        or np.abs(side - iso).max() > 1e-12 * scale):
                    raise ModelError(f'elastic body "{self.name}": {what}\'s inertia is not '
                                     "axisymmetric about the spin axis")
        if self.Psi is not None and np.shape(self.Psi) != (n, 3, self.n_q, self.n_q):
            raise ModelError(f'elastic body "{self.name}": Psi of shape {np.shape(self.Psi)}, '
                             f"expected {(n, 3, self.n_q, self.n_q)}")

    # value semantics (arrays compared by content, never by identity)
    def _key(self) -> tuple:
        arrays = (self.modal.nodes, self.modal.Phi, self.modal.K_e, self.modal.D_e,
                  self.node_mass, self.Psi if self.Psi is not None else np.zeros(0),
                  self.node_inertia if self.node_inertia is not None else np.zeros(0),
                  *(self.points.arrays() if self.points is not None else ()))
        return (self.name, self.parent, self.joint, self.attach, self.spin, self.points is None,
                tuple(np.ascontiguousarray(a, dtype=float).tobytes() for a in arrays))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, ElasticBody) and self._key() == other._key()

    def __hash__(self) -> int:
        return hash(self._key())

    @property
    def total_mass(self) -> float:
        """The body's mass: its nodes' and its mass points'."""
        return float(np.sum(self.node_mass) + (self.points.mass.sum() if self.points else 0.0))

    @property
    def elastic_mass(self) -> np.ndarray:
        """The body's own ``M_e``: Σ m·Φ_tᵀΦ_t + Φ_rᵀ·I·Φ_r over its nodes and mass points
        (the FE's Φᵀ·M·Φ for the consistent mass; the lumped masses' otherwise)."""
        md = self.modal
        sets = [(md.Phi_t, md.Phi_r, self.node_mass, self.node_inertia)]
        if self.points is not None:
            sets.append((self.points.Phi_t, self.points.Phi_r, self.points.mass,
                         self.points.inertia))
        out = np.zeros((self.n_q, self.n_q))
        for Pt, Pr, m, inertia in sets:
            out += np.einsum("n,nik,nil->kl", np.asarray(m, float), Pt, Pt)
            if inertia is not None:
                out += np.einsum("nik,nij,njl->kl", Pr, np.asarray(inertia, float), Pr)
        return 0.5 * (out + out.T)

    def damped(self, zeta: float) -> ElasticBody:
        """This body with every mode of its own (``K_e``, :attr:`elastic_mass`) damped by the
        ratio ``zeta`` (:func:`jourdain.elastic.reduction.modal_damping`; itself for 0)."""
        if not zeta:
            return self
        return replace(self, modal=modal_damping(self.modal, float(zeta), self.elastic_mass))

    @property
    def n_q(self) -> int:
        return self.modal.n_q

    @property
    def coordinates(self) -> tuple[se.Symbol, ...]:
        return tuple(se.Symbol(f"{self.name}_q{k + 1}") for k in range(self.n_q))

    def node_position(self, node: int) -> tuple[se.Basic, se.Basic, se.Basic]:
        """The node's position in the body frame as expressions of q_e."""
        return self._position(self.modal.nodes[node], self.modal.Phi_t[node],
                              None if self.Psi is None else self.Psi[node])

    def _position(self, c: np.ndarray, Pt: np.ndarray, quad: np.ndarray | None
                  ) -> tuple[se.Basic, se.Basic, se.Basic]:
        """``c + Pt·q_e + ½·q_eᵀ·quad·q_e`` (body frame) as expressions."""
        q = self.coordinates
        return tuple(_linear(Pt[i], q, float(c[i]), None if quad is None else quad[i])
                     for i in range(3))

    def expand(self) -> tuple[tuple[se.Symbol, ...], tuple[Body, ...], tuple[object, ...]]:
        """(coordinates, bodies, force elements), formed once per body (the expressions of
        every node: System expands the body, and each System.evaluate asks for its inner
        joints, :meth:`internal_joints`)."""
        parts = self.__dict__.get("_parts")
        if parts is None:
            parts = self._expand()
            object.__setattr__(self, "_parts", parts)
        return parts

    def _expand(self) -> tuple[tuple[se.Symbol, ...], tuple[Body, ...], tuple[object, ...]]:
        q = self.coordinates
        qd = [se.Symbol(f"{s}_d") for s in q]
        none = (0, 0, 0)
        bodies = [Body(self.name, self.parent, self.joint, mass=0, inertia=none)]
        for k, qk in enumerate(q):
            bodies.append(Body(f"{self.name}_q{k + 1}", self.name,
                               General(f"{self.name}_mode{k + 1}", [Trans("x", qk)],
                                       coordinates=[qk]), mass=0, inertia=none))
        inertia = self.node_inertia
        md = self.modal
        for node, m in enumerate(np.asarray(self.node_mass, dtype=float)):
            I_n = None if inertia is None or not np.any(inertia[node]) else inertia[node]
            quad = None if self.Psi is None else self.Psi[node]
            bodies += self._carrier(f"n{node}", f"node{node}", md.nodes[node], md.Phi_t[node],
                                    md.Phi_r[node], quad, float(m), I_n)
        pts = self.points
        for k in range(0 if pts is None else len(pts.mass)):
            assert pts is not None
            I_p = pts.inertia[k] if np.any(pts.inertia[k]) else None
            quad = None if pts.Psi is None else pts.Psi[k]
            bodies += self._carrier(f"g{k}", f"point{k}", pts.c[k], pts.Phi_t[k], pts.Phi_r[k],
                                    quad, float(pts.mass[k]), I_p, section=True)
        for label, node in self.attach:
            frame: list[Rot | Trans] = [Trans(vector=self.node_position(node))]
            frame += self._rotations(self.modal.Phi_r[node])
            bodies.append(Body(f"{self.name}_{label}", self.name,
                               General(f"{self.name}_{label}_node", frame), mass=0,
                               inertia=none))
        K, D = self.modal.K_e, self.modal.D_e
        forces = [GeneralizedForce(f"{self.name}_elastic{k + 1}", qk,
                                   -_linear(K[k], q) - _linear(D[k], qd))
                  for k, qk in enumerate(q)]
        return q, tuple(bodies), tuple(forces)

    def _carrier(self, body: str, joint: str, c: np.ndarray, Pt: np.ndarray, Pr: np.ndarray,
                 quad: np.ndarray | None, m: float, I_n: np.ndarray | None,
                 section: bool = False) -> list[Body]:
        """The body ``<name>_<body>`` of a node or mass point at ``c + Pt·q + ½qᵀ·quad·q``
        with mass ``m`` and, where ``I_n`` is given, a section turned by ``Pr·q`` (and spun)."""
        if not (m > 0 or I_n is not None):
            return []
        steps: list[Rot | Trans] = [Trans(vector=self._position(c, Pt, quad))]
        if I_n is not None:  # the section turns with the node (and spins)
            steps += self._rotations(Pr)
            if self.spin is not None:
                steps.append(Rot(self.spin[0], self.spin[1]))
        return [Body(f"{self.name}_{body}", self.name, General(f"{self.name}_{joint}", steps),
                     mass=_num(m), inertia=(0, 0, 0) if I_n is None else
                     [[_num(float(x)) for x in row] for row in I_n], section=section)]

    def internal_joints(self) -> tuple[str, ...]:
        _, bodies, _ = self.expand()
        return tuple(b.joint.name for b in bodies if b.name != self.name)

    def _rotations(self, Pr: np.ndarray) -> list[Rot | Trans]:
        """The small rotation θ = Pr·q_e of a node or point as elementary rotations about x,
        y, z."""
        q = self.coordinates
        theta = [_linear(Pr[i], q) for i in range(3)]
        return [Rot(axis, th) for axis, th in zip("xyz", theta, strict=True) if th != 0]

    @classmethod
    def from_fe(cls, name: str, parent: str, joint: Joint, fe: FEModel, n_modes: int, *,
                clamped: Iterable[int | tuple[int, str]] = (0,),
                attach: Mapping[str, int] | None = None,
                damping_ratio: float = 0.0, reduction: str = "normal") -> ElasticBody:
        """An elastic body from any finite-element model (:func:`jourdain.elastic.fe_model`:
        M and K as arrays, SciPy sparse matrices or MatrixMarket files, with node
        coordinates): its ``n_modes`` lowest normal modes with the ``clamped`` nodes (or
        ``(node, dof)`` pairs) held by the frame, the mass lumped at the nodes by HRZ
        (:func:`lumped_masses`); ``reduction="craig_bampton"`` as for :meth:`beam`. No
        geometric stiffening (it needs a beam's axis)."""
        clamped = list(clamped)
        nodes = [c[0] if isinstance(c, tuple) else c for c in clamped]
        modal = clamped_basis(name, fe, n_modes, nodes, clamped, reduction,
                              [int(v) for v in (attach or {}).values()])
        return cls(name, parent, joint, modal, lumped_masses(fe), None,
                   tuple((str(k), int(v)) for k, v in (attach or {}).items())
                   ).damped(damping_ratio)

    @classmethod
    def rotor(cls, name: str, parent: str, joint: Joint, shaft: Beam, n_modes: int, *,
              spin: object, discs: Sequence[Disc] = (), bearings: Sequence[Bearing] = (),
              attach: Mapping[str, int] | None = None, mass: str = "lumped") -> ElasticBody:
        """A flexible rotor: the ``shaft`` (along a body axis) with rigid ``discs`` and
        linear ``bearings`` (:mod:`jourdain.elastic.rotor`), its frame held by ``joint`` (not
        spinning), the shaft's material spinning by the angle ``spin`` (an expression such as
        ``Omega*t``). The basis: the ``n_modes`` lowest bending modes of the rotor on its
        bearings at rest (K_e, D_e with the bearings, cross-coupled terms kept). Each node
        carries its lumped mass (shaft ρA and discs) and a section that turns with the node's
        small rotation and spins: the lumped shaft inertia ρ·(I_p, I_y, I_z) per length and
        the discs' (I_p, I_d, I_d), so the gyroscopic terms come from the method itself.
        ``mass="consistent"``: the shaft's mass and sections at the elements' Gauss points
        instead (:mod:`jourdain.elastic.quadrature`: the FE rotor's M and G exactly)."""
        return _rotor_body(cls, name, parent, joint, shaft, discs, bearings, n_modes, spin,
                           attach, mass_kind(name, mass))

    @classmethod
    def beam(cls, name: str, parent: str, joint: Joint, beam: Beam, n_modes: int, *,
             clamped: Iterable[int] = (0,), keep: Sequence[str] | None = None,
             attach: Mapping[str, int] | None = None, stiffening: bool = True,
             damping_ratio: float = 0.0, mass: str = "lumped",
             reduction: str = "normal") -> ElasticBody:
        """A beam body: ``beam`` meshed (:func:`jourdain.elastic.beam.assemble`), its
        ``n_modes`` lowest normal modes with the nodes ``clamped`` held in the reference frame
        (the cantilever's modes for the default, node 0 at ``beam.origin``), node masses ρA
        per length lumped at the nodes (:func:`lumped_masses`), modal damping ``damping_ratio``
        (every mode of the body as built damped by ζ: :meth:`damped`), and the foreshortening
        of :mod:`~jourdain.elastic.stiffening` when ``stiffening``. ``keep`` (DOF names such as
        ``("uy", "rz")``) restricts the modes to those DOFs, every other one held at every
        node: a beam bending in one plane only.
        ``mass="consistent"`` puts the mass and the sections' rotary inertia at the elements'
        Gauss points (:mod:`jourdain.elastic.quadrature`): the FE beam's consistent mass,
        exactly, for four bodies per element instead of one per node.
        ``reduction="craig_bampton"``: the basis is Craig–Bampton's, constraint modes at the
        ``attach`` nodes (the DOFs kept there) and ``n_modes`` fixed-interface modes, so that
        static loads at the attachments are exact."""
        consistent = mass_kind(name, mass)
        fe = assemble(beam)
        clamped = [int(c) for c in clamped]
        fixed: list[int | tuple[int, str]] = list(clamped)
        if keep is not None:
            bad = sorted(set(keep) - {"ux", "uy", "uz", "rx", "ry", "rz"})
            if bad:
                raise ModelError(f'elastic body "{name}": unknown DOF names {bad} in keep')
            fixed += [d for d in fe.dofs if d[1] not in keep and d[0] not in clamped]
        modal = clamped_basis(name, fe, n_modes, clamped, fixed, reduction,
                              [int(v) for v in (attach or {}).values()])
        Psi = None
        if stiffening:
            R = frame_of_axis(beam.axis, beam.up)
            Psi = foreshortening(modal.nodes, R, modal.Phi_t, modal.Phi_r, clamped[0])
        labels = tuple((str(k), int(v)) for k, v in (attach or {}).items())
        if consistent:
            body = cls(name, parent, joint, modal, np.zeros(len(modal.nodes)), Psi, labels,
                       points=gauss_points(beam, modal, clamped[0] if stiffening else None))
        else:
            body = cls(name, parent, joint, modal, lumped_masses(fe), Psi, labels)
        return body.damped(damping_ratio)


def _rotor_body(cls: type[ElasticBody], name: str, parent: str, joint: Joint, shaft: Beam,
                discs: Sequence[Disc], bearings: Sequence[Bearing], n_modes: int, spin: object,
                attach: Mapping[str, int] | None, consistent: bool) -> ElasticBody:
    """:meth:`ElasticBody.rotor`."""
    r = rotor(shaft, discs, bearings)
    R = frame_of_axis(shaft.axis, shaft.up)
    k = int(np.argmax(np.abs(R[:, 0])))
    if not np.isclose(abs(R[k, 0]), 1.0, rtol=0, atol=1e-12):
        raise ModelError(f'elastic body "{name}": a rotor\'s shaft must lie along a body axis '
                         f"(x, y or z), got {shaft.axis}")
    keep = {f"u{a}" for a in "xyz" if a != "xyz"[k]} | {f"r{a}" for a in "xyz" if a != "xyz"[k]}
    fe = replace(r.fe, M=r.M, K=r.K, D=r.C, G=r.G)
    fixed = [d for d in fe.dofs if d[1] not in keep]
    # the Ritz basis: normal modes of the symmetric part at rest (bearings in K); K_e and D_e
    # keep the cross-coupled bearings' skew parts (modal_data would symmetrize them)
    sym = replace(fe, K=0.5 * (r.K + r.K.T), D=None, G=None)
    modal = modal_truncation(sym, n_modes, fixed=fixed)
    Phi = modal.Phi
    modal = replace(modal, K_e=Phi.T @ r.K @ Phi, D_e=Phi.T @ r.C @ Phi,
                    G_e=Phi.T @ r.G @ Phi)
    n = len(fe.nodes)
    mass = np.zeros(n) if consistent else lumped_masses(r.fe)
    inertia = np.zeros((n, 3, 3))
    share = np.zeros(n)
    le = shaft.length / int(shaft.n_elements)
    share[:-1] += le / 2
    share[1:] += le / 2
    Id = shaft.rho * np.array([shaft.polar, shaft.I_y if shaft.rotary_inertia else 0.0,
                               shaft.I_z if shaft.rotary_inertia else 0.0])
    for node in range(0 if consistent else n):
        inertia[node] = share[node] * (R @ np.diag(Id) @ R.T)
    for d in discs:
        mass[d.node] += d.m
        inertia[d.node] += R @ np.diag([d.Ip, d.Id, d.Id]) @ R.T
    axis = tuple(float(x) for x in R[:, 0])
    return cls(name, parent, joint, modal, mass, None,
               tuple((str(a), int(v)) for a, v in (attach or {}).items()),
               inertia, (axis, as_expr(spin, f'elastic body "{name}" spin')),  # type: ignore[arg-type]
               gauss_points(shaft, modal) if consistent else None)
