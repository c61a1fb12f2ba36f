# Two entry points for a fresh machine (Python 3.11+, a C compiler):
#   make run   - create .venv, install jourdain, run the main job on the default example
#   make test  - create .venv, install jourdain with test extras, run ruff, mypy (src/, configured
#                in pyproject.toml) and the test suite
#                (twice: PYTHONHASHSEED=0 with OPENBLAS_NUM_THREADS=1, and PYTHONHASHSEED=12345)
#   make docs  - install jourdain with the docs extra and build the documentation site into
#                site/ (mkdocs build --strict: offline, warnings are errors; see mkdocs.yml)
#   make bench - every benchmark script in its quick mode (not part of make test; the full runs
#                and their options are in each script's docstring)
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin

.PHONY: run test lint clean browser bench viewer-assets docs

$(BIN)/python:
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip

# the main job needs jourdain only; the test tools (Pinocchio, PyDy, Cython: most of a 1 GB
# environment) are installed by the test target
$(BIN)/.installed-run: pyproject.toml setup.py | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e .
	touch $@

$(BIN)/.installed: pyproject.toml setup.py | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $@ $(BIN)/.installed-run

run: $(BIN)/.installed-run
	$(BIN)/jourdain run examples/double_pendulum.toml --out report/ --force

lint: $(BIN)/.installed
	$(BIN)/ruff check src tests benchmarks
	$(BIN)/mypy

# headless Chromium for the report's browser test: installed when missing and running as root
# with apt-get (NO_BROWSER=1 skips the install); otherwise that one test is skipped with the reason
browser:
	@[ -n "$(NO_BROWSER)" ] && echo "NO_BROWSER set: the report's browser test will be skipped" || \
	command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	{ if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing chromium (Debian package, apt-get) for the report's browser test;" \
	         "NO_BROWSER=1 make test skips it"; \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium) \
	      >/dev/null 2>&1 || echo "chromium could not be installed: the browser test will be skipped"; \
	  else echo "chromium not found and not root: the report's browser test will be skipped"; fi; }

# the suite twice, with different hash seeds (set and dict order) and BLAS threading, so that a
# result that depends on either fails here rather than on another machine (tests/README.md)
# (the compiled libraries go to a cache in the project, shared by the two runs and removed by
# make clean, never to the user's ~/.cache/jourdain; compiled at -O1, JOURDAIN_OPTIMIZE=1: the
# same numbers bit for bit as the default -O2, tests/test_native.py, in a quarter of the
# compiler's time, which was most of the suite's). Each run in TEST_WORKERS processes
# (pytest-xdist, whole files per process; the cache is safe for concurrent builds);
# TEST_WORKERS=0 runs in one process.
TEST_WORKERS ?= 2
test: lint browser
	PYTHONHASHSEED=0 OPENBLAS_NUM_THREADS=1 JOURDAIN_TEST_CACHE=$(CURDIR)/.jourdain-test-cache \
	  JOURDAIN_OPTIMIZE=1 $(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile
	PYTHONHASHSEED=12345 JOURDAIN_TEST_CACHE=$(CURDIR)/.jourdain-test-cache \
	  JOURDAIN_OPTIMIZE=1 $(BIN)/python -m pytest -q -n $(TEST_WORKERS) --dist loadfile

# the documentation site (mkdocs.yml): tutorials executed and every example run for the gallery
# at each build, so a change of the code that breaks either fails here; compiled libraries in a
# cache of the project (removed by make clean); MkDocs' own notices about its future silenced
$(BIN)/.installed-docs: pyproject.toml setup.py | $(BIN)/python
	$(BIN)/python -m pip install --quiet -e ".[docs]"
	touch $@ $(BIN)/.installed-run

docs: $(BIN)/.installed-docs
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true \
	  JOURDAIN_CACHE=$(CURDIR)/.jourdain-docs-cache $(BIN)/mkdocs build --strict

# quick modes only: a few minutes in all; timings from a quick run are not the reported numbers
bench: $(BIN)/.installed
	$(BIN)/python benchmarks/derivation.py --quick
	$(BIN)/python benchmarks/linearization.py --quick
	$(BIN)/python benchmarks/reactions.py --n 3 --states 50
	$(BIN)/python benchmarks/simulation.py --quick --rounds 3
	$(BIN)/python benchmarks/crosscheck.py --n 3 --tree 3 --states 1
	$(BIN)/python benchmarks/scaling.py --quick
	$(BIN)/python benchmarks/per_state.py --quick
	$(BIN)/python benchmarks/derivatives.py --quick
	$(BIN)/python benchmarks/study.py --quick
	$(BIN)/python benchmarks/loops.py --units --T 1
	$(BIN)/python benchmarks/hostile_files.py --repeat 1
	$(BIN)/python benchmarks/rolling.py --quick
	$(BIN)/python benchmarks/per_call.py --repeat 50
	$(BIN)/python benchmarks/setup.py --quick
	mkdir -p build
	$(BIN)/python benchmarks/peers.py --tiny --json build/peers.json
	$(BIN)/python benchmarks/elastic.py --tiny --json build/elastic.json

# the 3-D view's three.js bundle (src/jourdain/io/viewer/three_bundle.js, committed): rebuilt from
# the npm versions pinned in tools/viewer/package-lock.json; needs node and npm, nothing else does
viewer-assets:
	tools/build_viewer.sh

clean:
	rm -rf $(VENV) .venv-docs .pytest_cache .ruff_cache .jourdain-test-cache .jourdain-docs-cache site \
	  src/jourdain/numeric/prebuilt
