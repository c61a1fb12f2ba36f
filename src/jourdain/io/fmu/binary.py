"""The FMU's binary: the FMI 2.0 headers (from FMPy), the platform folder, and the sources
compiled by :func:`jourdain.numeric.toolchain.compile_shared` into jourdain's cache.
"""

from __future__ import annotations

import hashlib
import importlib.util
import platform
import sys
from collections.abc import Mapping
from pathlib import Path
from typing import TYPE_CHECKING

from ...analysis.python_control import MissingDependency
from ...extras import missing
from ...numeric.cachefile import read_sealed
from ...numeric.toolchain import (
    CompilerError,
    compile_shared,
    compiler,
    content_key,
    library_dir,
)

if TYPE_CHECKING:
    pass



#: the FMI 2.0 headers copied into ``sources/`` (BSD-licensed, Modelica Association)
FMI_HEADERS = ("fmi2Functions.h", "fmi2FunctionTypes.h", "fmi2TypesPlatform.h")
#: the compiled sources, in the order of buildDescription.xml
SOURCES = ("jd_local.c", "jd_engine.c", "fmi2.c")
#: those of a closed system: the loop kernel (closed.c) besides
CLOSED_SOURCES = ("jd_local.c", "jd_engine.c", "jd_loop.c", "fmi2.c")
#: flags of the FMU's binary: only the fmi2 functions are exported (FMI2_Export)
CFLAGS = ("-O2", "-fPIC", "-std=c99", "-fno-math-errno", "-fvisibility=hidden")


def fmi_header_dir() -> Path:
    """The folder of the FMI 2.0 headers that FMPy ships (``fmpy/c-code``)."""
    spec = importlib.util.find_spec("fmpy")
    if spec is None or not spec.submodule_search_locations:
        raise missing("FMU export (the FMI 2.0 headers of FMPy)", "fmu", "fmpy")
    for loc in spec.submodule_search_locations:
        d = Path(loc) / "c-code"
        if all((d / h).is_file() for h in FMI_HEADERS):
            return d
    raise MissingDependency(f"the installed FMPy has no FMI 2.0 headers ({', '.join(FMI_HEADERS)}"
                            ' in fmpy/c-code): pip install --upgrade "jourdain[fmu]"')


def platform_folder() -> tuple[str, str]:
    """FMI 2.0's ``binaries/`` folder and the library suffix of this machine."""
    machine = platform.machine().lower()
    bits64 = sys.maxsize > 2**32
    if sys.platform.startswith("linux") and bits64 and machine in ("x86_64", "amd64"):
        return "linux64", ".so"
    if sys.platform == "darwin" and bits64:
        return "darwin64", ".dylib"
    raise CompilerError(f"no FMI 2.0 binary folder for this platform ({sys.platform}, {machine}):"
                        " FMUs are compiled here for Linux x86_64 and macOS; export with "
                        "binary=False (jourdain fmu --sources-only) for an FMU of sources only")


def _binary(sources: Mapping[str, bytes], name: str,
            order: tuple[str, ...] = SOURCES) -> bytes:
    """The compiled binary of the FMU's sources: from jourdain's cache of compiled code
    (:func:`jourdain.numeric.cache_dir`, keyed by the sources, the compiler and its flags) when
    it was built before (and is private and whole: its seal, :mod:`jourdain.numeric.cachefile`;
    a damaged one is deleted), else compiled there by
    :func:`jourdain.numeric.toolchain.compile_shared` (one compiler per unit, in parallel) and
    kept with its seal."""
    cc = compiler()
    h = hashlib.sha256()
    for k, v in sorted(sources.items()):
        h.update(k.encode() + b"\0" + v + b"\0")
    key = "fmu-" + content_key("fmu", cc, *CFLAGS, h.hexdigest())
    cache = library_dir() / f"{key}{Path(name).suffix}"
    data = read_sealed(cache)
    if data is None:
        try:
            compile_shared({k.split("/", 1)[1]: v for k, v in sources.items()}, order, cache,
                           CFLAGS)
        except CompilerError as exc:
            raise CompilerError(f"the FMU's binary: {exc}") from None
        data = cache.read_bytes()
    return data


