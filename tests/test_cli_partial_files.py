"""Issue 17, item 4 (no result is lost): results files written as a run goes, in CSV as in
HDF5, readable at any moment; the complete file replaces the partial one through a temporary
file, so an interruption while saving never leaves a truncated file."""

import numpy as np
import pytest

import jourdain as jd
from jourdain.models import n_link_pendulum_on_cart
from jourdain.simulation.results import append_incremental, open_incremental


def _run():
    s = n_link_pendulum_on_cart(1)
    return s, s.simulate((0, 1), [0.0, 3.0], [0, 0], inputs={"F": 0.0})


def test_partial_csv_of_a_killed_run_is_readable(tmp_path):
    s, res = _run()
    h = open_incremental(tmp_path / "killed.csv", s)
    x = np.c_[res.y, res.yd, res.W]
    append_incremental(h, res.t[:10], x[:10])
    append_incremental(h, res.t[10:20], x[10:20])
    h.close()
    back = jd.Results.load(tmp_path / "killed.csv")
    assert back.status == "running" and "killed" in back.message
    np.testing.assert_array_equal(back.t, res.t[:20])
    np.testing.assert_array_equal(back.y, res.y[:20])
    np.testing.assert_array_equal(back.yd, res.yd[:20])
    np.testing.assert_array_equal(back.W, res.W[:20])
    assert np.isnan(back.ydd).all()


def test_csv_output_is_written_as_the_run_goes(tmp_path, monkeypatch):
    """simulate(output="….csv") appends each chunk of the C loop to the file: looked at from
    the progress callback, the file already holds the motion up to there."""
    s = n_link_pendulum_on_cart(1)
    out = tmp_path / "live.csv"
    seen = []

    def progress(t, t1):
        if not seen:
            part = jd.Results.load(out)
            seen.append((t, part.status, len(part.t), part.t[-1]))

    res = s.simulate((0, 20), [0.0, 3.0], [0, 0], inputs={"F": 0.0}, max_step=5e-4,
                     output=str(out), progress=progress)
    assert seen, "the run was one chunk"
    t, status, n, last = seen[0]
    assert status == "running" and n > 100 and last == pytest.approx(t)
    back = jd.Results.load(out)
    assert back.status == "finished" and len(back.t) == len(res.t)
    np.testing.assert_array_equal(back.y, res.y)


def test_an_interrupted_save_leaves_the_previous_file(tmp_path, monkeypatch):
    _, res = _run()
    for name in ("r.csv", "r.h5"):
        path = tmp_path / name
        res.save(path)
        before = path.read_bytes()

        def interrupted(*args, **kw):
            raise KeyboardInterrupt

        with monkeypatch.context() as m:
            m.setattr(np, "savetxt", interrupted)
            m.setattr(jd.Results, "_save_h5", interrupted)
            with pytest.raises(KeyboardInterrupt):
                res.save(path)
        assert path.read_bytes() == before
        assert sorted(p.name for p in tmp_path.iterdir() if p.name.startswith(".")) == []


def test_header_values_stay_on_their_line(tmp_path):
    """A message holding a line break or a terminal escape cannot shift or colour the header."""
    _, res = _run()
    res.message = "first line\nsecond \x1b[31mred"
    path = res.save(tmp_path / "r.csv")
    lines = path.read_text().splitlines()
    assert "# message: first line second \\x1b[31mred" in lines
    back = jd.Results.load(path)
    np.testing.assert_array_equal(back.y, res.y)
