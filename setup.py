"""The one build step beyond pyproject.toml: jourdain's integrator library, which no model
changes, compiled when jourdain is installed from source (``pip install .`` or ``-e .``), so that
a machine's first simulation and first ``jourdain run`` do not wait for it
(:func:`jourdain.numeric.toolchain.prebuild`). It goes into ``jourdain/numeric/prebuilt/`` (for
an editable install: in the source tree) and is used only where its key matches the machine,
compiler and source at run time. An install without a C compiler, or whose compile fails, says
so and goes on: the library is then compiled at its first use, as before."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path
from types import ModuleType

from setuptools import Command, Distribution, setup
from setuptools.command.build import build

SRC = Path(__file__).resolve().parent / "src"
PREBUILT = Path("jourdain", "numeric", "prebuilt")


def _module(name: str, path: Path, package: bool = False) -> ModuleType:
    """``name`` from ``path``; a package's ``__init__`` is not run (jourdain's imports NumPy
    and SymEngine, which the build environment does not have)."""
    if name in sys.modules:
        return sys.modules[name]
    spec = importlib.util.spec_from_file_location(
        name, path / "__init__.py" if package else path,
        submodule_search_locations=[str(path)] if package else None)
    assert spec is not None and spec.loader is not None
    mod = importlib.util.module_from_spec(spec)
    sys.modules[name] = mod
    if not package:
        spec.loader.exec_module(mod)
    return mod


def prebuild_integrator(dest: Path) -> Path:
    """Compile the integrator library into ``dest``; its path (CompilerError where it cannot)."""
    _module("jourdain", SRC / "jourdain", package=True)
    _module("jourdain.numeric", SRC / "jourdain" / "numeric", package=True)
    _module("jourdain.errors", SRC / "jourdain" / "errors.py")
    _module("jourdain.numeric.cachefile", SRC / "jourdain" / "numeric" / "cachefile.py")
    _module("jourdain.numeric.buildlock", SRC / "jourdain" / "numeric" / "buildlock.py")
    _module("jourdain.numeric.native", SRC / "jourdain" / "numeric" / "native.py")
    _module("jourdain.numeric.toolchain", SRC / "jourdain" / "numeric" / "toolchain.py")
    ic = _module("jourdain.numeric.integrator_c", SRC / "jourdain" / "numeric" / "integrator_c.py")
    return ic.prebuild(dest)


class build_integrator(Command):
    """Compile the integrator library into the package (into the source tree for an editable
    install)."""

    description = "compile jourdain's integrator library (C) into jourdain/numeric/prebuilt"
    user_options: list = []

    def initialize_options(self) -> None:
        self.build_lib: str | None = None
        self.editable_mode = False
        self._outputs: list[str] = []

    def finalize_options(self) -> None:
        self.set_undefined_options("build_py", ("build_lib", "build_lib"))

    def _dest(self) -> Path:
        return (SRC if self.editable_mode else Path(self.build_lib or "build")) / PREBUILT

    def run(self) -> None:
        try:
            so = prebuild_integrator(self._dest())
        except Exception as exc:  # noqa: BLE001 - never fail the install: built at first use
            print(f"jourdain: the integrator library was not compiled at install time ({exc}); "
                  "it is compiled at its first use instead", file=sys.stderr)
            return
        self._outputs = [str(so), str(so.with_suffix(".c")), f"{so}.sha256"]  # and its seal

    def get_outputs(self) -> list[str]:
        return [] if self.editable_mode else list(self._outputs)

    def get_output_mapping(self) -> dict[str, str]:
        return {}

    def get_source_files(self) -> list[str]:
        return []


class build_with_integrator(build):
    sub_commands = [*build.sub_commands, ("build_integrator", None)]


class MachineCodeDistribution(Distribution):
    """A wheel that carries the integrator library is compiled code for one platform and one
    Python: tagged so (``cp311-cp311-linux_x86_64``), not as pure Python (``py3-none-any``,
    which pip would install anywhere, with a library that no other machine's key finds)."""

    def has_ext_modules(self) -> bool:
        return True


if __name__ == "__main__":
    setup(cmdclass={"build": build_with_integrator, "build_integrator": build_integrator},
          distclass=MachineCodeDistribution)
