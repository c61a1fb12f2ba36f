"""Install and test hygiene (issue 17, items 13 and 14)."""

import os
import re
from pathlib import Path

from jourdain.numeric import cache_dir

ROOT = Path(__file__).resolve().parents[1]


def test_tests_compile_into_a_temporary_cache_not_the_users():
    user = Path.home() / ".cache" / "jourdain"
    assert cache_dir().resolve() != user.resolve()
    assert os.environ["JOURDAIN_CACHE"] == str(cache_dir())


def test_make_run_installs_jourdain_without_the_test_tools():
    make = (ROOT / "Makefile").read_text()
    run_deps = re.search(r"^run: (.+)$", make, re.M).group(1).split()
    assert run_deps == ["$(BIN)/.installed-run"]
    rule = make.split("$(BIN)/.installed-run: pyproject.toml", 1)[1].split("\n\n", 1)[0]
    assert "pip install --quiet -e ." in rule and "[test]" not in rule
    # and it can run twice (the report of an earlier run is replaced)
    assert "--out report/ --force" in make


def test_make_test_says_before_it_installs_a_browser_and_can_skip_it():
    make = (ROOT / "Makefile").read_text()
    browser = re.search(r"^browser:\n(.*?)\n\n", make, re.M | re.S).group(1)
    assert browser.index('echo "installing chromium') < browser.index("apt-get install")
    assert "NO_BROWSER" in browser


def test_readme_links_point_into_the_project():
    readme = (ROOT / "README.md").read_text()
    assert "METHOD.md §" not in readme  # the seed's METHOD.md is not in the project
    for target in re.findall(r"\]\(([^)#]+)\)", readme):
        if not target.startswith("http"):
            assert (ROOT / target).exists(), target


def _extras() -> dict[str, set[str]]:
    """Each extra of pyproject.toml with the extras it includes (``jourdain[a,b]``), resolved."""
    import tomllib

    deps = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"][
        "optional-dependencies"]

    def resolve(name: str, seen: frozenset[str] = frozenset()) -> set[str]:
        out = {name}
        for req in deps[name]:
            m = re.match(r"jourdain\[([^\]]+)\]", req)
            if m:
                for sub in m.group(1).split(","):
                    if sub.strip() not in seen:
                        out |= resolve(sub.strip(), seen | {name})
        return out

    return {name: resolve(name) for name in deps}


def test_each_make_target_installs_the_extras_it_uses():
    """``make docs`` on a fresh clone (issue 38, item 9): the site's build runs every example
    (the gallery: URDF models need the urdf extra) and the tutorials (the parameter study
    needs the study extra), so the docs extra brings both; ``make test`` (and ``make bench``,
    on the same install) runs every command, so the test extra brings every extra the
    package imports (jourdain.extras)."""
    from jourdain.extras import EXTRAS

    extras = _extras()
    docs_needs = {"study"} if any("jourdain.study" in p.read_text() or "jd.study" in p.read_text()
                                  for p in (ROOT / "docs" / "tutorials").glob("*.py")) else set()
    if list((ROOT / "examples").glob("*.urdf")):
        docs_needs.add("urdf")
    assert docs_needs <= extras["docs"], docs_needs - extras["docs"]
    runtime = set(EXTRAS) - {"docs"}
    assert runtime <= extras["test"], runtime - extras["test"]
    make = (ROOT / "Makefile").read_text()

    def prerequisites(target: str) -> set[str]:
        m = re.search(rf"^{re.escape(target)}:(.*)$", make, re.M)
        direct = set(m.group(1).replace("|", " ").split()) if m else set()
        return direct.union(*(prerequisites(d) for d in direct)) if direct else set()

    for target, stamp, extra in (("docs", ".installed-docs", "[docs]"),
                                 ("test", ".installed", "[test]"),
                                 ("bench", ".installed", "[test]")):
        deps = prerequisites(target)
        assert f"$(BIN)/{stamp}" in deps, (target, deps)
        rule = make.split(f"$(BIN)/{stamp}: pyproject.toml", 1)[1].split("\n\n", 1)[0]
        assert f'pip install --quiet -e ".{extra}"' in rule, (target, rule)


def test_ci_builds_the_docs_in_an_environment_of_their_own():
    """CI's ``make test`` installs the test extra into .venv; the docs are built in another
    virtual environment that has only the docs extra, so that a dependency the docs lack is
    found by CI, not by the next fresh clone."""
    ci = (ROOT / ".ci" / "run").read_text()
    m = re.search(r"^make docs VENV=(\S+)", ci, re.M)
    assert m and m.group(1) not in (".venv", "$(VENV)"), ci
    assert ci.index("make test") < ci.index("make docs VENV=")
    make = (ROOT / "Makefile").read_text()
    clean = re.search(r"^clean:\n(.*?)(?:\n\n|\Z)", make, re.M | re.S).group(1)
    assert m.group(1) in clean, "make clean leaves the docs' environment behind"
