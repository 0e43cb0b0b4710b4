# Quick start:  make demo   (set up, then build the default design into out/)
#               make test   (set up, then run the whole test suite, slow tests included)
#               make test-fast   (before every commit: the suite without the slow tests, one real joint build kept)
PYTHON ?= python3
VENV   ?= .venv
PY     ?= $(VENV)/bin/python
PYTEST_ARGS ?=
# test processes (pytest-xdist): one per core, at most 4 (each imports OCP; the CAD tests are CPU-bound)
JOBS ?= $(shell n=$$(nproc 2>/dev/null || echo 1); [ $$n -gt 4 ] && n=4; echo $$n)

.PHONY: demo test test-fast pytest lint bench clean docs-images paper-finger paper-campaign identify-doc mujoco-doc vendor

# three.js for `rjcad view`'s pages, from the npm registry (pinned by version and integrity; MIT licence kept
# beside it; tools/vendor_three.py, which a wheel's build runs too); not committed.
VENDOR = rjcad/data/vendor

$(VENV)/.installed: pyproject.toml
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "rjcad needs Python >= 3.11"'
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -e '.[test]'
	$(MAKE) --no-print-directory vendor || echo "warning: could not fetch three.js; rjcad view will say so"
	touch $@

vendor: $(VENDOR)/three.module.min.js

$(VENDOR)/three.module.min.js:
	$(PYTHON) tools/vendor_three.py $(VENDOR)

demo: $(VENV)/.installed
	$(VENV)/bin/rjcad finger templates/finger.toml --out out/finger

# regenerate the images the README and docs/grasp.md show
docs-images: $(VENV)/.installed
	$(VENV)/bin/rjcad joint --config templates/joint.toml --out out/joint
	$(VENV)/bin/rjcad finger templates/finger.toml --out out/finger --html
	mkdir -p docs && cp out/joint/joint.png docs/joint.png && cp out/finger/finger.png docs/finger.png
	$(VENV)/bin/rjcad simulate finger out/finger/finger.json --object cylinder:diameter=40,x=20,y=32 --plot docs/grasp.png

test: $(VENV)/.installed
	$(MAKE) --no-print-directory pytest

# lint (ruff: rules and formatting) and types (mypy); both configured in pyproject.toml
lint: $(VENV)/.installed
	$(VENV)/bin/ruff check rjcad tests benchmarks tools
	$(VENV)/bin/ruff format --check rjcad tests benchmarks tools
	$(VENV)/bin/mypy

# the fast lane: `-m 'not slow'` (tests/conftest.py marks the slow tests); under 2 minutes on 2 cores
test-fast: $(VENV)/.installed
	$(MAKE) --no-print-directory pytest PYTEST_ARGS="-m 'not slow' $(PYTEST_ARGS)"

# pytest's exit code 5 (nothing collected) is not a failure; every other non-zero is. worksteal: an idle worker
# takes tests queued on the other, so that no long test waits behind short ones (tests/conftest.py deals the
# longest out first).
pytest:
	$(PY) -m pytest -n $(JOBS) --dist worksteal --durations=10 $(PYTEST_ARGS) || \
	  { rc=$$?; [ $$rc -eq 5 ] && echo "pytest collected no tests" || exit $$rc; }

bench: $(VENV)/.installed
	@for b in benchmarks/[!_]*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) out/* .pytest_cache .hypothesis

# docs/paper-finger.md and its plot, every number computed
paper-finger: $(VENV)/.installed
	$(VENV)/bin/rjcad paper-finger --out docs --records

# docs/mujoco.md, its plot and mujoco.json: the paper's finger in MuJoCo against rjcad, every number computed
mujoco-doc: $(VENV)/.installed
	$(VENV)/bin/python -m rjcad.mjcf.doc docs

# examples/paper_campaign: the SYNTHETIC paper campaign (experiments A-E), seed 7
paper-campaign: $(VENV)/.installed
	$(VENV)/bin/rjcad bench --paper --out examples/paper_campaign --seed 7

# docs/identify/: the report that docs/identify.md walks through
identify-doc: $(VENV)/.installed
	$(VENV)/bin/rjcad identify examples/paper_campaign --report docs/identify --json > docs/identify/result.json
