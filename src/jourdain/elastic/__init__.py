"""Elastic bodies' modal data (issue 36, item 2): beam finite elements, import of any FE
model's M and K, boundary conditions and reduction (modal truncation, Craig–Bampton, free modes
with static correction), the floating-frame invariants (m, m·c, J, C_t, C_r, M_e, K_e) and a
documented subset of the SID file format. Numbers only (NumPy, SciPy); the multibody
integration builds on :class:`ModalData`: :class:`ElasticBody` puts such a body into the
method (its nodes' masses on the floating frame, geometric stiffening by the foreshortening).
Guide: docs/elastic.md.
"""

from jourdain.elastic.beam import DOF_NAMES, Beam, FEModel, assemble, element_matrices
from jourdain.elastic.body import ElasticBody
from jourdain.elastic.femodel import fe_model
from jourdain.elastic.modal import ModalData, modal_data
from jourdain.elastic.quadrature import MassPoints, gauss_points, lumped_masses
from jourdain.elastic.reduction import (
    constrain,
    craig_bampton,
    free_modes,
    modal_truncation,
    normal_modes,
)
from jourdain.elastic.sid import read_sid, sid_data, sid_text, write_sid

__all__ = ["ElasticBody", "lumped_masses", "MassPoints", "gauss_points", "DOF_NAMES", "Beam",
           "FEModel", "assemble", "element_matrices", "ModalData", "modal_data", "constrain",
           "craig_bampton", "free_modes", "modal_truncation", "normal_modes", "fe_model",
           "read_sid", "write_sid", "sid_text", "sid_data"]
