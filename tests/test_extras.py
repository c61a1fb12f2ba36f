"""A missing optional dependency (an extra of pyproject.toml) gives one message naming the
extra, from every command (exit status 1, no traceback) and from Python
(:class:`jourdain.extras.MissingDependency`), never a raw ``ModuleNotFoundError`` (issue 38,
item 10).

Each case runs in a child process in which the packages of the extra are made uninstalled:
``sys.modules[name] = None`` before jourdain is imported, which is what Python does for a
package that is not there (``import`` raises ModuleNotFoundError, ``importlib.util.find_spec``
gives None), while the packages stay installed for the rest of the suite.
"""

import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from jourdain.extras import EXTRAS, MissingDependency, message, require

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

#: the packages of each extra that jourdain imports (a subset: those of the other extras'
#: dependencies are not blocked)
PACKAGES = {
    "urdf": ["yourdfpy", "lxml"],
    "fmu": ["fmpy"],
    "control": ["control"],
    "study": ["xarray", "h5netcdf", "netCDF4", "dask", "distributed"],
    "casadi": ["casadi"],
}


def without(packages: list[str], code: str, tmp_path: Path) -> subprocess.CompletedProcess:
    """Run ``code`` in a child process in which ``packages`` are not installed."""
    prelude = textwrap.dedent(f"""
        import sys
        for name in {packages!r}:
            sys.modules[name] = None
        """)
    return subprocess.run([sys.executable, "-c", prelude + textwrap.dedent(code)],
                          capture_output=True, text=True, cwd=tmp_path, timeout=600)


def command_without(packages: list[str], args: list[str], tmp_path: Path
                    ) -> subprocess.CompletedProcess:
    return without(packages, f"""
        from jourdain.cli import main
        sys.exit(main({args!r}))
        """, tmp_path)


def assert_names_the_extra(proc: subprocess.CompletedProcess, extra: str, what: str) -> None:
    assert proc.returncode == 1, (proc.returncode, proc.stderr[-3000:])
    assert "Traceback" not in proc.stderr, proc.stderr[-3000:]
    assert f"{what} needs the extra: pip install 'jourdain[{extra}]'" in proc.stderr, proc.stderr


@pytest.mark.parametrize("blocked", [["lxml"], PACKAGES["urdf"]], ids=["lxml", "urdf"])
@pytest.mark.parametrize("command", ["check", "run"])
def test_urdf_commands_without_the_urdf_extra(blocked, command, tmp_path):
    args = [command, str(EXAMPLES / "planar_arm.urdf")]
    if command == "run":
        args += ["--out", str(tmp_path / "report")]
    proc = command_without(blocked, args, tmp_path)
    assert_names_the_extra(proc, "urdf", "URDF import")
    assert "the package lxml is not installed" in proc.stderr


def test_fmu_without_the_fmu_extra(tmp_path):
    proc = command_without(PACKAGES["fmu"], ["fmu", str(EXAMPLES / "simple_pendulum.toml"),
                                             "--out", str(tmp_path / "p.fmu")], tmp_path)
    assert_names_the_extra(proc, "fmu", "FMU export (the FMI 2.0 headers of FMPy)")
    assert not (tmp_path / "p.fmu").exists()


@pytest.mark.parametrize("blocked, what", [
    (["xarray"], "A parameter study's output (xarray)"),
    (["h5netcdf", "netCDF4"], "NetCDF output (h5netcdf or netCDF4)"),
], ids=["xarray", "netcdf"])
def test_study_without_the_study_extra(blocked, what, tmp_path):
    spec = EXAMPLES / "studies" / "rotor_stability_map.toml"
    proc = command_without(blocked, ["study", "--spec", str(spec), "--out",
                                     str(tmp_path / "s.nc"), "--quiet"], tmp_path)
    assert_names_the_extra(proc, "study", what)


def test_python_api_without_the_extras(tmp_path):
    """From Python: MissingDependency (an ImportError and a JourdainError) naming the extra,
    for python-control, labelled results (xarray), URDF and CasADi."""
    proc = without(PACKAGES["control"] + PACKAGES["study"] + PACKAGES["urdf"]
                   + PACKAGES["casadi"], f"""
        import jourdain as jd
        from jourdain.extras import MissingDependency
        from jourdain.io.urdf import load_urdf
        from jourdain.models import double_pendulum

        s = double_pendulum()
        ss = jd.state_space(s.linearize({{"phi1": 0, "phi2": 0}}))
        res = s.simulate((0, 0.1), [0.1, 0], [0, 0])
        for call, extra in ((lambda: jd.to_control(ss), "control"),
                            (res.to_xarray, "study"),
                            (lambda: load_urdf({str(EXAMPLES / 'planar_arm.urdf')!r}), "urdf"),
                            (lambda: jd.to_casadi(s), "casadi")):
            try:
                call()
            except MissingDependency as exc:
                assert isinstance(exc, (ImportError, jd.JourdainError))
                assert f"needs the extra: pip install 'jourdain[{{extra}}]'" in str(exc), exc
            else:
                raise AssertionError(f"no MissingDependency for {{extra}}")
        print("ok")
        """, tmp_path)
    assert proc.returncode == 0 and proc.stdout.strip() == "ok", proc.stderr[-3000:]


def test_require_and_message():
    assert require("math", "x", "study").sqrt(4.0) == 2.0
    with pytest.raises(MissingDependency, match=r"^Gizmos needs the extra: pip install "
                       r"'jourdain\[urdf\]' \(the package no_such_package_38 is not installed\)"):
        require("no_such_package_38.sub", "Gizmos", "urdf")
    assert set(PACKAGES) < set(EXTRAS) and "docs" in EXTRAS
    with pytest.raises(ValueError, match="no extra"):
        message("x", "nonexistent")


def test_every_optional_import_goes_through_jourdain_extras():
    """No module of the package imports an optional package itself (an ``import`` statement
    of a package outside the core dependencies and the standard library), except where the
    ImportError is caught on the spot (IPython's display, threadpoolctl, dask's scheduler),
    so that a new optional import cannot bring the raw traceback back."""
    import ast

    core = {"symengine", "sympy", "numpy", "scipy", "matplotlib", "h5py", "jourdain"}
    guarded = {("study/runner.py", "IPython.display"), ("study/runner.py", "threadpoolctl"),
               ("study/dataset.py", "dask"), ("study/dataset.py", "distributed"),
               ("study/runner.py", "distributed")}
    src = ROOT / "src" / "jourdain"
    found = set()
    for path in src.rglob("*.py"):
        for node in ast.walk(ast.parse(path.read_text())):
            names = ([a.name for a in node.names] if isinstance(node, ast.Import) else
                     [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0
                     and node.module else [])
            for name in names:
                top = name.split(".")[0]
                if top not in core and top not in sys.stdlib_module_names:
                    found.add((path.relative_to(src).as_posix(), name))
    assert found <= guarded, sorted(found - guarded)
