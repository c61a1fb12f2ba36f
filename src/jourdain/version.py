"""The version of jourdain (floor 0: every layer may read it; ``jourdain.__version__`` is this)."""

__version__ = "0.1.0"
