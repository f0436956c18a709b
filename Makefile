# robomill — two commands matter (README quick start):
#   make demo   set up, build (release), run the bundled demo job
#   make test   set up, build, run every test (each unit test once under ASan+UBSan, the slow ones and the command-line, Python and browser tests in release); fuzz the parsers
JOBS        ?= $(shell nproc)
BUILD       ?= build
ASAN_BUILD  ?= build-asan
FUZZ_SECONDS ?= 30
FUZZ_FRF_SECONDS ?= 15
FUZZ_PROGRAM_SECONDS ?= 10
FUZZ_RECORDING_SECONDS ?= 10

.PHONY: all setup build demo docs test test-release sanitize-build test-sanitize fuzz bench format clean

all: build

setup:
	bash scripts/setup

# Both builds compile each target's sources in batches (ROBOMILL_UNITY,
# CMakeLists.txt): on CI's two cores that halves the time spent parsing the
# same headers again for every file.
UNITY ?= ON

# The unit-test programs the release build makes (tests/<folder>; all: every
# one). `make test` narrows it to RELEASE_TEST_PROGRAMS below.
TEST_PROGRAMS ?= all

build: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DROBOMILL_UNITY=$(UNITY) \
	  -DROBOMILL_TEST_PROGRAMS="$(TEST_PROGRAMS)"
	cmake --build $(BUILD) -j$(JOBS)

# The demo builds only what it runs, the robomill program (not the tests,
# benchmarks or Python module that `make build` adds).
demo: setup
	cmake -S . -B $(BUILD) -DCMAKE_BUILD_TYPE=Release -DROBOMILL_UNITY=$(UNITY)
	cmake --build $(BUILD) -j$(JOBS) --target robomill
	./$(BUILD)/robomill forces examples/demo.yaml --out out/demo/forces
	./$(BUILD)/robomill stability examples/demo.yaml --out out/demo/stability
	./$(BUILD)/robomill fit-modes examples/003_kr270_measured_frf.yaml --out out/demo/fit-modes
	./$(BUILD)/robomill stability examples/003_kr270_measured_frf.yaml --out out/demo/measured-stability
	./$(BUILD)/robomill toolpath examples/toolpath_pocket_gcode.yaml --out out/demo/toolpath
	./$(BUILD)/robomill listen examples/listen/benchmark_displacement_wav.yaml --out out/demo/listen
	@echo "demo: results in out/demo/forces (forces.csv, summary.json), out/demo/stability (sld.csv, sld_envelope.csv, summary.json), out/demo/fit-modes (modes.csv, frf_fit.csv, modes.yaml), out/demo/measured-stability (sld.csv from the fitted modes), out/demo/toolpath (a G-code pocket: samples.csv, moves.csv, stock.csv, report.html) and out/demo/listen (two recorded cuts judged: recordings.csv, spectrum.csv, spectrogram.csv, report.html)"

# The generated pages of docs/: the job-file reference from the job schema,
# and the validation report from what the paper-validation tests record
# (ctest label `validation`; the report's own check is left out here, since
# it is what is being regenerated). `make test` fails when either is stale.
docs: build
	./$(BUILD)/tests/robomill_docgen job-reference --output docs/job-reference.md
	cd $(BUILD) && ctest -L validation -FC validation_log --output-on-failure -j$(JOBS)
	./$(BUILD)/tests/robomill_docgen validation-report --records $(BUILD)/validation/records.jsonl \
	  --output docs/validation-report.md
	@echo "docs: docs/job-reference.md and docs/validation-report.md regenerated"

# One sanitizer build serves both the tests and the fuzzers: clang with
# AddressSanitizer + UndefinedBehaviorSanitizer, the library also carrying
# libFuzzer's coverage instrumentation. (Two separate builds, gcc+ASan for the
# tests and clang for the fuzzers, cost a third full build of the library:
# about 5 minutes of a 2-core CI run.) The fuzzers run before the sanitizer
# tests so that ctest's summary closes the output.
#
# Every unit test runs once under the sanitizers; the release pass of `make
# test` builds and runs the unit-test programs only where it has to (about 2
# of CI's 2-core minutes fewer): the folders holding a SANITIZE_SKIP test
# (stability, simulation, surface, toolpath, validation, analysis; a test
# added to SANITIZE_SKIP must live in one of them, or its folder must join
# the list) and those recording the validation report (validation, dynamics,
# deflection). The command-line, Python, browser and docs tests run in the
# release pass as before. `make test-release` alone still builds and runs
# every program.
RELEASE_TEST_PROGRAMS ?= stability;simulation;surface;toolpath;validation;analysis;dynamics;deflection
test: TEST_PROGRAMS = $(RELEASE_TEST_PROGRAMS)
test: test-release fuzz test-sanitize

test-release: build
	cd $(BUILD) && ctest --output-on-failure -j$(JOBS)
	@if ls $(BUILD)/report-screenshots/*.png > /dev/null 2>&1; then \
	  echo "browser.reports: screenshots of the example reports in $(BUILD)/report-screenshots/:"; \
	  ls $(BUILD)/report-screenshots/*.png; fi

# Line tables only (-gline-tables-only, not full -g): the sanitizers' reports
# still name file and line, and each object compiles 10-25 % faster and is a
# fraction of the size, so the tests and fuzzers link faster too.
sanitize-build: setup
	cmake -S . -B $(ASAN_BUILD) -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
	  -DCMAKE_CXX_FLAGS_RELWITHDEBINFO="-O2 -gline-tables-only -DNDEBUG" \
	  -DROBOMILL_SANITIZE=ON -DROBOMILL_BUILD_FUZZ=ON -DROBOMILL_BUILD_BENCH=OFF -DROBOMILL_UNITY=$(UNITY)
	cmake --build $(ASAN_BUILD) -j$(JOBS)

# The tests, built with AddressSanitizer + UndefinedBehaviorSanitizer.
# SANITIZE_SKIP names the tests that repeat, on dense grids or whole example
# programs, code paths the other tests already run under the sanitizers; they
# all still run in the release pass. Unit tests: boundary search, Floquet
# methods, the 004 optimum, the two-tooth zero-order comparison, process
# damping in the time domain at 4300 steps per tooth, the surface's dense
# Z-maps, the round pocket corners at 0.1 mm dexels (whose engagement code the
# slot, side-cut and helix tests run under ASan), the simulate-vs-stability
# grids (80 simulations and Floquet solves whose code the chatter-verdict and
# unstable-cut tests run), the stability band's Monte-Carlo error check (12 000
# zero-order diagrams; the band's other tests and cli.stability_uncertainty
# run the same code under ASan), the robust advice's thread-count check (three
# whole robust advices; its other tests and cli.advise_uncertainty run the
# same code under ASan), the learning's hidden-truth loops (the anchor's 16
# learns, the 140 of the calibration over 20 worlds, the robot's cuts and its hammer example: the closed-form, contradiction,
# recording and robot hammer-test tests run the same code under ASan). Command-line tests (tests/cli/*.sh) that run whole
# example jobs: under ASan they took 770 of the pass's 1 320 test-seconds
# (cli.toolpath_krl 211 s, cli.toolpath_arcs 198 s, cli.deformation 84 s,
# cli.optimize 76 s, ...), against 2-20 s each in release. What they run is
# the library, which the unit tests exercise under ASan (readers, writers,
# KRL frames and point edits, the program analysis, the robot along the
# program, --optimize's choices and the compensation: tests/toolpath,
# tests/robot_path, tests/io); the command-line tests that stay under ASan are
# the ones about the command layer itself (bad jobs and --set, exit codes,
# the report, listen, the program readers' vendor files) and the cheap ones.
SANITIZE_SKIP ?= ^(BoundarySearch\.NoUnstableDepthBelowTheLimitInADenseMap|BoundarySearch\.ContinuationFindsTheSameLimits|Floquet\.TimeInvariantCouplingReproducesTheTurningLimit|Floquet\.MethodsConvergeToTheSameBoundary|Paper004\.OptimumIsAtLeastAsGoodAsThePapersAndSeedsAgree|ZeroOrderVersusFdm\.TwoToothSlotWithItsMeanCouplingIsTheZeroOrderDiagram|BenchmarkChatter\.ProcessDampingStabilizesAsTheFdmBoundaryPredicts|SurfaceZMap\.HeightBudgetOnlySavesWork|SurfaceZMap\.VibrationLockedToTheSpindlePrintsLikeTheKinematicSurface|Paper001Surface\..*|ProgramAnalysis\.PocketCornerEngagementMatchesTheClosedForm|SimulateVsStability\.(OneDofBenchmarkGrid|TwoModeRobotGrid)|StabilityBand\.MonteCarloErrorHalvesWithFourTimesTheDraws|RobustAdvice\.ThreadCountDoesNotChangeTheAdvice|Learning\.(TheAnchorCaseLearnsAHiddenTruthFromTheTestsItChooses|ARobotLearnedAtThreePosturesPredictsTwoOthers|TheHammerExampleFindsItsHiddenTruth|PosteriorBandsAreCalibratedOverWorldsDrawnFromThePrior)|cli\.(learn_program|toolpath|toolpath_krl|toolpath_arcs|toolpath_bull|toolpath_uncertainty|deformation|optimize|atlas|advise|surface|stability|forces_demo))$$
test-sanitize: sanitize-build
	cd $(ASAN_BUILD) && ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=print_stacktrace=1 \
	  ctest --output-on-failure -j$(JOBS) -E '$(SANITIZE_SKIP)'

# libFuzzer on the job parser, the FRF readers, the program readers (G-code,
# APT CL, KRL) and the recording readers (WAV/FLAC, MAT, CSV, UFF58 time),
# seeded from fuzz/corpus*; any crash fails. One fuzzer per core at a time
# (scripts/fuzz.sh).
fuzz: sanitize-build
	bash scripts/fuzz.sh $(ASAN_BUILD) $(FUZZ_SECONDS) $(FUZZ_FRF_SECONDS) $(FUZZ_PROGRAM_SECONDS) \
	  $(FUZZ_RECORDING_SECONDS) $(JOBS)

bench: build
	for b in $(BUILD)/bench/bench_*; do $$b --benchmark_min_time=0.2; done

format:
	clang-format -i $$(git ls-files '*.cpp' '*.hpp')

clean:
	rm -rf $(BUILD) $(ASAN_BUILD) out
