"""Sums that hold all the terms of smaller sums, in a hash-consed graph (:class:`Merged`).

The equations of a tree of bodies hold sums over the bodies below each joint, and the code
generator (:mod:`jourdain.numeric.ccode`) forms each larger one from the largest smaller one
(:func:`shared_sums`).
"""

from __future__ import annotations

from .nodes import Merged, atom_key

#: the work of :func:`shared_sums` (terms looked up), beyond which the remaining sums are
#: formed term by term: it bounds the time spent on graphs with very many sums
SHARE_BUDGET = 2_000_000


def term_keys(g: Merged, i: int) -> list[int | tuple[str, str]]:
    """The terms of node ``i`` as keys: class ids of nodes, :func:`atom_key` of atoms."""
    return [atom_key(x) if c is None else c
            for c, x in zip(g.arg_ids[i], g.args[i], strict=True)]


def shared_sums(g: Merged, budget: int | None = None) -> dict[int, int]:
    """For each sum of three or more terms in ``g``, the largest other sum whose terms are all
    among its terms (ties: the first in the graph's order), where there is one.

    The equations of a tree of bodies hold sums over the bodies below each joint: a chain's
    k_i sums n − i terms, and the code formed term by term adds O(n²) times where O(n) do
    (:data:`jourdain.numeric.ccode.SHARE_SUMS`; the n-link pendulum on a cart's M, k, q: at
    n = 12 486 → 200 additions and subtractions, 151 → 142 ns per state; at n = 18 1 107 →
    410, 310 → 283 ns). The terms of the smaller sum are then added first, and the result
    differs from the term-by-term sum in the last bits. Sums are examined smallest first,
    candidates found through an index from each term to the sums holding it; the lookups stop at
    ``budget`` (:data:`SHARE_BUDGET`), so the result is the same on every run and machine.
    """
    budget = SHARE_BUDGET if budget is None else budget
    terms: dict[int, frozenset[int | tuple[str, str]]] = {}
    holding: dict[int | tuple[str, str], list[int]] = {}
    for i in g.order:
        if type(g.node[i]).__name__ == "Add":
            ks = frozenset(term_keys(g, i))
            terms[i] = ks
            for k in ks:
                holding.setdefault(k, []).append(i)
    best: dict[int, int] = {}
    work = 0
    for a in sorted((i for i in terms if len(terms[i]) >= 3), key=lambda i: (len(terms[i]), i)):
        ta = terms[a]
        n = len(ta)
        found: dict[int, int] = {}
        for k in ta:
            sums = holding[k]
            work += len(sums)
            for b in sums:
                if len(terms[b]) < n:
                    found[b] = found.get(b, 0) + 1
        if work > budget:
            break
        fits = [b for b, m in found.items() if m == len(terms[b])]
        if fits:
            best[a] = max(fits, key=lambda b: (len(terms[b]), -b))
    return best
