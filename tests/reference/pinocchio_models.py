"""Pinocchio models for the reference tests (skipped where Pinocchio is not installed)."""

import pytest

pin = pytest.importorskip("pinocchio")

from benchmarks.pinocchio_models import chain_model  # noqa: E402

#: the Pinocchio model of jourdain.models.spatial_chain(n) from spatial_chain_data(n)
spatial_chain_model = chain_model

__all__ = ["chain_model", "pin", "spatial_chain_model"]
