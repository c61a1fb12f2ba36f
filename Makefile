# Two entry points for a fresh machine (Python 3.11+, a C compiler):
#   make run   - create .venv, install jourdain, run the main job on the default example
#   make test  - create .venv, install jourdain with test extras, run ruff and the test suite
#                (twice: PYTHONHASHSEED=0 with OPENBLAS_NUM_THREADS=1, and PYTHONHASHSEED=12345)
PYTHON ?= python3
VENV   ?= .venv
BIN    := $(VENV)/bin

.PHONY: run test lint clean browser

$(BIN)/.installed: pyproject.toml
	$(PYTHON) -m venv $(VENV)
	$(BIN)/python -m pip install --quiet --upgrade pip
	$(BIN)/python -m pip install --quiet -e ".[test]"
	touch $@

run: $(BIN)/.installed
	$(BIN)/jourdain run examples/double_pendulum.toml --out report/

lint: $(BIN)/.installed
	$(BIN)/ruff check src tests benchmarks

# headless Chromium for the report's browser test: installed when missing and running as root
# with apt-get; otherwise that one test is skipped with the reason
browser:
	@command -v chromium >/dev/null 2>&1 || command -v chromium-browser >/dev/null 2>&1 || \
	{ if [ "$$(id -u)" = 0 ] && command -v apt-get >/dev/null 2>&1; then \
	    echo "installing chromium (Debian package) for the report's browser test"; \
	    (apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq chromium) \
	      >/dev/null 2>&1 || echo "chromium could not be installed: the browser test will be skipped"; \
	  else echo "chromium not found and not root: the report's browser test will be skipped"; fi; }

# the suite twice, with different hash seeds (set and dict order) and BLAS threading, so that a
# result that depends on either fails here rather than on another machine (tests/README.md)
test: lint browser
	PYTHONHASHSEED=0 OPENBLAS_NUM_THREADS=1 $(BIN)/python -m pytest -q
	PYTHONHASHSEED=12345 $(BIN)/python -m pytest -q

clean:
	rm -rf $(VENV) .pytest_cache .ruff_cache
