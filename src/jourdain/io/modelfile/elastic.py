"""Reading an elastic body: ``[bodies.<name>]`` with an ``elastic`` table instead of mass data
(:class:`jourdain.elastic.ElasticBody`, a beam meshed and reduced when the file is read):

    [bodies.arm]
    parent = "world"
    joint = { type = "revolute", coordinate = "phi", axis = "z" }
    elastic = { modes = 3, keep = ["ux", "uy", "rz"], attach = { tip = 8 },
                beam = { length = 1.0, E = 7e10, rho = 2700, A = 1e-4, I_y = 1e-10,
                         I_z = 8.3e-11, J = 1e-10, nu = 0.3, n_elements = 8 } }

The beam's data are numbers (the modes are computed from them once). Optional keys:
``clamped`` (nodes held by the frame, default ``[0]``), ``keep`` (the DOF names the modes use),
``attach`` (label -> node: the frames ``<name>_<label>`` other bodies and forces use),
``stiffening`` (geometric stiffening, default true), ``damping_ratio`` and ``mass``
(``"lumped"`` at the nodes, the default, or ``"consistent"``: at the elements' Gauss points,
the FE beam's consistent mass exactly, for four bodies per element) and ``reduction``
(``"normal"`` modes, the default, or ``"craig_bampton"``: constraint modes at the ``attach``
nodes and ``modes`` fixed-interface modes). A rotor has
``spin`` (the shaft's angle, ``"Omega*t"``), ``discs`` (``{ node, m, Id, Ip }``) and
``bearings`` (``{ node, k_yy, k_zz, k_yz, k_zy, c_yy, ... }``) instead. jourdain.elastic
(SciPy's sparse eigensolvers) is imported only for files that have such a body.
"""

from __future__ import annotations

from typing import Any

from ...errors import ModelError
from ..toml_positions import Path
from .values import _Values

_ELASTIC_KEYS = {"beam", "modes", "clamped", "keep", "attach", "stiffening", "damping_ratio",
                 "spin", "discs", "bearings", "mass", "reduction"}
_DISC_KEYS = {"node", "m", "Id", "Ip"}
_BEARING_KEYS = {"node", "k_yy", "k_zz", "k_yz", "k_zy", "c_yy", "c_zz", "c_yz", "c_zy"}
_BEAM_NUMBERS = ("length", "E", "rho", "A", "I_y", "I_z", "J", "G", "nu", "kappa", "I_p")
_BEAM_KEYS = {*_BEAM_NUMBERS, "n_elements", "axis", "origin", "rotary_inertia"}


class _Elastic(_Values):
    def attachment_names(self, tbl: dict) -> dict[str, str]:
        """The frames ``<body>_<label>`` that the elastic bodies of ``tbl`` attach, by the
        body that makes them (read before the bodies, so that others may hang from them)."""
        out: dict[str, str] = {}
        for bname, spec in tbl.items():
            if isinstance(spec, dict) and isinstance(spec.get("elastic"), dict):
                attach = spec["elastic"].get("attach", {})
                if isinstance(attach, dict):
                    out.update({f"{bname}_{label}": bname for label in attach})
        return out

    def read_elastic(self, bname: str, spec: dict, parent: str, joint: Any) -> Any:
        from ...elastic.beam import Beam
        from ...elastic.body import ElasticBody

        p: Path = ("bodies", bname, "elastic")
        el = self.table(spec["elastic"], p, _ELASTIC_KEYS)
        for key in ("mass", "com", "inertia"):
            if key in spec:
                raise self.fail(("bodies", bname, key), f'body "{bname}" is elastic: its mass '
                                "comes from the beam (rho, A), so it takes no " + key)
        bp: Path = (*p, "beam")
        bt = self.table(self.require(el, "beam", p), bp, _BEAM_KEYS)
        kw: dict[str, Any] = {k: self.number(bt[k], (*bp, k)) for k in _BEAM_NUMBERS if k in bt}
        for k in ("axis", "origin"):
            if k in bt:
                vec = bt[k]
                if not (isinstance(vec, list) and len(vec) == 3):
                    raise self.fail((*bp, k), "expected three numbers")
                kw[k] = tuple(self.number(x, (*bp, k, i)) for i, x in enumerate(vec))
        if "n_elements" in bt:
            kw["n_elements"] = int(self.number(bt["n_elements"], (*bp, "n_elements"),
                                               positive=True, integer=True))
        if "rotary_inertia" in bt:
            kw["rotary_inertia"] = self.flag(bt["rotary_inertia"], (*bp, "rotary_inertia"))
        for k in ("length", "E", "rho", "A", "I_y", "I_z", "J"):
            self.require(bt, k, bp)
        modes = int(self.number(self.require(el, "modes", p), (*p, "modes"), positive=True,
                                integer=True))
        clamped = [int(self.number(x, (*p, "clamped", i), integer=True))
                   for i, x in enumerate(self.list_of(el.get("clamped", [0]), (*p, "clamped")))]
        keep = None
        if "keep" in el:
            keep = [self.string(x, (*p, "keep", i))
                    for i, x in enumerate(self.list_of(el["keep"], (*p, "keep")))]
        attach = {label: int(self.number(v, (*p, "attach", label), integer=True))
                  for label, v in self.table(el.get("attach", {}), (*p, "attach")).items()}
        for label in attach:
            self.name(label, (*p, "attach", label), "attachment")
        stiffening = self.flag(el.get("stiffening", True), (*p, "stiffening"))
        zeta = self.number(el.get("damping_ratio", 0.0), (*p, "damping_ratio"))
        mass = self.string(el.get("mass", "lumped"), (*p, "mass"))
        if mass not in ("lumped", "consistent"):
            raise self.fail((*p, "mass"), f'expected "lumped" or "consistent", got {mass!r}')
        reduction = self.string(el.get("reduction", "normal"), (*p, "reduction"))
        if reduction not in ("normal", "craig_bampton"):
            raise self.fail((*p, "reduction"), 'expected "normal" or "craig_bampton", got '
                            f"{reduction!r}")
        if "spin" in el:
            if "reduction" in el:
                raise self.fail((*p, "reduction"), "a rotor (with spin) takes no reduction: its "
                                "modes are the bending modes on its bearings")
            return self.read_rotor(bname, el, parent, joint, kw, modes, attach, mass)
        for key in ("discs", "bearings"):
            if key in el:
                raise self.fail((*p, key), f"{key} belong to a rotor: give its spin as well "
                                '(spin = "Omega*t")')
        try:
            beam = Beam(**kw)
            return ElasticBody.beam(bname, parent, joint, beam, modes, clamped=clamped,
                                    keep=keep, attach=attach, stiffening=stiffening,
                                    damping_ratio=zeta, mass=mass, reduction=reduction)
        except ModelError as exc:
            where = bp if str(exc).startswith("Beam") else p
            raise self.fail(where, str(exc)) from None

    def read_rotor(self, bname: str, el: dict, parent: str, joint: Any, kw: dict[str, Any],
                   modes: int, attach: dict[str, int], mass: str) -> Any:
        """A flexible rotor (:meth:`jourdain.elastic.ElasticBody.rotor`): ``spin`` (the shaft's
        angle, an expression of parameters and t), ``discs`` and ``bearings`` (arrays of
        tables with numbers)."""
        from ...elastic.beam import Beam
        from ...elastic.body import ElasticBody
        from ...elastic.rotor import Bearing, Disc

        p: Path = ("bodies", bname, "elastic")
        for key in ("clamped", "keep", "stiffening", "damping_ratio"):
            if key in el:
                raise self.fail((*p, key), f"a rotor (with spin) takes no {key}: its modes are "
                                "the bending modes on its bearings")
        spin = self.expr(el["spin"], (*p, "spin"), set(self.params) | {"t"},
                         "the shaft's spin angle (parameters and t)")
        parts: dict[str, list[Any]] = {"discs": [], "bearings": []}
        for key, keys, cls in (("discs", _DISC_KEYS, Disc), ("bearings", _BEARING_KEYS,
                                                              Bearing)):
            for i, item in enumerate(self.list_of(el.get(key, []), (*p, key))):
                tbl = self.table(item, (*p, key, i), keys)
                vals = {k: self.number(v, (*p, key, i, k), integer=k == "node")
                        for k, v in tbl.items() if k != "node"}
                node = int(self.number(self.require(tbl, "node", (*p, key, i)),
                                       (*p, key, i, "node"), integer=True))
                try:
                    parts[key].append(cls(node, **vals))
                except TypeError as exc:
                    raise self.fail((*p, key, i), f"{key[:-1]}: {exc}") from None
        try:
            return ElasticBody.rotor(bname, parent, joint, Beam(**kw), modes, spin=spin,
                                     discs=parts["discs"], bearings=parts["bearings"],
                                     attach=attach, mass=mass)
        except ModelError as exc:
            raise self.fail(p, str(exc)) from None

    def flag(self, value: object, path: Path) -> bool:
        if not isinstance(value, bool):
            raise self.fail(path, f"expected true or false, got {value!r}")
        return value

    def list_of(self, value: object, path: Path) -> list:
        if not isinstance(value, list):
            raise self.fail(path, "expected an array")
        return value
