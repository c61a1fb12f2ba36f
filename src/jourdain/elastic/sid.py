"""A documented subset of the SID (Standard Input Data) format: write and read :class:`ModalData`.

The SID (Wallrapp 1994; Schwertassek & Wallrapp 1999, §6; the ``.SID_FEM`` text files of FEMBS
and the tools that read them) holds a flexible body's reduced data as *Taylor objects*
``A(q) = A⁰ + Σ_k A¹_k·q_k`` in nested blocks. jourdain writes and reads this subset, in this
layout (indentation free, one item per line, ``#`` or ``!`` starts a comment)::

    part
       new modal
       refmod
          mass = <m>
          nelastq = <n_q>
          ielastq(  1) = <kind of coordinate 1>      (one line per coordinate)
       end refmod
       frame
          new node = <k>                             (1-based, one per FE node)
             rframe = body
             origin                                  (node position c_k, 3 × 1)
                <Taylor object>
             end origin
             phi  <Taylor object, 3 × n_q>  end phi  (translational mode shapes at the node)
             psi  <Taylor object, 3 × n_q>  end psi  (rotational mode shapes at the node)
          end node
       end frame
       mdCM <3 × 1: m·c>    end mdCM
       J    <3 × 3>         end J                    (inertia tensor about the frame origin)
       Ct   <3 × n_q>       end Ct                   (∫ρ·Φ_t dV)
       Cr   <3 × n_q>       end Cr                   (∫ρ·c̃·Φ_t dV)
       Me   <n_q × n_q>     end Me
       Ke   <n_q × n_q>     end Ke
       De   <n_q × n_q>     end De
    end part

A Taylor object as jourdain writes it (order 0)::

       order = 0
       nrow = <r>
       ncol = <c>
       nq = <n_q>
       nqn = 0
       structure = 3                                 (full; 0–2 are read as full too)
       m0
          m0(  i,  j) = <value>                      (1-based; entries not listed are 0)
       end m0

Written values use 17 significant digits, so a file read back gives the same numbers. Read:
every block of the layout above; other blocks (``Gr``, ``Ge``, ``Oe``, ``ksigma``, ``AP``, ...)
are skipped whole, and their names are kept in ``ModalData.meta`` keys
``"sid skipped: <name>"``; Taylor objects of order 1 (as other tools write ``origin``, ``J``,
``mdCM``) give their order-0 part, the ``m1`` block (entries ``m1( i, j, k) = v``, k the
coordinate) read for its numbers and noted as ``"sid first-order terms skipped: <name>"``. ``Ct``, ``Cr`` given as n_q × 3 (transposed)
are accepted where n_q ≠ 3. Numbers are read with ``float`` alone: nothing in the file is
evaluated or executed. A file that does not follow the layout raises
:class:`~jourdain.errors.ModelError` naming the file and line. The DOF map read back has six
DOFs per node (ux … rz); the mode shapes Φ are rebuilt from ``phi`` and ``psi``; ω is computed
from M_e and K_e; the spin gyroscopic G_e is not part of the subset (read back as zeros).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass, field

import numpy as np
import scipy.linalg as sla

from jourdain.elastic.beam import DOF_NAMES
from jourdain.elastic.modal import ModalData
from jourdain.errors import ModelError

__all__ = ["write_sid", "read_sid", "sid_text", "sid_data", "parse_sid"]

_ENTRY = re.compile(r"^(m[01])\(\s*(\d+)\s*,\s*(\d+)\s*(?:,\s*(\d+)\s*)?\)\s*=\s*(\S+)$")
_INDEXED = re.compile(r"^(\w+)\(\s*(\d+)\s*\)\s*=\s*(.*)$")
_KEYVAL = re.compile(r"^(\w+)\s*=\s*(.*)$")
_NAME = re.compile(r"^[A-Za-z_]\w*$")


def _num(x: float) -> str:
    return format(float(x), ".17g")


def _taylor(name: str, a: np.ndarray, n_q: int, indent: str) -> list[str]:
    a = np.atleast_2d(np.asarray(a, dtype=float))
    out = [f"{indent}{name}", f"{indent}   order = 0", f"{indent}   nrow = {a.shape[0]}",
           f"{indent}   ncol = {a.shape[1]}", f"{indent}   nq = {n_q}", f"{indent}   nqn = 0",
           f"{indent}   structure = 3", f"{indent}   m0"]
    for (i, j), v in np.ndenumerate(a):
        if v != 0.0:
            out.append(f"{indent}      m0({i + 1:3d},{j + 1:3d}) = {_num(v)}")
    return [*out, f"{indent}   end m0", f"{indent}end {name}"]


def sid_text(md: ModalData) -> str:
    """The SID text of ``md`` (module docstring)."""
    n_q = md.n_q
    lines = ["# SID subset written by jourdain.elastic.sid (layout: its module docstring)",
             "part", "   new modal", "   refmod", f"      mass = {_num(md.mass)}",
             f"      nelastq = {n_q}"]
    kinds = md.kinds or ("mode",) * n_q
    lines += [f"      ielastq({k + 1:3d}) = {kind}" for k, kind in enumerate(kinds)]
    lines += ["   end refmod", "   frame"]
    Pt, Pr = md.Phi_t, md.Phi_r
    for k, c in enumerate(md.nodes):
        lines += [f"      new node = {k + 1}", "         rframe = body"]
        lines += _taylor("origin", np.reshape(c, (3, 1)), n_q, " " * 9)
        lines += _taylor("phi", Pt[k], n_q, " " * 9) + _taylor("psi", Pr[k], n_q, " " * 9)
        lines.append("      end node")
    lines.append("   end frame")
    for name, a in (("mdCM", np.reshape(md.mc, (3, 1))), ("J", md.J), ("Ct", md.C_t),
                    ("Cr", md.C_r), ("Me", md.M_e), ("Ke", md.K_e), ("De", md.D_e)):
        lines += _taylor(name, a, n_q, "   ")
    return "\n".join([*lines, "end part", ""])


def write_sid(md: ModalData, path: str | os.PathLike[str]) -> None:
    """Write ``md`` as a SID file (module docstring)."""
    with open(path, "w", encoding="utf-8") as f:
        f.write(sid_text(md))


@dataclass
class _Block:
    name: str
    line: int
    values: dict[str, tuple[str, int]] = field(default_factory=dict)
    entries: dict[tuple[int, ...], float] = field(default_factory=dict)
    children: list[_Block] = field(default_factory=list)


def parse_sid(text: str, source: str = "<sid>") -> _Block:
    """The block tree of a SID text; errors name ``source`` and the line."""
    root = _Block("<file>", 0)
    stack = [root]
    for n, raw in enumerate(text.splitlines(), start=1):
        line = re.split(r"[#!]", raw, maxsplit=1)[0].strip()
        if not line:
            continue

        def fail(msg: str, n: int = n) -> ModelError:
            return ModelError(f"{source}: line {n}: {msg}")

        top = stack[-1]
        if m := re.match(r"^end(?:\s+(\w+))?$", line):
            name = m.group(1) or ""
            if len(stack) == 1 or name != top.name:
                raise fail(f"'{line}' closes no open block (open: {top.name!r})")
            stack.pop()
        elif m := _ENTRY.match(line):
            if top.name != m.group(1):
                raise fail(f"{m.group(1)} entry outside an {m.group(1)} block (in {top.name!r})")
            if (m.group(4) is None) != (m.group(1) == "m0"):
                raise fail(f"{m.group(1)} entries have {2 if m.group(1) == 'm0' else 3} indices")
            idx = tuple(int(g) for g in m.group(2, 3, 4) if g is not None)
            try:
                top.entries[idx] = float(m.group(5))
            except ValueError:
                raise fail(f"not a number: {m.group(5)!r}") from None
        elif line.startswith("new "):
            kv = _KEYVAL.match(line[4:].strip())
            if line[4:].strip() == "modal":
                continue
            if not kv or kv.group(1) != "node":
                raise fail(f"unknown '{line}'")
            blk = _Block("node", n, {"id": (kv.group(2).strip(), n)})
            top.children.append(blk)
            stack.append(blk)
        elif m := _INDEXED.match(line):
            top.values[f"{m.group(1)}({int(m.group(2))})"] = (m.group(3).strip(), n)
        elif m := _KEYVAL.match(line):
            top.values[m.group(1)] = (m.group(2).strip(), n)
        elif _NAME.match(line):
            blk = _Block(line, n)
            top.children.append(blk)
            stack.append(blk)
        else:
            raise fail(f"cannot read {line!r}")
    if len(stack) > 1:
        raise ModelError(f"{source}: block {stack[-1].name!r} opened on line {stack[-1].line} "
                         "is not closed")
    return root


def _int(blk: _Block, key: str, source: str) -> int:
    if key not in blk.values:
        raise ModelError(f"{source}: line {blk.line}: block {blk.name!r} has no {key}")
    text, n = blk.values[key]
    try:
        return int(text)
    except ValueError:
        raise ModelError(f"{source}: line {n}: {key} = {text!r} is not an integer") from None


def _matrix(blk: _Block, source: str, skipped: dict[str, float] | None = None) -> np.ndarray:
    """The order-0 part A⁰ of a Taylor object; an order-1 part (``m1``: the first-order terms
    in q_e, outside the subset) is checked for its numbers and noted in ``skipped``."""
    order = _int(blk, "order", source)
    if order not in (0, 1):
        raise ModelError(f"{source}: line {blk.line}: {blk.name} of order {order}: 0 or 1 read")
    if order == 1 and skipped is not None:
        skipped[f"sid first-order terms skipped: {blk.name}"] = float(blk.line)
    r, c = _int(blk, "nrow", source), _int(blk, "ncol", source)
    a = np.zeros((r, c))
    for ch in blk.children:
        if ch.name != "m0":
            continue
        for (i, j), v in ch.entries.items():
            if not (1 <= i <= r and 1 <= j <= c):
                raise ModelError(f"{source}: line {ch.line}: entry ({i}, {j}) of {blk.name} "
                                 f"outside {r} × {c}")
            a[i - 1, j - 1] = v
    return a


def _child(blk: _Block, name: str, source: str) -> _Block:
    for ch in blk.children:
        if ch.name == name:
            return ch
    raise ModelError(f"{source}: line {blk.line}: block {blk.name!r} has no {name!r}")


def read_sid(path: str | os.PathLike[str]) -> ModalData:
    """Read a SID file of the subset (module docstring) into :class:`ModalData`."""
    source = os.fspath(path)
    with open(path, encoding="utf-8") as f:
        return sid_data(f.read(), source)


def _shape(name: str, a: np.ndarray, shape: tuple[int, int], blk: _Block, source: str
           ) -> np.ndarray:
    if name in ("Ct", "Cr") and a.shape == shape[::-1] and shape[0] != shape[1]:
        a = a.T
    if a.shape != shape:
        raise ModelError(f"{source}: line {blk.line}: {name} is {a.shape[0]} × {a.shape[1]}, "
                         f"expected {shape[0]} × {shape[1]}")
    return a


def sid_data(text: str, source: str = "<sid>") -> ModalData:
    """:class:`ModalData` from a SID text (module docstring)."""
    root = parse_sid(text, source)
    part = _child(root, "part", source)
    ref = _child(part, "refmod", source)
    n_q = _int(ref, "nelastq", source)
    mass_text, mass_line = ref.values.get("mass", ("", ref.line))
    try:
        mass = float(mass_text)
    except ValueError:
        raise ModelError(f"{source}: line {mass_line}: mass = {mass_text!r} is not a number") \
            from None
    kinds = tuple(ref.values.get(f"ielastq({k + 1})", ("mode", 0))[0] for k in range(n_q))
    meta: dict[str, float] = {}
    nodes_blk = [b for b in _child(part, "frame", source).children if b.name == "node"]
    nodes = np.zeros((len(nodes_blk), 3))
    Phi = np.zeros((6 * len(nodes_blk), n_q))
    for k, nb in enumerate(nodes_blk):
        nodes[k] = _shape("origin", _matrix(_child(nb, "origin", source), source, meta),
                          (3, 1), nb, source)[:, 0]
        for name, rows in (("phi", slice(0, 3)), ("psi", slice(3, 6))):
            blk = _child(nb, name, source)
            Phi[6 * k:6 * k + 6][rows] = _shape(name, _matrix(blk, source, meta), (3, n_q),
                                                blk, source)
    got = {}
    for name, shape in (("mdCM", (3, 1)), ("J", (3, 3)), ("Ct", (3, n_q)), ("Cr", (3, n_q)),
                        ("Me", (n_q, n_q)), ("Ke", (n_q, n_q)), ("De", (n_q, n_q))):
        blk = _child(part, name, source)
        got[name] = _shape(name, _matrix(blk, source, meta), shape, blk, source)
    known = {"refmod", "frame", "mdCM", "J", "Ct", "Cr", "Me", "Ke", "De"}
    meta.update({f"sid skipped: {b.name}": float(b.line) for b in part.children
                 if b.name not in known})
    try:
        lam = sla.eigh(got["Ke"], got["Me"], eigvals_only=True) if n_q else np.zeros(0)
    except np.linalg.LinAlgError:
        raise ModelError(f"{source}: Me is not positive definite") from None
    dofs = tuple((k, name) for k in range(len(nodes_blk)) for name in DOF_NAMES)
    return ModalData(nodes=nodes, dofs=dofs, Phi=Phi, M_e=got["Me"], K_e=got["Ke"],
                     D_e=got["De"], G_e=np.zeros((n_q, n_q)),
                     omega=np.sqrt(np.clip(np.sort(lam), 0.0, None)), mass=mass,
                     mc=got["mdCM"][:, 0], J=got["J"], C_t=got["Ct"], C_r=got["Cr"],
                     method="SID", kinds=kinds, meta=meta)
