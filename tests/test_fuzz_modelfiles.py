"""Issue 33 (the fuzz test): a few hundred seeded mutants of ``examples/*.toml`` — numbers
replaced by extremes (1e-320, 1e308, -1e308, 0, nan, inf, subnormals), keys deleted or
duplicated, values truncated or made 5 000 characters long — each run through ``jourdain
check`` (a tenth through ``jourdain eval --json``). Every one must end with exit status 0, 1 or
2, no traceback, no Python warning echoed with its source line, and within a time bound (no
hang).

The mutants run in-process through :func:`jourdain.cli.main` in a worker process that reports
each case as it finishes: fast (most mutants share their model's compiled code), and a case
that hangs in C (where no signal is looked at) or crashes the interpreter is detected by the
watchdog here, which kills the worker and starts a new one at the next case.
"""

from __future__ import annotations

import json
import os
import random
import re
import select
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = sorted((ROOT / "examples").glob("*.toml"))

#: the number of mutants and the seed (the same mutants on every run)
N_MUTANTS = 300
SEED = 33
#: seconds one case may take before it counts as a hang (a compile on a loaded machine
#: included; a case takes milliseconds to a second)
CASE_TIMEOUT = 25.0

EXTREMES = ["1e-320", "5e-324", "1e-310", "1e308", "-1e308", "1.7976931348623157e308", "0",
            "-0.0", "nan", "inf", "-inf", "1e300", "1e-300"]
STRING_EXTREMES = ['"nan"', '"inf"', '"-inf"', '"1e309"', '"1e-320"', '"0/0"']
NUMBER = re.compile(r"(?<![\w.])-?(?:\d+\.\d*|\.\d+|\d+)(?:[eE][-+]?\d+)?(?![\w.])")
KEY_LINE = re.compile(r"^\s*[A-Za-z_][\w-]*\s*=")


def _numbers(lines: list[str]) -> list[tuple[int, int, int, bool]]:
    """Every number in the file: (line, start, end, in [parameters])."""
    out = []
    table = ""
    for i, line in enumerate(lines):
        code = line.split("#", 1)[0] if '"' not in line else line
        if line.lstrip().startswith("["):
            table = line.strip()
        if line.lstrip().startswith("#"):
            continue
        for m in NUMBER.finditer(code):
            out.append((i, m.start(), m.end(), table == "[parameters]"))
    return out


def mutant(text: str, rng: random.Random) -> tuple[str, str]:
    """One mutation of a model file's text and what it was."""
    lines = text.splitlines()
    kind = rng.choices(["parameter", "number", "delete", "duplicate", "truncate", "long",
                        "string"], weights=[45, 14, 12, 7, 12, 4, 6])[0]
    numbers = _numbers(lines)
    keys = [i for i, ln in enumerate(lines) if KEY_LINE.match(ln)]
    if kind in ("parameter", "number"):
        pool = [n for n in numbers if n[3] == (kind == "parameter")] or numbers
        i, a, b, _ = rng.choice(pool)
        new = rng.choice(EXTREMES)
        in_string = lines[i][:a].count('"') % 2 == 1
        if new in ("nan", "inf", "-inf") and in_string and rng.random() < 0.5:
            new = {"nan": "0/0", "inf": "1/0", "-inf": "-1/0"}[new]
        what = f"line {i + 1}: {lines[i][a:b]} -> {new}"
        lines[i] = lines[i][:a] + new + lines[i][b:]
    elif kind == "delete":
        i = rng.choice(keys)
        what = f"line {i + 1} deleted: {lines[i][:60]}"
        del lines[i]
    elif kind == "duplicate":
        i = rng.choice(keys + [j for j, ln in enumerate(lines) if ln.startswith("[")])
        what = f"line {i + 1} duplicated: {lines[i][:60]}"
        lines.insert(i + 1, lines[i])
    elif kind == "truncate":
        i = rng.choice(keys)
        cut = rng.randrange(lines[i].index("=") + 1, len(lines[i]) + 1)
        what = f"line {i + 1} cut at {cut}: {lines[i][:cut][:60]}"
        lines[i] = lines[i][:cut]
    elif kind == "long":
        i = rng.choice(keys)
        key = lines[i].split("=", 1)[0]
        what = f"line {i + 1}: a 5000-character value for {key.strip()}"
        lines[i] = key + '= "' + "x@" * 2500 + '"'
    else:
        i, a, b, _ = rng.choice(numbers)
        new = rng.choice(STRING_EXTREMES)
        if lines[i][:a].count('"') % 2 == 1:
            new = new.strip('"')
        what = f"line {i + 1}: {lines[i][a:b]} -> {new}"
        lines[i] = lines[i][:a] + new + lines[i][b:]
    return "\n".join(lines) + "\n", f"{kind}: {what}"


def mutants(folder: Path, n: int = N_MUTANTS, seed: int = SEED) -> list[dict]:
    """``n`` mutants written to ``folder``, each with its command line."""
    rng = random.Random(seed)
    texts = {p: p.read_text() for p in EXAMPLES}
    cases = []
    for k in range(n):
        source = EXAMPLES[k % len(EXAMPLES)]
        text, what = mutant(texts[source], rng)
        path = folder / f"{k:03d}-{source.name}"
        path.write_text(text)
        command = ["eval", str(path), "--json"] if k % 10 == 7 else ["check", str(path)]
        cases.append({"k": k, "what": f"{source.name}, {what}", "argv": command})
    return cases


#: the worker: runs the cases it is given on its stdin, one JSON line each, in this process
WORKER = r"""
import contextlib, io, json, sys, traceback, warnings
from jourdain.cli import main
for line in sys.stdin:
    case = json.loads(line)
    out, err = io.StringIO(), io.StringIO()
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            code = main(case["argv"])
    except SystemExit as exc:  # argparse's usage errors
        code = exc.code
    except BaseException:
        code = None
        err.write(traceback.format_exc())
    print(json.dumps({"k": case["k"], "code": code, "err": err.getvalue()[-3000:]}),
          flush=True)
"""


def run_cases(cases: list[dict], timeout: float = CASE_TIMEOUT) -> dict[int, dict]:
    """Each case's exit status and stderr; ``code`` "hang" (no answer within ``timeout``, the
    worker killed) or "crash" (the worker died)."""
    results: dict[int, dict] = {}
    todo = list(cases)
    env = {**os.environ, "PYTHONWARNINGS": "default"}
    while todo:
        proc = subprocess.Popen([sys.executable, "-c", WORKER], stdin=subprocess.PIPE,
                                stdout=subprocess.PIPE, stderr=subprocess.DEVNULL, text=True,
                                env=env, cwd=ROOT)
        assert proc.stdin is not None and proc.stdout is not None
        for case in todo:
            proc.stdin.write(json.dumps(case) + "\n")
        proc.stdin.close()
        try:
            while todo:
                ready, _, _ = select.select([proc.stdout], [], [], timeout)
                if not ready:
                    results[todo[0]["k"]] = {"code": "hang", "err": ""}
                    todo.pop(0)
                    break
                line = proc.stdout.readline()
                if not line:  # the worker died in the middle of a case
                    results[todo[0]["k"]] = {"code": "crash", "err": f"rc {proc.wait()}"}
                    todo.pop(0)
                    break
                done = json.loads(line)
                assert done["k"] == todo[0]["k"]
                results[done["k"]] = done
                todo.pop(0)
        finally:
            proc.kill()
            proc.wait()
    return results


def problems(cases: list[dict], results: dict[int, dict]) -> list[str]:
    out = []
    for case in cases:
        r = results[case["k"]]
        err = r["err"]
        bad = []
        if r["code"] not in (0, 1, 2):
            bad.append(f"exit {r['code']}")
        if "Traceback" in err:
            bad.append("traceback")
        if re.search(r"\w+Warning: ", err) and re.search(r"\n {2}\S", err):
            bad.append("a warning with its source line")
        if max((len(ln) for ln in err.splitlines()), default=0) > 2000:
            bad.append("a message line of more than 2000 characters")
        if bad:
            out.append(f"{case['k']:03d} {case['what']} ({' '.join(case['argv'][:1])}): "
                       f"{', '.join(bad)}\n    {err.strip()[-600:]}")
    return out


def test_mutated_examples_end_cleanly(tmp_path):
    cases = mutants(tmp_path)
    start = time.monotonic()
    results = run_cases(cases)
    found = problems(cases, results)
    codes = [str(results[c["k"]]["code"]) for c in cases]
    summary = {c: codes.count(c) for c in sorted(set(codes))}
    assert not found, (f"{len(found)} of {len(cases)} mutants failed ({summary}, "
                       f"{time.monotonic() - start:.0f} s):\n" + "\n".join(found))


def test_the_mutants_are_the_same_on_every_run(tmp_path):
    a = mutants(tmp_path / "a", n=40) if (tmp_path / "a").mkdir() is None else []
    b = mutants(tmp_path / "b", n=40) if (tmp_path / "b").mkdir() is None else []
    assert [c["what"] for c in a] == [c["what"] for c in b]
    kinds = {c["what"].split(", ", 1)[1].split(":", 1)[0] for c in mutants(tmp_path / "a")}
    assert kinds == {"parameter", "number", "delete", "duplicate", "truncate", "long", "string"}


if __name__ == "__main__":  # counts for the note: python tests/test_fuzz_modelfiles.py
    import tempfile

    with tempfile.TemporaryDirectory() as d:
        cases = mutants(Path(d), n=int(sys.argv[1]) if len(sys.argv) > 1 else N_MUTANTS)
        t0 = time.monotonic()
        res = run_cases(cases)
        found = problems(cases, res)
        codes = [str(res[c["k"]]["code"]) for c in cases]
        print({c: codes.count(c) for c in sorted(set(codes))}, f"{time.monotonic() - t0:.0f} s")
        print("\n".join(found))
