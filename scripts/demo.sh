#!/usr/bin/env bash
# Sets everything up on a fresh machine, builds the wasm package and serves the demo on localhost.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cd "$ROOT"
"$ROOT/scripts/setup.sh"
"$ROOT/scripts/build-wasm.sh"
exec node scripts/serve.mjs www "${PORT:-8080}"
