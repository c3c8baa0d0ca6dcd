# Sourced by the other scripts: how to drive cargo for wasm32 on this machine.
#
# Where rustup has the wasm32 target (a typical laptop), plain cargo works. Where it cannot have it
# (these build machines, see ../shared/TOOLCHAIN.md), Debian's rustc-web compiles `std` from its
# shipped source with -Z build-std. Native builds always keep using the default toolchain.

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export CHROMEDRIVER="${CHROMEDRIVER:-/usr/bin/chromedriver}"
# wasm-bindgen-test-runner gives a whole suite 20 s by default; the debug-built suites (scenes at
# res 48 with self-intersection and surface-error checks, MC at res 64) take about that on a shared
# 2-core machine, so give them room rather than fail on load.
export WASM_BINDGEN_TEST_TIMEOUT="${WASM_BINDGEN_TEST_TIMEOUT:-300}"
WASM_TARGET=wasm32-unknown-unknown
# A separate target dir keeps the two compilers' artefacts apart.
WASM_TARGET_DIR="$ROOT/target/wasm"

rustup_has_wasm() {
  command -v rustup >/dev/null 2>&1 && rustup target list --installed 2>/dev/null | grep -qx "$WASM_TARGET"
}

# debian_wasm_cargo TARGET_DIR SUBCOMMAND [ARGS...]: cargo for the wasm32 target on Debian's
# toolchain, std rebuilt from its sources (../shared/TOOLCHAIN.md), with the caller's RUSTFLAGS.
debian_wasm_cargo() {
  local dir="$1" sub="$2"
  shift 2
  PATH="/usr/bin:$PATH" RUSTC=/usr/bin/rustc RUSTDOC=/usr/bin/rustdoc RUSTC_BOOTSTRAP=1 \
    CARGO_TARGET_DIR="$dir" /usr/bin/cargo "$sub" --target "$WASM_TARGET" -Z build-std=std,panic_abort "$@"
}

# wasm_cargo SUBCOMMAND [ARGS...]: cargo for the wasm32 target, whichever way this machine allows.
wasm_cargo() {
  local sub="$1"
  shift
  if rustup_has_wasm; then
    CARGO_TARGET_DIR="$WASM_TARGET_DIR" cargo "$sub" --target "$WASM_TARGET" "$@"
  else
    debian_wasm_cargo "$WASM_TARGET_DIR" "$sub" "$@"
  fi
}

# The threaded build (feature `threads`, pkg/threads/): std rebuilt with atomics, shared memory
# imported so that Web Workers can share it, and the TLS exports wasm-bindgen's thread start-up
# needs. It has a target dir of its own, as its std differs from the plain build's.
WASM_THREADS_RUSTFLAGS="-C target-feature=+atomics,+bulk-memory,+simd128 -C link-arg=--shared-memory \
-C link-arg=--max-memory=4294967296 -C link-arg=--import-memory -C link-arg=--export=__wasm_init_tls \
-C link-arg=--export=__tls_size -C link-arg=--export=__tls_align -C link-arg=--export=__tls_base"
WASM_THREADS_TARGET_DIR="$ROOT/target/wasm-threads"

# wasm_threads_cargo SUBCOMMAND [ARGS...]: cargo for the threaded build. Rebuilding std needs
# -Z build-std, so it runs only where Debian's toolchain is used (or RUSTC_BOOTSTRAP is allowed);
# returns 2 where rustup's wasm32 target is used instead, and the package then ships without it.
wasm_threads_cargo() {
  local sub="$1"
  shift
  if rustup_has_wasm; then
    return 2
  fi
  RUSTFLAGS="$WASM_THREADS_RUSTFLAGS" debian_wasm_cargo "$WASM_THREADS_TARGET_DIR" "$sub" "$@"
}

# The exact wasm-bindgen version the crate links against; the CLI must match it.
wasm_bindgen_version() {
  awk '/^name = "wasm-bindgen"$/ { getline; gsub(/version = |"/, ""); print; exit }' "$ROOT/Cargo.lock"
}

log() { printf '\033[1m==> %s\033[0m\n' "$*"; }
