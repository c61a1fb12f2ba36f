"""Time to refuse or read hostile model files (issue 17, item 3; issue 38, item 1).

The tests in ``tests/test_hostile_modelfiles.py`` check what happens to each hostile file
(the message, the line, the key; what is read; the Python lines executed; a child process's
memory and processor limits); how long it takes is measured here, where a loaded machine
changes a number rather than a verdict. Each case is timed as the best of ``--repeat`` runs:

- ``under_limit``: a 3.4 MB file of 80 000 parameters with a mistake at its end, read and the
  mistake located (``load_model``);
- ``too_large``: a 50 MB file refused (``load_model``: the first 4 MB + 1 byte read);
- ``key_lines``: the key-to-line map of 3 MB of comments and strings around a small model;
- ``display``: ``repr`` of ``spatial_chain(4)``'s M (summarized: too large to read).

    .venv/bin/python benchmarks/hostile_files.py
    .venv/bin/python benchmarks/hostile_files.py --repeat 1 --json out.json
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import tempfile
import time
from collections.abc import Callable
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

# the model file of tests/test_hostile_modelfiles.py (the same hostile cases, timed here)
from tests.test_hostile_modelfiles import BASE  # noqa: E402


def best(fn: Callable[[], object], repeat: int) -> float:
    """Best wall time of ``fn()`` over ``repeat`` runs, in seconds."""
    t = math.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        t = min(t, time.perf_counter() - t0)
    return t


def _refused(path: Path) -> None:
    from jourdain.io import ModelFileError, load_model

    try:
        load_model(path)
    except ModelFileError:
        return
    raise AssertionError(f"{path} was not refused")


def main(argv: list[str] | None = None) -> dict[str, float]:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args(argv)

    from jourdain.io.toml_positions import key_lines
    from jourdain.models import spatial_chain

    times: dict[str, float] = {}
    with tempfile.TemporaryDirectory() as tmp:
        params = "".join(f"p{i} = {{ value = {i}.5, unit = \"kg\" }}\n" for i in range(80_000))
        under = Path(tmp) / "under.toml"
        under.write_text(BASE.replace("[parameters]\n", "[parameters]\n" + params).replace(
            'axis = "z" }', 'axis = "w" }'))
        times["under_limit"] = best(lambda: _refused(under), args.repeat)
        big = Path(tmp) / "big.toml"
        with open(big, "w") as fh:
            fh.write(BASE)
            line = "# " + "x" * 98 + "\n"
            fh.write(line * (50_000_000 // len(line)))
        times["too_large"] = best(lambda: _refused(big), args.repeat)
    text = ("# " + "c" * 1_000_000 + "\n" + 'd = "' + "s" * 1_000_000 + '"\n'
            + "e = '''" + "m\n" * 500_000 + "'''\n" + BASE)
    times["key_lines"] = best(lambda: key_lines(text), args.repeat)
    M = spatial_chain(4).equations_of_motion().M
    times["display"] = best(lambda: repr(M), args.repeat)
    print("| case | best of", args.repeat, "/ s |\n| --- | --- |")
    for name, t in times.items():
        print(f"| {name} | {t:.3f} |")
    if args.json:
        args.json.write_text(json.dumps(times, indent=1))
    return times


if __name__ == "__main__":
    main()
