"""Closed kinematic loops in independent coordinates, in numbers.

A closed :class:`jourdain.System` is a spanning tree (its coordinates, named ``z`` in this
package, n of them) cut open at its closing joints, whose m independent scalar constraints
``Φ(z, t) = 0`` (:mod:`jourdain.stages.constraints`) tie the tree's coordinates together. The
method stays the seed's (METHOD.md §1–3) with one more kinematic stage:

* **Coordinate partitioning.** ``z = (y, d)``: f = n − m independent coordinates y and m
  dependent ones d, chosen by QR with column pivoting on ``Φ_z`` at the initial
  configuration (the best-conditioned ``Φ_d``) or by the user (:func:`partition`).
* **Kinematics on the manifold.** With ``Φ_z = [Φ_y Φ_d]``, ``ż = J_z·ẏ + ż_r`` where the
  dependent rows of ``J_z`` are ``−Φ_d⁻¹Φ_y`` and ``ż_r,d = −Φ_d⁻¹Φ_t`` (the implicit function
  theorem, kept as a linear solve with ``Φ_d``, never a symbolic inverse), and
  ``z̈ = J_z·ÿ + γ`` with ``γ_d = −Φ_d⁻¹·c``, ``c = Φ̈`` at ``z̈ = 0`` (the convective term
  ``(Φ_z ż)_z ż + 2 Φ_zt ż + Φ_tt``, generated symbolically and compiled).
* **Projection.** The tree's Jacobian ``J̄_tree`` becomes ``J̄ = J̄_tree·J_z`` and the seed's
  projection gives, in the independent coordinates,
  ``M = J_zᵀ M_tree J_z``, ``k = J_zᵀ(k_tree + M_tree·γ)``, ``q = J_zᵀ q_tree``: the closing
  joints' constraint forces ``Φ_zᵀλ`` drop out because ``Φ_z·J_z = 0`` (the orthogonality
  relation of the closing joints, checked by :func:`evaluate`).
* **Reactions of the closing joints** (Lagrange multipliers) from the tree's equations
  ``M_tree·z̈ + k_tree − q_tree = Φ_zᵀ·λ`` with the z̈ of the projected equations
  (:meth:`LoopEvaluator.multipliers`).

The redundant-coordinate form, side by side: ``[M_tree Φ_zᵀ; Φ_z 0]·[z̈; −λ] = [q − k; −c]``
(index 1), :meth:`LoopEvaluator.redundant_accelerations`, optionally with Baumgarte's
stabilization. It needs no partition and so no singular ``Φ_d``, but its positions drift off
the manifold unless projected back; the independent form stays on the manifold by
construction (the dependent coordinates are solved by Newton at every evaluation). Where
Φ_z itself loses rank (a mechanism's flat or bifurcation positions) neither a partition nor
the bordered matrix can be solved; the augmented-Lagrangian form
(``system.simulate(..., formulation="penalty")``) passes there.
"""

from __future__ import annotations

from .evaluator import Assembly, LoopEvaluator, evaluate
from .partitioning import Partition, partition
from .system import (
    AssemblyError,
    Constraints,
    SingularConfiguration,
    constraint_function,
    constraints,
)

__all__ = ["Assembly", "AssemblyError", "Constraints", "LoopEvaluator", "Partition",
           "SingularConfiguration", "constraint_function", "constraints", "evaluate",
           "partition"]
