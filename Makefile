# Quick start:  make demo   (set up rjcad alone, then build the default design into out/)
#               make test   (set up rjcad and its test tools, then run the whole test suite, slow tests included)
#               make test-fast   (before every commit: the suite without the slow tests, one real joint build kept)
#               make docs   (the user guide, docs/, built by MkDocs into site/; warnings are errors)
#               make docs-examples   (run README.md's and docs/'s examples and rewrite the outputs that changed)
PYTHON ?= python3
VENV   ?= .venv
PY     ?= $(VENV)/bin/python
PYTEST_ARGS ?=
# test processes (pytest-xdist): one per core, at most 4 (each imports OCP; the CAD tests are CPU-bound)
JOBS ?= $(shell n=$$(nproc 2>/dev/null || echo 1); [ $$n -gt 4 ] && n=4; echo $$n)

.PHONY: demo test test-fast pytest lint bench clean docs docs-examples docs-images paper-finger paper-campaign \
	identify-doc mujoco-doc vendor

# three.js for `rjcad view`'s pages, from the npm registry (pinned by version and integrity; MIT licence kept
# beside it; tools/vendor_three.py, which a wheel's build runs too); not committed.
VENDOR = rjcad/data/vendor

# Two set-ups: rjcad alone (make demo), and with the test extra (the suite, lint and docs tools) on top.
$(VENV)/.installed: pyproject.toml
	$(PYTHON) -c 'import sys; assert sys.version_info >= (3, 11), "rjcad needs Python >= 3.11"'
	$(PYTHON) -m venv $(VENV)
	$(VENV)/bin/pip install --quiet --upgrade pip
	$(VENV)/bin/pip install --quiet -e .
	$(MAKE) --no-print-directory vendor || echo "warning: could not fetch three.js; rjcad view will say so"
	touch $@

$(VENV)/.installed-test: $(VENV)/.installed
	$(VENV)/bin/pip install --quiet -e '.[test]'
	touch $@

vendor: $(VENDOR)/three.module.min.js

$(VENDOR)/three.module.min.js:
	$(PYTHON) tools/vendor_three.py $(VENDOR)

demo: $(VENV)/.installed
	$(VENV)/bin/rjcad finger templates/finger.toml --out out/finger

# the user guide as a web site in site/ (mkdocs.yml; any warning, such as a broken link, fails the build)
docs: $(VENV)/.installed-test
	NO_MKDOCS_2_WARNING=1 $(VENV)/bin/mkdocs build --strict --site-dir site

# run every example of README.md and docs/ (tools/docs_examples.py) and rewrite the output lines that changed;
# review the diff. PAGES=docs/spring.md: that page only.
docs-examples: $(VENV)/.installed-test
	$(PY) tools/docs_examples.py --write $(PAGES)

# regenerate the images the README and docs/grasp.md show
docs-images: $(VENV)/.installed
	$(VENV)/bin/rjcad joint --config templates/joint.toml --out out/joint
	$(VENV)/bin/rjcad finger templates/finger.toml --out out/finger --html
	mkdir -p docs && cp out/joint/joint.png docs/joint.png && cp out/finger/finger.png docs/finger.png
	$(VENV)/bin/rjcad simulate finger out/finger/finger.json --object cylinder:diameter=40,x=20,y=32 --plot docs/grasp.png

test: $(VENV)/.installed-test
	$(MAKE) --no-print-directory pytest

# lint (ruff: rules and formatting) and types (mypy); both configured in pyproject.toml
lint: $(VENV)/.installed-test
	$(VENV)/bin/ruff check rjcad tests benchmarks tools
	$(VENV)/bin/ruff format --check rjcad tests benchmarks tools
	$(VENV)/bin/mypy

# the fast lane: `-m 'not slow'` (tests/conftest.py marks the slow tests); under 2 minutes on 2 cores
test-fast: $(VENV)/.installed-test
	$(MAKE) --no-print-directory pytest PYTEST_ARGS="-m 'not slow' $(PYTEST_ARGS)"

# pytest's exit code 5 (nothing collected) is not a failure; every other non-zero is. worksteal: an idle worker
# takes tests queued on the other, so that no long test waits behind short ones (tests/conftest.py deals the
# longest out first).
pytest:
	$(PY) -m pytest -n $(JOBS) --dist worksteal --durations=10 $(PYTEST_ARGS) || \
	  { rc=$$?; [ $$rc -eq 5 ] && echo "pytest collected no tests" || exit $$rc; }

bench: $(VENV)/.installed-test
	@for b in benchmarks/[!_]*.py; do echo "== $$b"; $(PY) $$b || exit 1; done

clean:
	rm -rf $(VENV) out/* site .pytest_cache .hypothesis

# docs/paper-finger.md and its plot, every number computed
paper-finger: $(VENV)/.installed
	$(VENV)/bin/rjcad paper-finger --out docs --records

# docs/mujoco.md, its plot and mujoco.json: the paper's finger in MuJoCo against rjcad, every number computed
mujoco-doc: $(VENV)/.installed-test
	$(VENV)/bin/python -m rjcad.mjcf.doc docs

# examples/paper_campaign: the SYNTHETIC paper campaign (experiments A-E), seed 7
paper-campaign: $(VENV)/.installed
	$(VENV)/bin/rjcad bench --paper --out examples/paper_campaign --seed 7

# docs/identify/: the report that docs/identify.md walks through
identify-doc: $(VENV)/.installed
	$(VENV)/bin/rjcad identify examples/paper_campaign --report docs/identify --json > docs/identify/result.json
