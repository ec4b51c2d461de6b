# geomint front door. Two commands matter (README): `make figures` and `make test`.
# Both install missing Debian packages first (as root; anyone else gets the exact command).
BUILD     ?= build
OUT       ?= out
JOBS      ?= $(shell nproc 2>/dev/null || echo 2)
# matplotlib and jupyter-notebook (the `jupyter` command): the example notebook's figures, in a notebook; python3-venv,
# -setuptools and -pip: `pip install .` of the module into a virtual environment (README).
PACKAGES  := cmake make g++ git libeigen3-dev libgsl-dev libboost-dev libboost-program-options-dev \
             libboost-iostreams-dev libboost-filesystem-dev libboost-system-dev catch2 \
             libgnuplot-iostream-dev gnuplot-nox libbenchmark-dev libopenmpi-dev openmpi-bin libginac-dev \
             pkg-config python3-sympy python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest \
             python3-nbconvert python3-ipykernel python3-matplotlib jupyter-notebook \
             python3-venv python3-setuptools python3-pip clang libclang-rt-14-dev ninja-build
# Warnings are errors in CI.
CMAKE_FLAGS := -DCMAKE_BUILD_TYPE=Release $(if $(filter true,$(CI)),-DGEOMINT_WERROR=ON,)
# A new build folder is configured for Ninja: it starts a library's dependants' compiles while the library still
# builds, where make waits at every target for the last of its units (a heavy template unit: one core idle for a
# minute, at each library). A folder configured before keeps its generator.
generator = $(if $(wildcard $(1)/CMakeCache.txt),,-G Ninja)
# The sanitizer build: -Og with line tables only. Against -O1 -g1 it builds in 787 s instead of 1094 s and its
# tests take 236 s instead of 205 s (one run each on 2 idle cores): -O1's passes over the instrumented AD
# templates cost more than they save at run time (61 s -> 40 s for the knife edge's unit).
SANITIZE_OPT := -Og -g1 -DNDEBUG
# Every figure and table with the paper's defaults, in this order.
FIGURES   := stability fig2_foucault anomaly_foucault modified_equation modified_agreement nonholonomic_modified

# Figures of the generic core's systems, the paper's settings among them: one "program arguments..." per line.
define FIGURE_COMMANDS
regularized_error --system oscillator --alpha 0.01 0.1 --schemes la la-printed contact --reference leapfrog --trajectory
modified_agreement --systems oscillator --schemes la contact --orders 0 1 --alpha 0.01 0.1 1 --T 50 --h-max 0.2 --halvings 7 --start shooting naive --all-orders
convergence --system oscillator --alpha 0.01 0.1 1 --h-max 0.2 --schemes la contact la-printed leapfrog la-midpoint contact-sym
work_precision --system oscillator --alpha 0.01 0.1 1 --h-max 0.2 --h-min 2e-4 --schemes la contact la-midpoint contact-sym leapfrog --baselines odeint-rk4 odeint-dopri5 odeint-bulirsch-stoer gsl-rk8pd --equations rhs --adaptive-error steps
convergence --system foucault --alpha 1e-3 1e-4 0.1 --T 4 32 --h-max 0.1 --h-min 0.0015625 --schemes la-nh contact-nh --reference odeint-rhs --tol 1e-12 --norm 2
work_precision --system foucault --alpha 1e-3 --T 4 --h-max 0.1 --h-min 4e-4 --schemes la-nh contact-nh --baselines odeint-dopri5 --tol 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10 1e-11 1e-12 --equations rhs
work_precision --system foucault-rotation --alpha 1e-3 --T 100 --h-max 0.1 --h-min 4e-4 --schemes la-nh contact-nh --baselines odeint-dopri5 --tol 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10 1e-11 1e-12 --equations rhs
modified_equation --formulas
modified_equation --system oscillator --order 3 --formulas
modified_equation --system knife-edge --order 2 --q 0 0 0.3 --v 1 0 0.5 --formulas
modified_equation --system foucault --schemes la --order 3 --q 0 0.67 --v 3.687e-5 0 --formulas
modified_equation --system-file docs/systems/chaplygin-sleigh.geomint --order 3 --q 0 0 0 --v 1 0.15 0.5 --formulas --on-constraint
surrogate --system-file docs/systems/oscillator.geomint --schemes la contact --order 2
surrogate --system-file docs/systems/foucault.geomint --schemes la --order 2
surrogate --system-file docs/systems/knife-edge.geomint --schemes la-midpoint la contact --order 2
convergence --system pendulum
regularized_error --system forced-oscillator --alpha 0.01 0.1 1 2
convergence --system forced-oscillator --alpha 0.01 0.1 1 2
convergence --system knife-edge
integrate --system knife-edge --scheme la
integrate --system knife-edge --scheme contact-trapezoid
ensemble --system knife-edge --scheme la --runs 2000
work_precision --system pendulum
stability --system coupled-oscillators --n 60
long_horizon --system oscillator
long_horizon --system foucault
long_horizon --system forced-oscillator
long_horizon --system kepler
long_horizon --system pendulum --alpha 0.01
kepler_anchor
nonholonomic_suite
nonholonomic_suite --problems contact-oscillator nonreversible-oscillator --schemes la contact la-midpoint --T 10000 --reps 1 --stride 8 --name nonholonomic_suite_long
endef
export FIGURE_COMMANDS

.PHONY: all deps build figures test bench sanitize fuzz clean reference

all: build

deps:
	@missing=""; for p in $(PACKAGES); do \
	  dpkg-query -W -f='$${Status}' $$p 2>/dev/null | grep -q 'install ok installed' || missing="$$missing $$p"; \
	done; \
	if [ -n "$$missing" ]; then \
	  if [ "$$(id -u)" = 0 ]; then \
	    echo "Installing missing Debian packages:$$missing"; \
	    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq --no-install-recommends $$missing || exit 1; \
	  else \
	    echo "Missing Debian packages:$$missing"; \
	    echo "Run:  sudo apt-get install -y --no-install-recommends$$missing"; \
	    exit 1; \
	  fi; \
	fi

build: deps
	@cmake -S . -B $(BUILD) $(call generator,$(BUILD)) $(CMAKE_FLAGS) > /dev/null
	@cmake --build $(BUILD) -j$(JOBS)

# The programs make figures runs, and nothing else: the tests and benchmarks are not compiled before the first
# figure.
figures: deps
	@cmake -S . -B $(BUILD) $(call generator,$(BUILD)) $(CMAKE_FLAGS) > /dev/null
	@targets=$$(printf '%s\n' $(FIGURES); printf '%s\n' "$$FIGURE_COMMANDS" | awk 'NF { print $$1 }'); \
	cmake --build $(BUILD) -j$(JOBS) --target $$(printf '%s\n' $$targets | sort -u)
	@mkdir -p $(OUT)
	@total0=$$(date +%s.%N); \
	for f in $(FIGURES); do \
	  t0=$$(date +%s.%N); \
	  echo "== $$f"; \
	  $(BUILD)/experiments/$$f --out $(OUT) || { echo "$$f failed"; exit 1; }; \
	  t1=$$(date +%s.%N); \
	  awk -v f=$$f -v a=$$t0 -v b=$$t1 'BEGIN { printf "== %s took %.2f s\n\n", f, b - a }'; \
	done; \
	printf '%s\n' "$$FIGURE_COMMANDS" | while read -r f args; do \
	  t0=$$(date +%s.%N); \
	  echo "== $$f $$args"; \
	  $(BUILD)/experiments/$$f $$args --out $(OUT) || { echo "$$f $$args failed"; exit 1; }; \
	  t1=$$(date +%s.%N); \
	  awk -v f="$$f $$args" -v a=$$t0 -v b=$$t1 'BEGIN { printf "== %s took %.2f s\n\n", f, b - a }'; \
	done || exit 1; \
	awk -v a=$$total0 -v b=$$(date +%s.%N) 'BEGIN { printf "All figures in $(OUT)/ (%.1f s after the build)\n", b - a }'

test: build
	@cd $(BUILD) && ctest --output-on-failure --no-tests=error -j$(JOBS)

# Nanoseconds per step, baselines, subnormals; ensembles scalar vs vector vs threads vs a hand-written floor; the
# generic step against the closed forms; seconds to derive the modified equations as formulas, and to build a surrogate
# (and its step against the base's); a composition step
# against its stages alone; systems written as formulas against the same systems as headers (Google Benchmark);
# a time-transformed step against the untransformed one;
# a million steps called from Python against the same registry call timed in C++ (timings: never part of make test).
# The benchmarks are built here, not by `make test`, and their refusals of bad input are checked before any timing.
bench: build
	@cmake --build $(BUILD) --target benchmarks -j$(JOBS)
	@$(BUILD)/tests/geomint_tests "[bench]"
	@mkdir -p $(OUT)
	@$(BUILD)/experiments/bench_steps --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_ensembles --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_generic --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_symbolic --system-files docs/systems/chaplygin-sleigh.geomint --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_surrogate --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_compose --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_formula --systems docs/systems --out $(OUT)
	@echo
	@$(BUILD)/experiments/bench_time_transform --systems docs/systems --out $(OUT)
	@echo
	@PYTHONPATH=$(BUILD)/python /usr/bin/python3 experiments/bench_python.py

# docs/programs.md from the programs' --help, docs/systems.md from the registry (tests hold both to the build).
reference: build
	@/usr/bin/python3 python/reference.py $(BUILD)/experiments > docs/programs.md.tmp && mv docs/programs.md.tmp docs/programs.md
	@/usr/bin/python3 python/reference.py --systems $(BUILD)/python > docs/systems.md.tmp && mv docs/systems.md.tmp docs/systems.md
	@echo "docs/programs.md, docs/systems.md: written"

# The system file reader, parser and compiler fuzzed (libFuzzer, AddressSanitizer, UndefinedBehaviorSanitizer) for
# FUZZ_SECONDS from the seed corpus docs/systems/ (read only: new inputs go to $(BUILD)/fuzz/corpus). Fails on a
# crash, a sanitizer report, an input that takes more than 10 s or 2 GB, and a refusal that is not an InputError
# naming its place (tests/fuzz/formula_reader.fuzz.cpp); the input that did it is left in $(BUILD)/fuzz/.
FUZZ_SECONDS ?= 60
fuzz: deps
	@cmake -S tests/fuzz -B $(BUILD)/fuzz $(call generator,$(BUILD)/fuzz) -DCMAKE_CXX_COMPILER=clang++ $(if $(filter true,$(CI)),-DCMAKE_CXX_FLAGS=-Werror,) > /dev/null
	@cmake --build $(BUILD)/fuzz -j$(JOBS)
	@mkdir -p $(BUILD)/fuzz/corpus
	@$(BUILD)/fuzz/formula_reader_fuzz -max_total_time=$(FUZZ_SECONDS) -timeout=10 -rss_limit_mb=2048 -max_len=32768 \
	  -print_final_stats=1 -dict=tests/fuzz/formula.dict -artifact_prefix=$(BUILD)/fuzz/ $(BUILD)/fuzz/corpus docs/systems

# The test suite under AddressSanitizer and UndefinedBehaviorSanitizer. It links the release build's template units
# (one per system and shape, generated) instead of compiling them again: cmake/registry_lists.cmake says why.
sanitize: build
	@cmake -S . -B $(BUILD)-sanitize $(call generator,$(BUILD)-sanitize) -DCMAKE_BUILD_TYPE=RelWithDebInfo '-DCMAKE_CXX_FLAGS_RELWITHDEBINFO=$(SANITIZE_OPT)' \
	  -DGEOMINT_SANITIZE=ON -DGEOMINT_SYMBOLIC=OFF '-DGEOMINT_TEMPLATE_UNITS_FROM=$(abspath $(BUILD))' \
	  $(if $(filter true,$(CI)),-DGEOMINT_WERROR=ON,) > /dev/null
	@cmake --build $(BUILD)-sanitize -j$(JOBS)
	@cd $(BUILD)-sanitize && ASAN_OPTIONS=detect_leaks=1 LSAN_OPTIONS=suppressions=$(CURDIR)/tests/lsan.supp:print_suppressions=0 \
	  UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 ctest --output-on-failure --no-tests=error -j$(JOBS)

clean:
	rm -rf $(BUILD) $(BUILD)-sanitize $(OUT)
