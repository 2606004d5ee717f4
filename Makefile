# Two commands for everyone: `make lab` (JupyterLab on the course) and `make test`.
# Everything lives in this folder: the venv, pip's and uv's caches, Jupyter's and ROS's files.

PYTHON ?= python3
VENV   := .venv
PY     := $(VENV)/bin/python
STAMP  := $(VENV)/.installed
HERE   := $(CURDIR)

export PIP_CACHE_DIR       := $(HERE)/.cache/pip
export UV_CACHE_DIR        := $(HERE)/.cache/uv
export JUPYTER_CONFIG_DIR  := $(HERE)/.jupyter/config
export JUPYTER_DATA_DIR    := $(HERE)/.jupyter/data
export JUPYTER_RUNTIME_DIR := $(HERE)/.jupyter/runtime
export IPYTHONDIR          := $(HERE)/.jupyter/ipython
export MPLCONFIGDIR        := $(HERE)/.cache/matplotlib
export ROS_HOME            := $(HERE)/.cache/ros
export ROS_LOG_DIR         := $(HERE)/.cache/ros/log
export PIP_DISABLE_PIP_VERSION_CHECK := 1
# uv trusts the machine's certificate store, as pip does: behind a proxy that re-signs HTTPS
# (an institution's, whose CA the machine trusts), uv's own roots refuse PyPI.
export UV_SYSTEM_CERTS := 1
# numpy's OpenBLAS starts a thread per CPU that spins at import; every process with ROS imports
# numpy (rclpy's message types), and none of them does linear algebra (docs/decisions.md).
export OPENBLAS_NUM_THREADS := 1

.PHONY: image image-tool lab lab-instructor check test setup bytecode sandbox-tool browser-tool axe-tool graph-tool grading-course solutions learner-notebooks bench grade export clean docs mistakes

setup: $(STAMP)

$(STAMP): environment/requirements.txt environment/installer.txt pyproject.toml
	@$(PYTHON) -c 'import sys, platform; v = sys.version_info; \
	  ok = (3, 10) <= v[:2] <= (3, 13) and platform.system() == "Linux" and platform.machine() == "x86_64"; \
	  sys.exit(0 if ok else "The pip route needs Linux x86_64 and Python 3.10-3.13 (found %s %s, Python %d.%d); see README for RoboStack." % (platform.system(), platform.machine(), v[0], v[1]))'
	@$(PYTHON) -c 'import ensurepip, venv' 2>/dev/null || { echo "Python's venv is not installed: sudo apt install python3-venv (Debian, Ubuntu), then make again."; exit 1; }
	@if [ -e $(VENV) ] && ! $(PY) -m pip --version >/dev/null 2>&1; then \
	  echo "$(VENV) was left half-made by an earlier try: making it again."; rm -rf $(VENV); fi
	@test -x $(PY) || $(PYTHON) -m venv $(VENV)
	$(PY) -m pip install --quiet -r environment/installer.txt
	@# --compile-bytecode: uv compiles site-packages once, on every CPU; where
	@# PYTHONDONTWRITEBYTECODE is set, every process would otherwise compile what it imports
	$(VENV)/bin/uv pip install --quiet --compile-bytecode --python $(PY) -r environment/requirements.txt
	$(VENV)/bin/uv pip install --quiet --python $(PY) --no-deps --editable .
	@touch $(STAMP)

# The course's own Python compiled once, here: where PYTHONDONTWRITEBYTECODE is set (as on
# our machines) every process that imports ros2nb (kernels, judges, subjects: hundreds in
# make test) would compile it again (docs/decisions.md).  Python checks each file's source
# time and size, so a stale one is compiled again in memory, never used.
bytecode: $(STAMP)
	@$(PY) -m compileall -q src tests benchmarks conftest.py >/dev/null

# The learner's lab: the course's notebooks copied into work/ (git ignores it; a course update
# never overwrites a notebook there, it puts the new version beside it), nbgrader's instructor
# tools, the news pop-up and the Extension Manager off (environment/jupyter-learner/).
# Localhost only, token authentication on (src/ros2nb_instructor/lab.py).
LAB_ARGS ?=

lab: $(STAMP) bytecode graph-tool
	$(VENV)/bin/ros2nb-lab $(LAB_ARGS)

# The instructor's lab: the course folder itself, nbgrader's Formgrader and Create Assignment on.
lab-instructor: $(STAMP) bytecode graph-tool
	$(VENV)/bin/ros2nb-lab --instructor

# The Debian tools the lab (graphviz), some tests and grading use: installed by make when it
# runs as root, saying so first (README); else it says the one apt line, and what goes without
# them (their tests skip, saying why).
# $(call from_debian,COMMANDS,PACKAGES,WITHOUT,FOR): installs PACKAGES when a command is missing.
have_all = for command in $(1); do command -v $$command >/dev/null || exit 1; done
define from_debian
	@( $(call have_all,$(1)) ) || [ "$$(id -u)" != 0 ] || { \
	  echo "Installing $(2) from Debian with apt-get (make runs as root): $(4)"; \
	  apt-get install -y -q $(2) >/dev/null 2>&1 \
	  || { apt-get update -q >/dev/null 2>&1 && apt-get install -y -q $(2) >/dev/null 2>&1; } || true; }
	@( $(call have_all,$(1)) ) || echo "$(firstword $(2)) is not installed (sudo apt-get install $(2)): $(3)"
endef

# Grading runs learners' code in bubblewrap sandboxes.
sandbox-tool:
	$(call from_debian,bwrap,bubblewrap,grading refuses to run and its tests skip.,grading runs learners' code in its sandboxes.)

# Browser tests (Playwright) drive Debian's chromium; Playwright's own download is unreachable.
browser-tool:
	$(call from_debian,chromium,chromium,the browser tests skip.,the browser tests drive it.)

# The browser tests of the website (tests/test_docs_site.py) run axe-core, the accessibility
# engine, on every page: from npm, pinned, into .cache/node beside the hub's proxy (never
# globally), so nothing is fetched while a test runs; without npm the axe tests skip, saying why.
AXE_VERSION := 4.14.1
AXE_STAMP   := $(HERE)/.cache/node/.installed-axe-core-$(AXE_VERSION)

axe-tool:
	@test -e $(AXE_STAMP) || { command -v npm >/dev/null || { echo "npm not found (install Node.js with npm): the site's accessibility tests skip."; exit 0; }; \
	  npm install --prefix $(HERE)/.cache/node --cache $(HERE)/.cache/npm --save-exact --no-audit --no-fund --loglevel=error axe-core@$(AXE_VERSION) && touch $(AXE_STAMP) \
	  || echo "axe-core not installed (needs npm's registry): the site's accessibility tests skip."; }

# Notebook 06 draws the ROS graph with Graphviz's dot layout (as rqt_graph does).
graph-tool:
	$(call from_debian,dot,graphviz,notebook 06 lists the graph as text instead of drawing it.,notebook 06 draws the ROS graph with it.)

# The image test (tests/test_image.py) builds the course's image with podman and runc on a base
# debootstrap makes.
image-tool:
	$(call from_debian,podman runc debootstrap,podman runc debootstrap,the image test skips.,the image test builds the course's image with them.)

# The fast lane (docs/developing.md): ruff over the course's Python, mypy over all of src
# (pyproject.toml: [tool.mypy]; its cache in .cache/mypy), then the tests that need only
# Python (no ROS process, kernel, sandbox, browser, image or hub: tests/conftest.py's lanes),
# notebook structure and layer rules among them, on both cores (pytest-xdist): one process
# took a minute for its 478 tests, two take half.  Run it while you work.
check: $(STAMP) bytecode
	@$(VENV)/bin/ruff check --quiet .
	@$(PY) -m mypy
	@$(PY) -m pytest --lane check -q -n 2

# Everything: the fast lane first (a lint error or a broken rule stops here, in a minute),
# the website (make docs, which its browser test opens), then four steps, always all four
# (tests/run_steps.sh): the slow lane of tests/ with pytest-xdist, and beside it nbval over
# solutions/ and notebooks/ and the course's image built and run; one failure never hides the
# others, the results come together at the end, and make fails if any step failed.
# Six workers: much of a slow test's time is a judge and its subject waiting on each other
# step by step, and fewer left the cores idle between steps (docs/decisions.md).
TEST_WORKERS ?= 6

test: check $(STAMP) bytecode sandbox-tool browser-tool axe-tool graph-tool image-tool grading-course docs
	@tests/run_steps.sh $(PY) $(TEST_WORKERS)

# The nbgrader course of the current solutions (generate_assignment, kept per version of the
# solutions in .cache/grading-courses/), made before the tests start. Otherwise the first test
# that grades makes it, at make test's busiest moment and as the first step of the sample
# class, tests/'s longest chain, which then waits for it (docs/decisions.md).
grading-course: $(STAMP) bytecode
	@$(PY) -c 'from ros2nb_instructor.grading.scores.nbgrader_course import kept_course; kept_course()'

# The course's website (docs/site/build.py): the lessons as the learner sees them (from the
# stored outputs of solutions/, each answer an exercise with its hint, never its solution),
# the guides and the reference, in docs/_build/html; offline, nothing executed, every Sphinx
# warning an error and every link checked.  make test builds it for tests/test_docs_site.py.
# SOLUTIONS=1: the instructor's site, with the solutions, in docs/_build/instructor/html.
# DOCS_HUB_URL=https://hub.example.org/hub/user-redirect/lab/tree/notebooks/{notebook}:
# each lesson also links to itself on that JupyterHub.
docs: $(STAMP)
	@$(PY) docs/site/build.py $(if $(SOLUTIONS),--solutions --out docs/_build/instructor)

# Re-run solutions/ in place so their stored outputs are fresh (then make learner-notebooks).
solutions: $(STAMP)
	$(VENV)/bin/ros2nb-solutions

# Regenerate notebooks/ from solutions/ with nbgrader (never edit notebooks/ by hand).
learner-notebooks: $(STAMP)
	$(VENV)/bin/ros2nb-learner-notebooks

# ros2nb against bare rclpy, and grading seconds per notebook (benchmarks/bench.py).
bench: $(STAMP) bytecode sandbox-tool
	$(PY) benchmarks/bench.py $(BENCH_ARGS)

# The mutation test of the checks (benchmarks/mistakes.py): every answer cell of solutions/
# mutated by a fixed set of operators, each mutant run in a real kernel and through the
# grader's path, each answer judged; the report goes to mistakes/report.md (git-ignored).
# MISTAKES_ARGS='--notebooks 03,04 --workers 3' narrows or widens it; fails on a bad answer.
mistakes: $(STAMP) bytecode
	$(PY) benchmarks/mistakes.py $(MISTAKES_ARGS)

# Grade a class: SUBMISSIONS is a folder of <learner-id>/NN-*.ipynb or a platform .zip.
# Output goes to grading/ (git-ignored); FORCE=1 replaces an earlier grading/.
grade: $(STAMP) bytecode sandbox-tool
	@test -n "$(SUBMISSIONS)" || { echo "Usage: make grade SUBMISSIONS=DIR (DIR/<learner>/NN-title.ipynb) or SUBMISSIONS=class.zip [FORCE=1] [NO_SANDBOX=1] [SEED=N] [SCHEDULER=tcp://host:8786] [SETTINGS=course.toml] [EXTENSIONS=extensions.toml] [EXPORT=canvas|moodle|csv ROSTER=roster.csv] [LEARNER=name]"; exit 2; }
	$(VENV)/bin/ros2nb-grade "$(SUBMISSIONS)" $(if $(FORCE),--force) $(if $(NO_SANDBOX),--no-sandbox) $(if $(SEED),--seed $(SEED)) $(if $(SCHEDULER),--scheduler "$(SCHEDULER)") $(if $(SETTINGS),--settings "$(SETTINGS)") $(if $(EXTENSIONS),--extensions "$(EXTENSIONS)") $(if $(EXPORT),--export "$(EXPORT)") $(if $(ROSTER),--roster "$(ROSTER)") $(if $(LEARNER),--learner "$(LEARNER)")

# A learning platform's grade file from the existing grading (nothing graded again: the
# formgrader's manual points are kept): grading/export/<EXPORT>.csv. DUE_BY= exports the
# notebooks due by then (ISO 8601 with its offset); what is not yet due is blank, never 0.
export: $(STAMP)
	@test -n "$(EXPORT)" || { echo "Usage: make export EXPORT=canvas|moodle|csv [ROSTER=roster.csv] [DUE_BY=2026-10-20T00:00:00+02:00] [GRADING=grading] [SETTINGS=course.toml] [EXTENSIONS=extensions.toml]"; exit 2; }
	@$(VENV)/bin/ros2nb-export "$(EXPORT)" $(if $(ROSTER),--roster "$(ROSTER)") $(if $(DUE_BY),--due-by "$(DUE_BY)") $(if $(GRADING),--grading "$(GRADING)") $(if $(SETTINGS),--settings "$(SETTINGS)") $(if $(EXTENSIONS),--extensions "$(EXTENSIONS)")

clean:
	rm -rf $(VENV) .cache .jupyter

# The course as an image (environment/Containerfile), with podman or else docker:
# `make image` (IMAGE=ros2-course, BASE=a Debian 12 or Ubuntu 24.04 image, PULL=never for a
# base that is only local, IMAGE_ARGS=--no-cache or any other option of the engine's build).
IMAGE   ?= ros2-course
BASE    ?= docker.io/library/debian:bookworm
PULL    ?= missing
IMAGE_ARGS ?=
# This machine's certificate authorities, handed to the build as a secret (behind a proxy
# that re-signs HTTPS, pip needs them); an empty file when there are none.
HOST_CA ?= $(firstword $(wildcard /etc/ssl/certs/ca-certificates.crt) /dev/null)
# The wheels this checkout's set-up already downloaded (uv's cache), handed to podman's build
# as an overlay at IMAGE_UV_CACHE (the build may add to it; the host's cache is never
# written), so the image installs them without downloading them again.  docker's build takes
# no volume: there the image downloads them.
IMAGE_UV_CACHE := /var/cache/ros2-course-uv
image:
	@engine=$$(command -v podman || command -v docker) || { echo "Neither podman nor docker is installed: sudo apt install podman (Debian, Ubuntu), then make image again."; exit 1; }; \
	  cache=; if [ "$$(basename $$engine)" = podman ] && [ -d "$(UV_CACHE_DIR)" ]; then \
	    cache="--volume $(UV_CACHE_DIR):$(IMAGE_UV_CACHE):O"; fi; \
	  $$engine build --network host --pull=$(PULL) --build-arg BASE=$(BASE) $$cache $(IMAGE_ARGS) \
	    --secret id=host-ca,src=$(HOST_CA) -f environment/Containerfile -t $(IMAGE) .

# ---- Classroom server: JupyterHub on this machine (docs/classroom-server.md) --------------
# `make hub` (as root): JupyterHub on 127.0.0.1:8000 for the local users of the Unix group
# ros2-course (settings: environment/jupyterhub_config.py), with its hand-in service.
# `make hub-collect CLASS=DIR` copies what each learner handed in, with the hub's time of
# each, to DIR/<user>/ for `make grade SUBMISSIONS=DIR` (HOMES=1: their work folders as they
# are, no times); `make hub-feedback` gives each learner their own feedback pages.
# configurable-http-proxy comes from npm, pinned, into .cache/node (never globally);
# `make test` installs it when npm can, and otherwise goes on (tests/test_jupyterhub.py skips).
CHP_VERSION := 4.6.3
CHP_PREFIX  := $(HERE)/.cache/node
CHP_STAMP   := $(CHP_PREFIX)/.installed-$(CHP_VERSION)

.PHONY: hub hub-proxy hub-proxy-if-possible hub-collect hub-feedback

hub-proxy: $(CHP_STAMP)

$(CHP_STAMP):
	@command -v npm >/dev/null || { echo "npm not found: install Node.js (18 or newer) with npm, then run make hub-proxy again."; exit 1; }
	npm install --prefix $(CHP_PREFIX) --cache $(HERE)/.cache/npm --save-exact --no-audit --no-fund --loglevel=error configurable-http-proxy@$(CHP_VERSION)
	@touch $@

hub-proxy-if-possible:
	@{ command -v npm >/dev/null && $(MAKE) --no-print-directory hub-proxy; } || echo "configurable-http-proxy not installed (needs npm and its registry): tests/test_jupyterhub.py will skip."

test: hub-proxy-if-possible

hub: $(STAMP) $(CHP_STAMP)
	@$(VENV)/bin/ros2nb-hub-singleuser --check
	$(VENV)/bin/jupyterhub -f environment/jupyterhub_config.py

hub-collect: $(STAMP)
	@test -n "$(CLASS)" || { echo "Usage: make hub-collect CLASS=DIR [HOMES=1] [STORE=folder], then make grade SUBMISSIONS=DIR"; exit 2; }
	$(VENV)/bin/ros2nb-hub-collect "$(CLASS)" $(if $(HOMES),--from-homes) $(if $(STORE),--store "$(STORE)")

hub-feedback: $(STAMP)
	$(VENV)/bin/ros2nb-hub-feedback $(if $(GRADING),"$(GRADING)") $(if $(STORE),--store "$(STORE)")
# ---- end of the classroom-server block ----------------------------------------------------
