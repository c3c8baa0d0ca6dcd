# The two commands a newcomer needs; both install what is missing first and are safe to re-run.
.PHONY: demo test setup wasm bench soak fuzz
demo:   ## set up, build the wasm package, serve the demo on http://localhost:8080/
	./scripts/demo.sh
test:   ## every test: fmt, clippy (native + wasm32), cargo test, wasm-bindgen-test in Chromium, browser tests
	./scripts/test.sh
setup:
	./scripts/setup.sh
wasm:
	./scripts/build-wasm.sh
bench:
	cargo bench
soak:   ## the seeded property suites (every test named prop_*) with ISOFORGE_SOAK cases each (default 2000); not in CI
	ISOFORGE_SOAK=$${ISOFORGE_SOAK:-2000} cargo test -- prop_
fuzz:   ## every cargo-fuzz target in fuzz/ for FUZZ_TIME seconds each (default 600), one at a time, one job; not in CI (see docs/fuzzing.md)
	./scripts/fuzz.sh $${FUZZ_TIME:-600} $(FUZZ_TARGETS)
