# Every target creates or reuses .venv and installs gearcheck (with test extras) first,
# so each one works alone on a fresh machine.
PYTHON ?= python3
VENV   ?= .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.gearcheck-installed

.PHONY: install demo studies test browser lint bench fuzz docs clean

install: $(STAMP)

$(STAMP): pyproject.toml
	test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet --upgrade pip
	$(PY) -m pip install --quiet -e '.[test]'
	touch $(STAMP)

demo: $(STAMP)
	$(PY) -m gearcheck demo --out out

# Lint and type-check first (seconds), then the suite. The browser test needs Debian's Chromium:
# installed here when missing (apt-get, as root or through sudo), and required by the suite.
test: $(STAMP) browser
	$(VENV)/bin/ruff check src bench
	$(VENV)/bin/mypy
	GEARCHECK_REQUIRE_BROWSER=1 $(PY) -m pytest -q --durations=12

browser:
	@command -v chromium >/dev/null 2>&1 || { \
	  SUDO=$$( [ "$$(id -u)" = 0 ] || echo sudo ); \
	  $$SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $$SUDO apt-get install -y -qq chromium; }

# The API reference from the docstrings (offline, no network): out/api/index.html (tests/test_docs.py
# builds the same list)
API_MODULES := gearcheck gearcheck.design gearcheck.drafting gearcheck.mechanism gearcheck.results \
	gearcheck.pipeline gearcheck.executor gearcheck.testing gearcheck.notebook gearcheck.figures gearcheck.params \
	gearcheck.sweep gearcheck.geometry gearcheck.studies gearcheck.cad

docs: $(STAMP)
	$(VENV)/bin/pdoc --docformat restructuredtext -o out/api $(API_MODULES)

lint: $(STAMP)
	$(VENV)/bin/ruff check src bench
	$(VENV)/bin/mypy

# The shipped tolerance studies at their default sizes (a few minutes): out/study_NAME/
studies: $(STAMP)
	$(PY) -m gearcheck study differential_tolerances --out out/study_differential_tolerances
	$(PY) -m gearcheck study differential_mounting --out out/study_differential_mounting
	$(PY) -m gearcheck study track_wear --out out/study_track_wear
	$(PY) -m gearcheck study steering_tolerances --out out/study_steering_tolerances

bench: $(STAMP)
	$(PY) bench/run.py --out out/bench.json

# Random parameter sets through validation, the analytical models, CAD and a sweep (out/fuzz.json,
# about 23 min on 2 cores).
fuzz: $(STAMP)
	$(PY) bench/fuzz.py

clean:
	rm -rf out/* build src/*.egg-info .pytest_cache
