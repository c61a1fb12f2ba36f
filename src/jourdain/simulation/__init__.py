"""Simulation of the equations of motion (``docs/method.md`` §7): :mod:`.simulate` integrates
``M·ÿ + k = q`` (compiled step loops or SciPy), :mod:`.results` holds the motion. The
integration's parts: :mod:`.options` (methods, defaults, checks), :mod:`.problem` (events,
inputs, the C structure and library), :mod:`.template` (the problem and the results' constant
fields, memoized per system and options), :mod:`.runs` (one run of the loop or of SciPy).

This package re-exports nothing, so ``jourdain.simulation.simulate`` is the module (the
function is ``jourdain.simulate``).
"""
