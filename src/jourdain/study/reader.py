"""Study files: which model, which cases, what to compute per case (TOML, read as data).

A study file names a model file, the quantities it varies (parameters, initial coordinates
``x``, initial rates ``x_d``) and what to compute for every case. The format is described in
``docs/studies.md``::

    [study]
    model = "rotor.toml"          # relative to this file
    design = "grid"               # grid | list | random
    [vary.Omega]
    range = { start = 0, stop = 30, num = 61 }
    [vary.d_i]
    values = [0.5, 1.0, 2.0]
    [compute.linearize]
    about = "centred"

Numbers may be written as constant expressions of jourdain's expression language, and bounds
as expressions in the model's parameters (their default values), e.g. ``"3*sqrt(k/m)"``; they
are read by :mod:`jourdain.io.expressions`, never by Python. Every mistake raises
:class:`StudyError` naming the file, the line and the key.
"""
from __future__ import annotations

import hashlib
import math
import tomllib
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np

from ..io.expressions import ExpressionError, parse_expression
from ..io.toml_positions import key_lines, line_of
from .compute_tables import COMPUTE_KEYS, ComputeTables, type_name
from .spec import (
    DESIGNS,
    DISTRIBUTIONS,
    MAX_CASES,
    MAX_FILE_BYTES,
    RESERVED,
    StudyError,
    StudySpec,
    Varied,
)

__all__ = ["COMPUTE_KEYS", "load_study", "loads_study"]

def load_study(path: str | Path, model: str | Path | None = None) -> StudySpec:
    """Read a study file; ``model`` replaces the file's ``[study] model``."""
    name = str(path)
    try:
        raw = Path(path).read_bytes()[:MAX_FILE_BYTES + 1]
    except OSError as exc:
        raise StudyError(f"{name}: cannot read the study file: {exc.strerror}", name) from None
    if len(raw) > MAX_FILE_BYTES:
        raise StudyError(f"{name}: larger than {MAX_FILE_BYTES} bytes", name)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError:
        raise StudyError(f"{name}: not UTF-8 text", name) from None
    return loads_study(text, name, base=Path(path).resolve().parent, model=model)


def loads_study(text: str, filename: str = "<study>", base: str | Path | None = None,
                model: str | Path | None = None) -> StudySpec:
    """Read a study from TOML ``text``; a relative model path is taken from ``base`` (default:
    the working directory); ``model`` replaces the file's ``[study] model``."""
    return _Reader(text, filename, Path(base) if base is not None else Path.cwd()).read(model)


class _Reader(ComputeTables):
    def __init__(self, text: str, filename: str, base: Path) -> None:
        self.text = text
        self.file = filename
        self.base = base
        try:
            self.data = tomllib.loads(text)
        except tomllib.TOMLDecodeError as exc:
            raise StudyError(f"{filename}: not valid TOML: {exc}", filename) from None
        self.lines = key_lines(text)

    def error(self, path: tuple[str | int, ...], message: str) -> StudyError:
        line = line_of(self.lines, path)
        where = f"{self.file}:{line}" if line else self.file
        key = " → ".join(str(p) for p in path)
        return StudyError(f"{where}: {key}: {message}" if key else f"{where}: {message}",
                          self.file, line)

    def table(self, value: Any, path: tuple[str | int, ...], allowed: set[str]) -> dict:
        if not isinstance(value, dict):
            raise self.error(path, f"expected a table, got {type_name(value)}")
        unknown = sorted(set(value) - allowed)
        if unknown:
            raise self.error((*path, unknown[0]), f"unknown key; allowed: "
                             f"{', '.join(sorted(allowed))}")
        return value

    def number(self, value: Any, path: tuple[str | int, ...], names: Mapping[str, float]
               | None = None) -> float:
        """A number, or an expression string in the model's parameters (their defaults)."""
        if isinstance(value, bool):
            raise self.error(path, "expected a number, got a boolean")
        if isinstance(value, int | float):
            out = float(value)
        elif isinstance(value, str):
            try:
                e = parse_expression(value, names=set(names or ()))
                out = float(e.subs({k: v for k, v in (names or {}).items()}))
            except (ExpressionError, RuntimeError, TypeError, ValueError) as exc:
                raise self.error(path, f'"{value}": {exc}') from None
        else:
            raise self.error(path, f"expected a number, got {type_name(value)}")
        if not math.isfinite(out):
            raise self.error(path, f"{value!r} is not finite")
        return out

    def read(self, model_override: str | Path | None) -> StudySpec:
        from ..io.modelfile import loads_model

        top = self.table(self.data, (), {"study", "vary", "compute"})
        study = self.table(top.get("study", {}), ("study",),
                           {"model", "name", "design", "samples", "seed", "block"})
        model_name = model_override if model_override is not None else study.get("model")
        if model_name is None:
            raise self.error(("study",), 'no model: give [study] model = "FILE.toml" (or the '
                             "model on the command line)")
        if not isinstance(model_name, str | Path):
            raise self.error(("study", "model"), f"expected a file name, got {type_name(model_name)}")
        mpath = Path(model_name)
        if not mpath.is_absolute() and model_override is None:
            mpath = self.base / mpath
        try:
            model_text = mpath.read_text(encoding="utf-8")
        except (OSError, UnicodeDecodeError) as exc:
            raise self.error(("study", "model"), f"cannot read the model file {str(mpath)!r}: "
                             f"{getattr(exc, 'strerror', None) or exc}") from None
        model = loads_model(model_text, str(mpath))
        system = model.system
        defaults = system.parameter_values
        design = study.get("design", "grid")
        if design not in DESIGNS:
            raise self.error(("study", "design"), f'expected one of {", ".join(DESIGNS)}, got '
                             f"{design!r}")
        samples, seed = 0, None
        if design == "random":
            samples = self.count(study.get("samples"), ("study", "samples"), "samples")
            seed = study.get("seed")
            if isinstance(seed, bool) or not isinstance(seed, int) or seed < 0:
                raise self.error(("study", "seed"), "a random design needs a seed, a whole "
                                 "number ≥ 0 (the same seed gives the same cases)")
        else:
            for key in ("samples", "seed"):
                if key in study:
                    raise self.error(("study", key), f'only for design = "random" (this study '
                                     f'is "{design}")')
        block = self.count(study.get("block", 512), ("study", "block"), "block")
        name = study.get("name", Path(self.file).stem)
        if not isinstance(name, str):
            raise self.error(("study", "name"), f"expected a string, got {type_name(name)}")
        kinds = {n: "parameter" for n in defaults}
        kinds.update({n: "y0" for n in system.coordinate_names})
        kinds.update({f"{n}_d": "yd0" for n in system.coordinate_names})
        raw_vary = top.get("vary", {})
        vary = self.table(raw_vary, ("vary",), set(raw_vary) if isinstance(raw_vary, dict)
                          else set())
        varied = []
        for vname, entry in vary.items():
            path = ("vary", vname)
            if vname in RESERVED:
                raise self.error(path, f'"{vname}" names a dimension or output of the results '
                                 f"({', '.join(sorted(RESERVED))}): rename the model's "
                                 "parameter to vary it")
            if vname not in kinds:
                raise self.error(path, f'"{vname}" is not a parameter, coordinate or rate of '
                                 f"the model; parameters: {', '.join(defaults) or '(none)'}; "
                                 f"coordinates: {', '.join(system.coordinate_names)}")
            varied.append(self.varied(vname, kinds[vname], entry, path, design, defaults))
        if design == "list" and varied:
            lengths = {v.name: len(v.values or ()) for v in varied}
            if len(set(lengths.values())) > 1:
                raise self.error(("vary",), f"a list design needs lists of one length, got "
                                 f"{lengths}")
        compute = self.compute(top.get("compute"), model, defaults)
        spec = StudySpec(model_path=str(mpath), model_text=model_text,
                         model_hash=hashlib.sha256(model_text.encode()).hexdigest(),
                         design=design, varied=tuple(varied), compute=compute, samples=samples,
                         seed=seed, block=block, name=name, source=self.text,
                         filename=self.file)
        if spec.n_cases > MAX_CASES:
            raise self.error(("vary",), f"{spec.n_cases} cases; at most {MAX_CASES}")
        return spec

    def count(self, value: Any, path: tuple[str | int, ...], what: str) -> int:
        if isinstance(value, bool) or not isinstance(value, int) or value < 1:
            raise self.error(path, f"{what}: expected a whole number ≥ 1, got {value!r}")
        if value > MAX_CASES:
            raise self.error(path, f"{what}: at most {MAX_CASES}")
        return value

    def varied(self, name: str, kind: str, entry: Any, path: tuple[str | int, ...],
               design: str, defaults: Mapping[str, float]) -> Varied:
        if design == "random":
            entry = self.table(entry, path, {"distribution", "low", "high", "mean", "std", "mu",
                                             "sigma"})
            dist = entry.get("distribution")
            if dist not in DISTRIBUTIONS:
                raise self.error((*path, "distribution"), f"expected one of "
                                 f"{', '.join(DISTRIBUTIONS)}, got {dist!r}")
            keys = DISTRIBUTIONS[dist]
            extra = sorted(set(entry) - {"distribution", *keys})
            if extra:
                raise self.error((*path, extra[0]), f'not a parameter of the {dist} '
                                 f"distribution ({', '.join(keys)})")
            args = []
            for k in keys:
                if k not in entry:
                    raise self.error(path, f"the {dist} distribution needs {' and '.join(keys)}")
                args.append(self.number(entry[k], (*path, k), defaults))
            if dist == "uniform" and not args[0] < args[1]:
                raise self.error(path, f"uniform: low < high needed, got {args}")
            if dist != "uniform" and not args[1] >= 0:
                raise self.error((*path, keys[1]), f"must be ≥ 0, got {args[1]}")
            return Varied(name, kind, distribution=dist, arguments=tuple(args))
        allowed = {"values", "range"} if design == "grid" else {"values"}
        entry = self.table(entry, path, allowed)
        if ("values" in entry) == ("range" in entry):
            raise self.error(path, "give values = [...]" + (" or range = { start, stop, num }"
                                                            if design == "grid" else ""))
        if "values" in entry:
            vals = entry["values"]
            if not isinstance(vals, list) or not vals:
                raise self.error((*path, "values"), "expected a non-empty list of numbers")
            values = tuple(self.number(v, (*path, "values", i), defaults)
                           for i, v in enumerate(vals))
        else:
            rng = self.table(entry["range"], (*path, "range"), {"start", "stop", "num"})
            if set(rng) != {"start", "stop", "num"}:
                raise self.error((*path, "range"), "needs start, stop and num (evenly spaced, "
                                 "both ends included)")
            num = self.count(rng["num"], (*path, "range", "num"), "num")
            a = self.number(rng["start"], (*path, "range", "start"), defaults)
            b = self.number(rng["stop"], (*path, "range", "stop"), defaults)
            values = tuple(float(x) for x in np.linspace(a, b, num))
        return Varied(name, kind, values=values)
