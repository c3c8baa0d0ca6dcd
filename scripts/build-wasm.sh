#!/usr/bin/env bash
# Builds the wasm package into pkg/ (the npm package) and puts it, with three.js, next to the demo.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cd "$ROOT"

log "building isoforge for $WASM_TARGET (release)"
wasm_cargo build --release --lib --no-default-features
wasm="$WASM_TARGET_DIR/$WASM_TARGET/release/isoforge.wasm"

log "generating JavaScript bindings into pkg/"
rm -rf pkg
wasm-bindgen --target web --out-dir pkg "$wasm"
# No wasm-opt pass: Debian's binaryen (108) predates the reference-types output of current rustc
# and produces a module that fails at instantiation ("Table.set(): Argument 1 is invalid").
cp pkg-config/package.json pkg-config/README.md pkg/ 2>/dev/null || true

# The threaded build beside it, which the mesher worker loads on cross-origin-isolated pages.
log "building the threaded variant into pkg/threads/"
if wasm_threads_cargo build --release --lib --no-default-features --features threads; then
  wasm-bindgen --target web --out-dir pkg/threads "$WASM_THREADS_TARGET_DIR/$WASM_TARGET/release/isoforge.wasm"
else
  log "no threaded build on this toolchain: pages mesh on one thread"
fi
# The plain-JavaScript parts, shipped as they are (and so also in www/pkg): the CSG builder
# ("isoforge/csg"), the worker mesher ("isoforge/mesher") and the three.js helpers ("isoforge/three").
cp pkg-config/*.js pkg-config/*.d.ts pkg/
# The licence texts npm users must receive with the package (MIT OR Apache-2.0).
cp LICENSE-MIT LICENSE-APACHE pkg/

log "copying the package and three.js into www/"
rm -rf www/pkg www/vendor
mkdir -p www/vendor/three/addons/controls
cp -r pkg www/pkg
cp node_modules/three/build/three.module.js node_modules/three/build/three.core.js www/vendor/three/
cp node_modules/three/examples/jsm/controls/OrbitControls.js www/vendor/three/addons/controls/
ls -l pkg/isoforge_bg.wasm
