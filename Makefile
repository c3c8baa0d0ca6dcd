# The two commands a newcomer needs; both install what is missing first and are safe to re-run.
.PHONY: demo test setup wasm bench
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
