# The two commands of the README: `make demo` and `make test`.
# Each builds .venv from requirements.lock (exact versions, hashes) when it is missing or older
# than the lock or pyproject.toml; `make lock` regenerates the lock from pyproject.toml.
PYTHON ?= $(shell command -v python3.11 || command -v python3)
VENV := .venv
STAMP := $(VENV)/.installed
LOCK := requirements.lock
UV_VERSION := 0.13.8
# Foxglove's own WebSocket client (@foxglove/ws-protocol, run by node), which the tests of
# `parsimony view` drive: installed exactly as package-lock.json pins it.
FOXGLOVE_CLIENT := tests/foxglove_client
CLIENT_STAMP := $(FOXGLOVE_CLIENT)/node_modules/.installed

.PHONY: demo test docs bench lint lock clean foxglove-client

# Each step that takes more than a second says what it does first (pip itself is quiet).
$(STAMP): $(LOCK) pyproject.toml
	@echo "[make] building $(VENV) from $(LOCK), which it is older than or missing"
	rm -rf $(VENV)
	$(PYTHON) -m venv $(VENV)
	@echo "[make] installing the $$(grep -cE '^[A-Za-z0-9_.-]+==' $(LOCK)) packages pinned in" \
		"$(LOCK), hashes checked (about a minute the first time, quiet meanwhile)"
	$(VENV)/bin/python -m pip install --quiet --require-hashes --no-deps -r $(LOCK)
	@echo "[make] installing parsimony itself into $(VENV) (editable)"
	$(VENV)/bin/python -m pip install --quiet --no-deps --no-build-isolation -e .
	touch $(STAMP)
	@echo "[make] $(VENV) is ready"

# The pose experiment of section 6.2.1 on the whole simulated loop, in real time.
demo: $(STAMP)
	@echo "[make] the pose experiment in real time (about half a minute; its progress follows)"
	$(VENV)/bin/parsimony experiment pose --controller lp --realtime --out runs/demo --force

$(CLIENT_STAMP): $(FOXGLOVE_CLIENT)/package.json $(FOXGLOVE_CLIENT)/package-lock.json
	@echo "[make] installing Foxglove's WebSocket client for the tests as" \
		"$(FOXGLOVE_CLIENT)/package-lock.json pins it (npm ci)"
	cd $(FOXGLOVE_CLIENT) && npm ci --no-audit --no-fund --loglevel=error
	touch $(CLIENT_STAMP)

foxglove-client: $(CLIENT_STAMP)

# Three test workers on CI's two cores: many tests wait on a real-time run or a child process,
# which a third worker may fill (one core kept busy, pytest's seconds: 464 with two workers;
# 396, 457 and 489 with three: not clearly faster, the spread larger than the gain; 336, 243
# and 243 with three once launches and the component tests forked their processes from a fork
# server). Files go out in the order tests/conftest.py sorts them (the heavy ones first):
# pytest-xdist's own order (most tests first) handed out the one-test files last, the README's
# first hour among them, which then ran alone for the last minute and a half.
test: $(STAMP) $(CLIENT_STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .
	$(VENV)/bin/python -m pytest -q -n 3 --dist loadfile --no-loadscope-reorder --durations=20

# The documentation site (docs/, mkdocs.yml) into site/, strict: a broken link or a missing page
# fails. make test builds it too (tests/test_docs.py). The banners about MkDocs' future are muted.
docs: $(STAMP)
	NO_MKDOCS_2_WARNING=1 DISABLE_MKDOCS_2_WARNING=true $(VENV)/bin/mkdocs build --strict

bench: $(STAMP)
	$(VENV)/bin/parsimony bench

lint: $(STAMP)
	$(VENV)/bin/ruff check .
	$(VENV)/bin/ruff format --check .

# Resolve pyproject.toml (runtime and test dependencies, and setuptools to build the project)
# into exact versions with hashes, for every platform, on Python 3.11.
lock: $(STAMP)
	$(VENV)/bin/python -m pip install --quiet uv==$(UV_VERSION)
	printf 'setuptools>=68\n' | $(VENV)/bin/uv pip compile pyproject.toml - --extra test \
		--universal --python-version 3.11 --generate-hashes --quiet -o $(LOCK)

clean:
	rm -rf $(VENV) build site *.egg-info $(FOXGLOVE_CLIENT)/node_modules
