"""A study in the model's report (jourdain.study.report): the section's figures are files in the
report's folder and the HTML references them; the numbers shown are the dataset's (written as
study.nc), and the stability verdicts they count agree with the Jeffcott rotor's closed-form
threshold; a study that cannot run becomes a note, not a failed report."""

from __future__ import annotations

import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

pytest.importorskip("xarray")
pytest.importorskip("h5netcdf")
pytest.importorskip("matplotlib")

from jourdain.study import load_study, open_study  # noqa: E402
from jourdain.study.report import output_summary, study_section  # noqa: E402

DATA = Path(__file__).parent / "data" / "study"
MODEL = DATA / "jeffcott.toml"

MAP = f"""[study]
model = "{MODEL}"
name = "whirl map"
design = "grid"
block = 40
[vary.Omega]
range = {{ start = 0, stop = 30, num = 16 }}
[vary.d_i]
values = [0.3, 1.0, 2.0]
[compute.linearize]
"""


def _info() -> SimpleNamespace:
    return SimpleNamespace(files=[], notes=[])


def _row(page: str, name: str) -> list[str]:
    """The cells of the outputs table's row ``name``."""
    m = re.search(rf"<tr><th>{name}</th>((?:<td[^>]*>[^<]*</td>)+)</tr>", page)
    assert m, name
    return re.findall(r"<td[^>]*>([^<]*)</td>", m.group(1))


def test_stability_map_section(tmp_path: Path) -> None:
    spec_file = tmp_path / "map.toml"
    spec_file.write_text(MAP)
    info = _info()
    page = study_section(spec_file, tmp_path, info, workers=1)
    assert info.notes == []
    # the figures are files of the report, listed with it, inline and linked in the section
    for name in ("study-stability_map", "study-campbell"):
        for ext in ("svg", "png"):
            f = tmp_path / f"{name}.{ext}"
            assert f.exists() and f.stat().st_size > 1000, f
            assert f in info.files
            assert f"href='{name}.{ext}'" in page
    assert page.count("<svg") == 2 and "<?xml" not in page
    assert tmp_path / "study.nc" in info.files and "href='study.nc'" in page
    # the numbers come from the dataset written beside the report
    ds = open_study(tmp_path / "study.nc")
    mr = ds.max_real_part.values
    assert _row(page, "max_real_part") == ["1/s", f"{mr.min():.6g}", f"{mr.mean():.6g}",
                                           f"{mr.max():.6g}", str(mr.size)]
    # ... and they are right: the rotor whirls unstably above Omega = ω(1 + d_a/d_i)
    # (ω = √(k/m) = 10 rad/s, d_a = 0.5); at the threshold itself it is marginal
    Om, di = np.meshgrid(ds.Omega.values, ds.d_i.values, indexing="ij")
    threshold = 10.0 * (1 + 0.5 / di)
    unstable = int(np.sum(Om > threshold + 1e-9))
    assert not np.any(np.isclose(Om, threshold, atol=1e-9))  # no case on the boundary
    assert int((ds.verdict.values == 2).sum()) == unstable
    assert (f"asymptotically stable: {mr.size - unstable}, marginally stable: 0, "
            f"unstable: {unstable}") in page
    assert "Failed cases (0)" in page and "Omega from 0 to 30" in page


def test_monte_carlo_histograms_section(tmp_path: Path) -> None:
    spec = load_study(DATA / "montecarlo.toml")
    info = _info()
    page = study_section(spec, tmp_path, info, workers=1)
    ds = open_study(tmp_path / "study.nc")
    x = ds.max_abs_x.values
    f = tmp_path / "study-histogram_max_abs_x.svg"
    assert f.exists() and f in info.files and "href='study-histogram_max_abs_x.svg'" in page
    assert _row(page, "max_abs_x")[1:] == [f"{x.min():.6g}", f"{x.mean():.6g}", f"{x.max():.6g}",
                                           "40"]
    assert "random design of 40 cases, seed 2026" in page
    # the section's table is output_summary's: every scalar output of the dataset, once
    names = [r[0] for r in output_summary(ds)]
    assert names == sorted(set(names), key=names.index) and "max_abs_x" in names
    assert all(f"<tr><th>{n}</th>" in page for n in names)


def test_a_study_that_cannot_run_is_a_note(tmp_path: Path) -> None:
    info = _info()
    page = study_section(tmp_path / "missing.toml", tmp_path, info)
    assert "could not be run" in page and "missing.toml" in page
    assert len(info.notes) == 1 and "missing.toml" in info.notes[0]
    assert info.files == []


def test_jourdain_run_with_a_study(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    """``jourdain run MODEL --study STUDY``: the model's report holds the study's section, its
    figures are files of the report (listed in its Files section and in run.json)."""
    import json

    from jourdain.cli import main

    spec_file = tmp_path / "map.toml"
    spec_file.write_text(MAP.replace(f'model = "{MODEL}"\n', ""))  # the model: the report's
    out = tmp_path / "report"
    assert main(["run", str(MODEL), "--out", str(out), "--study", str(spec_file)]) == 0
    printed = capsys.readouterr().out
    page = (out / "report.html").read_text()
    assert "Parameter study: whirl map" in page
    assert page.index("Parameter study") > page.index("<h2>5.")  # after the simulation
    files = json.loads((out / "run.json").read_text())["files"]
    for name in ("study.nc", "study-stability_map.svg", "study-campbell.png"):
        assert (out / name).exists() and name in files
        assert f"href='{name}'" in page
    ds = open_study(out / "study.nc")
    assert ds.attrs["model_file"] == str(MODEL)
    mr = ds.max_real_part.values
    assert _row(page, "max_real_part")[1:4] == [f"{mr.min():.6g}", f"{mr.mean():.6g}",
                                                f"{mr.max():.6g}"]
    unstable = int((ds.verdict.values == 2).sum())
    assert f"study whirl map: 48 cases (grid), {unstable} unstable; results in study.nc" in printed
    # a study file with a mistake stops the command before the report, naming the file
    bad = tmp_path / "bad.toml"
    bad.write_text('[study]\ndesign = "sobol"\n[compute.linearize]\n')
    assert main(["run", str(MODEL), "--out", str(tmp_path / "r2"), "--study", str(bad)]) != 0
    assert "bad.toml" in capsys.readouterr().err and not (tmp_path / "r2" / "report.html").exists()
