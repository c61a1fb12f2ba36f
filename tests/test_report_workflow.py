"""The report's structure (issue 16) and its speed-ups (issue 13): the command line and the
report share jourdain.workflow and never import each other's private names; the report made
with forked workers (``jourdain run``) is the report made in one process; the symbolic display
comes from the compile cache only for the same equations."""

import ast
import json
import re
from pathlib import Path

import pytest

import jourdain.io.report.equations as equations
from jourdain.io import load_model
from jourdain.io.report import write_report

ROOT = Path(__file__).resolve().parents[1]
SRC = ROOT / "src" / "jourdain"
PENDULUM = ROOT / "examples" / "double_pendulum.toml"


def _imports(path: Path) -> list[tuple[str, list[str], bool]]:
    """(module, names, at module level) of every import of a source file, relative imports
    resolved to absolute module names."""
    package = ".".join(path.relative_to(SRC.parent).with_suffix("").parts[:-1])
    if path.name == "__init__.py":
        package = ".".join(path.relative_to(SRC.parent).parts[:-1])
    tree = ast.parse(path.read_text())
    top = set(map(id, tree.body))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom):
            base = package.split(".")
            mod = node.module or ""
            if node.level:
                base = base[:len(base) - node.level + 1]
                mod = ".".join([*base, mod]) if mod else ".".join(base)
            out.append((mod, [a.name for a in node.names], id(node) in top))
        elif isinstance(node, ast.Import):
            out += [(a.name, [], id(node) in top) for a in node.names]
    return out


def _files(*packages: str) -> list[Path]:
    return [p for pkg in packages for p in sorted((SRC / pkg).rglob("*.py"))]


def test_cli_and_report_share_the_workflow_not_each_other():
    for path in _files("io/report", "workflow"):
        for mod, _, _ in _imports(path):
            assert not mod.startswith("jourdain.cli"), f"{path} imports {mod}"
    for path in _files("workflow"):
        for mod, _, _ in _imports(path):
            assert not mod.startswith("jourdain.io.report"), f"{path} imports {mod}"
    for path in _files("cli"):
        for mod, names, _ in _imports(path):
            if mod.startswith("jourdain.io.report"):
                private = [n for n in names if n.startswith("_")]
                assert not private, f"{path} imports private {private} of {mod}"


def test_no_deferred_imports_but_heavy_optional_ones():
    # function-level imports only for Matplotlib (imported by the figure workers),
    # jourdain.loops and jourdain.io.closed_linear, which loads it (SciPy's linear algebra,
    # for closed systems only) and jourdain.study (a study's section of jourdain run --study;
    # xarray is optional)
    allowed = ("matplotlib", "jourdain.loops", "jourdain.io.closed_linear", "jourdain.study")
    for path in _files("cli", "workflow", "io/report"):
        for mod, _, top in _imports(path):
            assert top or mod.startswith(allowed), f"{path}: deferred import of {mod}"


def _normalized(page: str) -> str:
    """The page without what depends on the clock: the header's time and the simulation's
    wall time."""
    page = re.sub(r"<p class='meta'>jourdain .*? computed in [0-9.]+ s</p>", "", page)
    return re.sub(r"[0-9.]+ s wall time", "", page)


def test_the_report_with_workers_is_the_report_without(tmp_path, monkeypatch):
    # a display cache of its own: empty for the first report (the worker computes the
    # display), then holding it (the other two read it)
    monkeypatch.setattr(equations, "_cache_file",
                        lambda key: tmp_path / "display" / f"{key}.json")
    (tmp_path / "display").mkdir()
    runs = {}
    for name, parallel in (("cold", True), ("serial", False), ("warm", True)):
        info = write_report(load_model(PENDULUM), tmp_path / name, parallel=parallel)
        assert info.status == "complete"
        runs[name] = info
    assert len(list((tmp_path / "display").glob("*.json"))) == 1
    one = (tmp_path / "serial" / "report.html").read_text()
    for name in ("cold", "warm"):
        assert [f.name for f in runs[name].files] == [f.name for f in runs["serial"].files]
        assert runs[name].summary_lines == runs["serial"].summary_lines
        two = (tmp_path / name / "report.html").read_text()
        assert "jourdain-figure" not in two and "jourdain-nominal" not in two
        assert "jourdain-equations" not in two
        assert two.count("<svg") == one.count("<svg") >= 5
        assert _normalized(one) == _normalized(two)
        for file in ("equations.json", "equations.tex", "values.json",
                     "linearization-hanging.json"):
            assert (tmp_path / "serial" / file).read_bytes() == \
                (tmp_path / name / file).read_bytes(), (name, file)


def test_display_cache_is_keyed_by_what_it_shows(tmp_path, monkeypatch):
    monkeypatch.setenv("JOURDAIN_CACHE", str(tmp_path / "cache"))
    model = load_model(PENDULUM)
    first = equations.cached_display(model, 600)
    kept = list((tmp_path / "cache" / "report").glob("*.json"))
    assert [p.stem for p in kept] == [equations.display_key(model, 600)]

    def refuse(*args):
        raise AssertionError("computed again although cached")

    with monkeypatch.context() as m:
        m.setattr(equations, "compute_display", refuse)
        assert equations.cached_display(model, 600) == first
    # another bound on displayed operations, another parameter value: other keys
    assert equations.display_key(model, 10) != kept[0].stem
    text = PENDULUM.read_text()
    changed = text.replace('m1 = { value = 1.0,', 'm1 = { value = 1.25,', 1)
    assert changed != text
    other = tmp_path / "other.toml"
    other.write_text(changed)
    assert equations.display_key(load_model(other), 600) != kept[0].stem
    # an unreadable entry is computed again (and replaced)
    kept[0].write_text("{not json")
    again = equations.cached_display(model, 600)
    assert again == first
    assert json.loads(kept[0].read_text())["ops"] == first.ops


def test_display_counts_operations_of_the_equations():
    model = load_model(PENDULUM)
    display = equations.compute_display(model, 600)
    mats = equations.eom_matrices(model.system)
    assert display.ops == {k: m.count_ops(cse=True) for k, m in mats.items()}
    assert set(display.nominal) == {n.name for n in model.nominal}
    assert json.loads(display.json_text)["format"] == "jourdain-eom/1"



def test_figures_of_a_lost_worker_are_drawn_here():
    import os
    import signal
    import time

    import numpy as np

    from jourdain.io import workers
    from jourdain.io.report import figures

    if workers.cores() < 2:
        pytest.skip("one core: the report forks no workers")
    t = np.linspace(0.0, 1.0, 11)
    expected = figures.time_plot(t, {"x": t}, "x / m", "coordinates")
    pool = workers.fork_workers(None, workers=1)
    assert pool is not None
    try:
        queued = figures.Figures(pool)
        first = queued.add(figures.time_plot, t, {"x": t}, "x / m", "coordinates")
        assert queued.fill(first) == expected  # drawn by the worker, the same bytes
        for pid in list(pool._processes):  # the worker killed (out of memory, say)
            os.kill(pid, signal.SIGKILL)
        time.sleep(0.5)
        lost = figures.Figures(pool)
        page = lost.add(figures.time_plot, t, {"x": t}, "x / m", "coordinates")
        assert lost.fill(page) == expected
    finally:
        pool.shutdown()


def test_the_numbers_never_import_sympy(tmp_path):
    """``jourdain run``'s own process computes the numbers (matrices, numeric linearization,
    simulation) with SymEngine alone; SymPy (0.3 s to import) is for the display, in the
    worker. A comparison of None with a SymEngine number had imported it. Checked in a fresh
    process on the robot arm (its Pow nodes go through the numeric jet's base test)."""
    import subprocess
    import sys

    code = (
        "import sys, numpy as np\n"
        "from jourdain.io import load_model\n"
        "from jourdain.workflow.evaluation import evaluate_all\n"
        f"m = load_model({str(ROOT / 'examples' / 'robot_arm.toml')!r})\n"
        "s = m.system\n"
        "v, extra, missing = evaluate_all(m, np.array(m.simulation.y0, float),\n"
        "    np.array(m.simulation.yd0, float), 0.0, {}, {})\n"
        "assert 'A' in v or 'M' in v, sorted(v)\n"
        "r = s.simulate((0.0, 0.1), m.simulation.y0, m.simulation.yd0)\n"
        "print('sympy' in sys.modules, sorted(v)[:3])\n")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         env={**__import__("os").environ, "JOURDAIN_CACHE": str(tmp_path)})
    assert out.returncode == 0, out.stderr[-2000:]
    assert out.stdout.startswith("False"), out.stdout


def _sleep_long() -> None:
    import time as _time
    _time.sleep(60)


def test_stop_workers_does_not_wait_for_a_worker_still_starting(tmp_path):
    """``jourdain run`` forks its figures' worker before it reads the model; where the model
    is malformed, the message must not wait for the worker's imports: stop_workers ends a
    worker whose initializer would take a minute (killed by a signal: a worker that had been
    waited for would have ended by itself, with status 0), and the command exits 1 naming
    the line."""
    import subprocess
    import sys

    from jourdain.io.workers import fork_workers, stop_workers

    pool = fork_workers(_sleep_long)
    if pool is None:
        pytest.skip("one core: no worker is forked")
    processes = list(pool._processes.values())
    stop_workers(pool)
    assert processes and all(not p.is_alive() and p.exitcode is not None and p.exitcode < 0
                             for p in processes), [p.exitcode for p in processes]
    bad = tmp_path / "bad.toml"
    bad.write_text("[model]\nname = 3 = 4\n")
    proc = subprocess.run([sys.executable, "-m", "jourdain.cli", "run", str(bad), "--out",
                           str(tmp_path / "out")], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 1
    assert "bad.toml:2: TOML syntax error" in proc.stderr
    assert "Traceback" not in proc.stderr
