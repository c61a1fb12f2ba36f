"""The stages of Schiehlen's method (``docs/method.md``), each a module named after its step:

kinematics (§2) → newton_euler (§3) → projection (§4) → reactions (§4) → linearization (§5).

Each module takes the results of the stages before it and returns a frozen dataclass with the
method's symbols as field names; this package re-exports nothing, so ``jourdain.stages.projection``
is the module (the functions are at ``jourdain.projection`` etc.).
"""
