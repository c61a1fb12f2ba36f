"""Import of FE models' M and K (jourdain.elastic.femodel) and the SID subset
(jourdain.elastic.sid): checks with errors naming what is wrong, MatrixMarket files, SID
written and read back to the same numbers, malformed files naming the line."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
import scipy.io
import scipy.sparse as sp

from jourdain.elastic import (
    Beam,
    assemble,
    craig_bampton,
    fe_model,
    modal_truncation,
    read_sid,
    sid_data,
    sid_text,
    write_sid,
)
from jourdain.elastic.sid import _taylor
from jourdain.errors import ModelError

BEAM = Beam(length=1.0, E=2.1e11, rho=7850.0, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, nu=0.3,
            kappa=0.85, n_elements=6)


def test_imported_matrices_reduce_like_the_beam(tmp_path: Path) -> None:
    """The beam's M and K given as arrays, as sparse matrices and as MatrixMarket files: the
    same modal data as the beam itself."""
    fe = assemble(BEAM)
    ref = craig_bampton(fe, [6], 4, fixed=[0])
    scipy.io.mmwrite(tmp_path / "M.mtx", sp.csr_matrix(fe.M), precision=17)
    scipy.io.mmwrite(tmp_path / "K.mtx", sp.csr_matrix(fe.K), precision=17)
    for M, K in ((fe.M, fe.K), (sp.csr_matrix(fe.M), sp.csr_matrix(fe.K)),
                 (tmp_path / "M.mtx", str(tmp_path / "K.mtx"))):
        imp = fe_model(M, K, fe.nodes, dofs_per_node=("ux", "uy", "uz", "rx", "ry", "rz"))
        assert imp.dofs == fe.dofs
        md = craig_bampton(imp, [6], 4, fixed=[0])
        np.testing.assert_allclose(md.omega, ref.omega, rtol=1e-9)
        np.testing.assert_allclose(md.J, ref.J, rtol=1e-12)
        np.testing.assert_allclose(md.C_t, ref.C_t, rtol=1e-8, atol=1e-10 * np.abs(ref.C_t).max())


def test_solid_like_model_with_translations_only() -> None:
    """Three point masses on springs (translations only, an explicit DOF map in any order)."""
    nodes = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    dofs = [(2, "ux"), (1, "ux"), (0, "ux")]
    k = 1e4
    K = k * np.array([[1.0, -1, 0], [-1, 2, -1], [0, -1, 1]])
    M = np.diag([1.0, 2.0, 3.0])
    imp = fe_model(M, K, nodes, dofs=dofs)
    md = modal_truncation(imp, 3)
    assert md.omega[0] < 1e-6 * md.omega[1]
    np.testing.assert_allclose(md.mass, 6.0, rtol=1e-15)  # from the x direction, the only one
    assert md.Phi_r.shape == (3, 3, 3) and not md.Phi_r.any()


@pytest.mark.parametrize(("change", "match"), [
    ("asym", r"K: not symmetric: \|A\[0,1\]"),
    ("nan", r"M: entry \(2, 2\) is not finite"),
    ("size", r"K: shape \(11, 11\), expected \(12, 12\)"),
    ("indefinite", "K: not positive semi-definite"),
    ("singular_m", "M: not positive definite"),
    ("dofname", r"DOF map row 3: name 'tx'"),
    ("dofnode", "DOF map row 0: node 7 is not among the 2 nodes"),
    ("duplicate", r"DOF map rows 0 and 1: \(0, 'ux'\) is listed twice"),
    ("rows", "DOF map has 11 rows, the matrices 12"),
    ("nodes", r"nodes must be a finite \(n, 3\) array"),
])
def test_bad_models_are_refused_with_the_reason(change: str, match: str) -> None:
    b = Beam(length=1.0, E=2.1e11, rho=7850.0, A=1e-3, I_y=2e-7, I_z=1e-7, J=2.5e-7, nu=0.3,
             n_elements=1)
    fe = assemble(b)
    M, K, nodes = fe.dense("M"), fe.dense("K"), fe.nodes.copy()
    dofs = list(fe.dofs)
    if change == "asym":
        K[0, 1] += 1e-3 * np.abs(K).max()
    elif change == "nan":
        M[2, 2] = np.nan
    elif change == "size":
        K = K[:11, :11]
    elif change == "indefinite":
        K[0, 0] = -np.abs(K).max()
    elif change == "singular_m":
        M[:, 3] = M[3, :] = 0.0
    elif change == "dofname":
        dofs[3] = (0, "tx")
    elif change == "dofnode":
        dofs[0] = (7, "ux")
    elif change == "duplicate":
        dofs[1] = (0, "ux")
    elif change == "rows":
        dofs = dofs[:11]
    elif change == "nodes":
        nodes = nodes[:, :2]
    with pytest.raises(ModelError, match=match):
        fe_model(M, K, nodes, dofs=dofs, name="model")


def test_unreadable_matrix_file(tmp_path: Path) -> None:
    bad = tmp_path / "K.mtx"
    bad.write_text("not a matrix market file\n")
    with pytest.raises(ModelError, match="cannot read MatrixMarket file"):
        fe_model(np.eye(6), bad, np.zeros((1, 3)), dofs_per_node=("ux", "uy", "uz", "rx", "ry",
                                                                    "rz"))


# ---------------------------------------------------------------- SID


def test_sid_round_trip_is_exact(tmp_path: Path) -> None:
    md = craig_bampton(assemble(BEAM), [6, 3], 4, fixed=[0])
    write_sid(md, tmp_path / "beam.sid")
    back = read_sid(tmp_path / "beam.sid")
    for name in ("nodes", "Phi", "M_e", "K_e", "D_e", "J", "mc", "C_t", "C_r", "omega"):
        np.testing.assert_array_equal(getattr(back, name), getattr(md, name), err_msg=name)
    assert back.mass == md.mass and back.kinds == md.kinds and back.dofs == md.dofs
    assert back.method == "SID"


def test_sid_reads_the_order_0_part_of_first_order_taylor_objects() -> None:
    """Other tools write origin, J, mdCM with their first-order terms (m1): read m0."""
    md = modal_truncation(assemble(BEAM), 2, fixed=[0])
    text = sid_text(md)
    start = text.index("   J\n")
    stop = text.index("   end J\n")
    block = text[start:stop].replace("order = 0", "order = 1", 1)
    block += "      m1\n         m1(  1,  1,  2) = 0.5\n      end m1\n"
    back = sid_data(text[:start] + block + text[stop:])
    np.testing.assert_array_equal(back.J, md.J)
    assert "sid first-order terms skipped: J" in back.meta


def test_sid_skips_blocks_outside_the_subset_and_reads_transposed_ct() -> None:
    md = modal_truncation(assemble(BEAM), 4, fixed=[0])
    text = sid_text(md)
    extra = "   Gr\n      order = 0\n      nrow = 3\n      ncol = 12\n   end Gr\nend part\n"
    back = sid_data(text.replace("end part\n", extra))
    assert "sid skipped: Gr" in back.meta
    # Ct written as n_q × 3 by another tool
    start, stop = text.index("   Ct\n"), text.index("   end Ct\n") + len("   end Ct\n")
    transposed = "\n".join(_taylor("Ct", md.C_t.T, md.n_q, "   ")) + "\n"
    back = sid_data(text[:start] + transposed + text[stop:])
    np.testing.assert_array_equal(back.C_t, md.C_t)


@pytest.mark.parametrize(("edit", "match"), [
    (lambda t: t.replace("   end J\n", "   end Jx\n", 1), r"line \d+: 'end Jx' closes no open"),
    (lambda t: t.replace("mass = ", "mass = __import__('os').system('x') #", 1),
     r"line 5: mass = \"__import__\('os'\).system\('x'\)\" is not a number|line 5"),
    (lambda t: t.replace("nelastq = 10", "nelastq = ten", 1), r"line 6: nelastq = 'ten'"),
    (lambda t: t.replace("end part\n", ""), r"block 'part' opened on line 2 is not closed"),
    (lambda t: t.replace("      end m0\n", "      m0(  1,  1,  1) = 1.0\n      end m0\n", 1),
     "m0 entries have 2 indices"),
    (lambda t: t.replace("      end m0\n", "      end m0\n      m1(  1,  1) = 1.0\n", 1),
     r"m1 entry outside an m1 block \(in 'origin'\)"),
    (lambda t: t.replace("order = 0", "order = 2", 1), "origin of order 2: 0 or 1 read"),
    (lambda t: t.replace("   Me\n", "   Mx\n   end Mx\n   Me2\n", 1), r"line \d+: 'end Me'"),
    (lambda t: t.replace("m0(  1,  1) = ", "m0(  1,  1) = 1.0.0 # ", 1), "not a number: '1.0.0'"),
    (lambda t: t.replace("      nrow = 10\n", "      nrow = 9\n", 1),
     r"entry \(10, \d+\) of \w+ outside 9 × 10"),
    (lambda t: t + "???\n", r"line \d+: cannot read '\?\?\?'"),
])
def test_malformed_sid_names_the_line(edit, match: str) -> None:  # type: ignore[no-untyped-def]
    md = craig_bampton(assemble(BEAM), [6], 4, fixed=[0])
    text = sid_text(md)
    with pytest.raises(ModelError, match=match):
        sid_data(edit(text), "beam.sid")


@pytest.mark.parametrize("case", ["good", "indefinite_k", "singular_m"])
def test_definiteness_by_inertia_on_large_models(case: str, monkeypatch) -> None:  # type: ignore[no-untyped-def]
    """Beyond DENSE_LIMIT DOFs the signs of a symmetric factorization's pivots decide
    (Sylvester's inertia): the same verdicts as the dense eigenvalues."""
    import jourdain.elastic.femodel as femodel

    monkeypatch.setattr(femodel, "DENSE_LIMIT", 10)
    fe = assemble(BEAM, sparse=True)
    M, K = fe.M.tolil(), fe.K.tolil()
    if case == "indefinite_k":
        K[9, 9] = -1e-6 * abs(fe.K).max()
    elif case == "singular_m":
        M[:, 3] = 0.0
        M[3, :] = 0.0
    args = (M.tocsr(), K.tocsr(), fe.nodes)
    if case == "good":
        assert fe_model(*args, dofs=fe.dofs).n == fe.n
        return
    what = "K: not positive semi-definite" if case == "indefinite_k" else \
        "M: not positive definite"
    with pytest.raises(ModelError, match=f"{what} \\(1 pivot"):
        fe_model(*args, dofs=fe.dofs)
