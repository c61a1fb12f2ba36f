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
