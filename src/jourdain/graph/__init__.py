"""Shared expression graphs: one node store for CSE, differentiation and code generation.

The stages build M, k, q, N̂, ... as SymEngine expressions that share sub-expressions (a DAG).
This package reads such expressions once into a :class:`Graph` (:mod:`.nodes`: the distinct
nodes by address, children before parents, with a hash-consed view :meth:`Graph.merged` in which
equal sub-expressions built separately are one node) and walks it:

* :mod:`.elimination`: common-subexpression elimination (:func:`cse`) and operation counts, on
  the merged view; the C code generator (:mod:`jourdain.numeric.ccode`) walks the same view;
* :mod:`.forward`: first derivatives at a point, symbolically (:func:`jet`);
* :mod:`.numbers`: numbers and first derivatives in floating point (:func:`evaluate_float`,
  :func:`jet_float`), and numbers at many states at once (:func:`evaluate_arrays`);
* :mod:`.identity`: which SymEngine wrappers hold the same node;
* :mod:`.sums`: sums that hold all the terms of smaller ones (:func:`shared_sums`), which the
  code generator forms from them.

Floor: model → **graph tools** → stages → numeric. The package imports nothing of jourdain but
:mod:`jourdain.errors`; the stages, the numeric layer, the analyses and the export build on it.
"""

from .elimination import CSE, count_graph, count_nodes, cse, graph_ops, node_ops, tree_ops
from .forward import Jet, as_basic, jet
from .nodes import Graph, Merged, atom_key
from .numbers import (
    FloatJet,
    evaluate_arrays,
    evaluate_float,
    evaluate_float_many,
    free_symbol_names,
    jet_float,
)
from .sums import shared_sums, term_keys

__all__ = [
    "CSE", "FloatJet", "Graph", "Jet", "Merged", "as_basic", "atom_key", "count_graph", "count_nodes", "cse",
    "evaluate_arrays", "evaluate_float", "evaluate_float_many", "free_symbol_names",
    "graph_ops", "jet", "jet_float", "node_ops",
    "shared_sums", "term_keys", "tree_ops",
]
