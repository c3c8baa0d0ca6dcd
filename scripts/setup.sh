#!/usr/bin/env bash
# Installs everything the build, the demo and the tests need. Idempotent: a second run only checks.
set -euo pipefail
source "$(dirname "$0")/env.sh"
cd "$ROOT"

apt_packages=(lld chromium chromium-driver binaryen)
if ! rustup_has_wasm; then
  # No wasm32 std from rustup here: Debian's compiler of the same generation plus std's source.
  apt_packages+=(rustc-web rust-web-src cargo-web rust-web-clippy)
fi
missing=()
for p in "${apt_packages[@]}"; do
  dpkg -s "$p" >/dev/null 2>&1 || missing+=("$p")
done
if ((${#missing[@]})); then
  log "installing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" = 0 ] || SUDO=sudo
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
else
  log "Debian packages present"
fi

# Cargo.lock pins wasm-bindgen; generate it if this is a fresh clone without one.
[ -f Cargo.lock ] || cargo generate-lockfile
want="$(wasm_bindgen_version)"
have="$(wasm-bindgen --version 2>/dev/null | awk '{print $2}' || true)"
if [ "$have" != "$want" ]; then
  log "installing wasm-bindgen-cli $want (found '${have:-none}')"
  # No --locked: one of its locked dependencies is missing from the registry here.
  cargo install wasm-bindgen-cli --version "$want" --force
else
  log "wasm-bindgen-cli $want present"
fi

# Vite 8 (tests/vite-consumer, installed by its test) needs Node ^20.19 or >= 22.12.
node_ok="$(node -e 'const [a, b] = process.versions.node.split(".").map(Number); console.log(a > 22 || (a === 22 && b >= 12) || (a === 20 && b >= 19) ? 1 : 0)')"
if [ "$node_ok" != 1 ]; then
  echo "Node $(node --version) is too old for the Vite consumer test: install Node 20.19+ or 22.12+" >&2
  exit 1
fi

if [ ! -d node_modules ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  log "installing npm dev tools (three.js, playwright-core, typescript)"
  npm ci --no-audit --no-fund --loglevel=error
else
  log "npm dev tools present"
fi
