"""The stages of Schiehlen's method (``docs/method.md``), each a module or package named after
its step:

kinematics (§1: r, S, ω, J_T, J_R, v̄, ω̄, ā, ᾱ) → newton_euler (§2: M̄, J̄, q̄^c, q̄^e) →
projection (§3: M, k, q) → reactions (§4: Q̄, N̂, k̂, q̂) → linearization (§5–6: M̃, P, Q, h, B;
D, G, K, N).

Each takes the results of the stages before it and returns a frozen dataclass with the method's
symbols as field names; this package re-exports nothing, so ``jourdain.stages.projection`` is the
module (the functions are at ``jourdain.projection`` etc.). Floor: above the model and the
expression graph (:mod:`jourdain.graph`), below the numeric layer; the numbers of the symbolic
linearization are in :mod:`jourdain.numeric.linearization` (``lin.evaluate``, ``lin.compile``),
those of reactions and of the numeric linearization in :mod:`jourdain.analysis`
(``reactions``, ``numeric_linearization``).
"""
