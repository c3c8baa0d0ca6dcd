#!/usr/bin/env bash
# Every test: formatting, clippy (native and wasm32), native tests, the same suites as
# wasm-bindgen-test in headless Chromium, and the demo page in a real browser.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cd "$ROOT"
"$ROOT/scripts/setup.sh"

log "cargo fmt --check"
cargo fmt --all -- --check

log "clippy (native)"
cargo clippy --all-targets -- -D warnings

log "cargo doc (no warnings)"
RUSTDOCFLAGS="-D warnings" cargo doc --no-deps --quiet

log "clippy (wasm32)"
wasm_cargo clippy --lib --tests --no-default-features -- -D warnings

log "cargo test (native)"
cargo test

log "cargo test (wasm32, headless Chromium via wasm-bindgen-test)"
wasm_cargo test --no-default-features

log "demo in headless Chromium"
"$ROOT/scripts/build-wasm.sh"
node --test tests/browser/
