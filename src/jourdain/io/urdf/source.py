"""Reading the XML of a URDF file: well-formedness (no DTD), the source line of each link and
joint, checked numbers and poses, and URDF names made identifiers.
"""

from __future__ import annotations

import keyword
import math
import re
from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

from ...extras import require
from ..expressions import RESERVED_NAMES
from ..modelfile import (
    MAX_FILE_BYTES,
)
from .model import Pose, UrdfError

#: what the urdf extra is needed for, in the message of a missing package
URDF = "URDF import"


def _yourdfpy() -> Any:
    return require("yourdfpy", URDF, "urdf")


def _read_xml(path: str) -> tuple[bytes, dict[tuple[str, str], int]]:
    """The file's bytes, checked to be well-formed XML without a DTD (a located error
    otherwise): yourdfpy would recover silently from broken XML."""
    try:
        with open(path, "rb") as fh:
            raw = fh.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        raise UrdfError(f"cannot read the URDF file: {exc.strerror}", path) from None
    if len(raw) > MAX_FILE_BYTES:
        raise UrdfError(f"the file is larger than {MAX_FILE_BYTES // 1_000_000} MB; URDF "
                        "files of real robots are a few hundred kB", path)
    etree = require("lxml.etree", URDF, "urdf")  # a dependency of yourdfpy

    parser = etree.XMLParser(resolve_entities=False, no_network=True, load_dtd=False,
                             huge_tree=False)
    try:
        root = etree.fromstring(raw, parser=parser)
    except etree.XMLSyntaxError as exc:
        line = exc.lineno if isinstance(exc.lineno, int) and exc.lineno > 0 else None
        msg = str(exc.msg) if getattr(exc, "msg", None) else str(exc)
        raise UrdfError(f"malformed XML: {msg}", path, line) from None
    if root.getroottree().docinfo.internalDTD is not None or b"<!ENTITY" in raw:
        raise UrdfError("DOCTYPE/ENTITY declarations are not read (URDF files need none)", path)
    if root.tag != "robot":
        raise UrdfError(f"the root element is <{root.tag}>, expected <robot>", path,
                        root.sourceline)
    lines: dict[tuple[str, str], int] = {}
    for el in root:
        if not isinstance(el.tag, str):
            continue
        if "loop" in el.tag.lower():
            name = el.get("name", "")
            raise UrdfError(f'<{el.tag}> "{name}": closed kinematic loops are not supported '
                            "(jourdain models trees; cut the loop or model it in a model "
                            "file)", path, el.sourceline)
        if el.tag in ("link", "joint"):
            lines.setdefault((el.tag, el.get("name", "")), el.sourceline)
            mim = el.find("mimic") if el.tag == "joint" else None
            if mim is not None:
                lines.setdefault(("mimic", el.get("name", "")), mim.sourceline)
    return raw, lines


def _float(value: object, what: str, path: str, line: int | None,
           default: float | None = None) -> float | None:
    if value is None:
        return default
    try:
        v = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        raise UrdfError(f"{what}: expected a number, got {value!r}", path, line) from None
    if not math.isfinite(v):
        raise UrdfError(f"{what}: {value!r} is not a finite number", path, line)
    return v



def _float_or(value: object, what: str, path: str, line: int | None, default: float) -> float:
    """:func:`_float` with a default for an absent value."""
    v = _float(value, what, path, line)
    return default if v is None else v


def _matrix(value: Any, what: str, path: str, line: int | None) -> np.ndarray:
    """A 4×4 pose of yourdfpy (None: identity), checked finite with a rotation block."""
    if value is None:
        return np.eye(4)
    T = np.asarray(value, dtype=float)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise UrdfError(f"{what}: the origin is not finite", path, line)
    return T


def _pose(T: np.ndarray) -> Pose:
    return tuple((float(r[0]), float(r[1]), float(r[2]), float(r[3])) for r in T)



class _Names:
    """URDF names made identifiers, unique within one kind, first come first served (file
    order, so the result does not depend on anything but the file)."""

    def __init__(self, prefix: str) -> None:
        self.prefix = prefix
        self.taken: set[str] = set()
        self.names: dict[str, str] = {}

    def __call__(self, name: str) -> str:
        if name in self.names:
            return self.names[name]
        s = re.sub(r"[^A-Za-z0-9_]", "_", name)
        s = re.sub(r"__+", "_", s).strip("_")
        if not s or not s[0].isalpha():
            s = f"{self.prefix}_{s}".rstrip("_")
        if keyword.iskeyword(s) or s in RESERVED_NAMES:
            s = f"{s}_{self.prefix}"
        base, k = s, 2
        while s in self.taken:
            s, k = f"{base}_{k}", k + 1
        self.taken.add(s)
        self.names[name] = s
        return s



@dataclass(frozen=True)
class _Source:
    """The file being read: its name and the source lines of its links and joints."""

    path: str
    lines: Mapping[tuple[str, str], int]

    def line(self, tag: str, name: str) -> int | None:
        return self.lines.get((tag, name))

