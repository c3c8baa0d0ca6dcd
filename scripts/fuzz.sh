#!/usr/bin/env bash
# Runs the cargo-fuzz targets in fuzz/ one after another, each for the given number of seconds, in
# one process (libFuzzer's default, no -jobs/-workers) so a 2-core machine stays usable. Installs
# cargo-fuzz from crates.io when it is missing. Targets default to all of them; crashes land in
# fuzz/artifacts/TARGET/ and stop that target's run (libFuzzer's default), and the script goes on
# with the next so one finding does not hide the others; the exit status says whether any failed.
#
#   scripts/fuzz.sh SECONDS [TARGET...]
#
# cargo fuzz needs nightly compiler flags (-Z sanitizer, -C passes=sancov-module): a `nightly`
# toolchain from rustup is used when there is one, otherwise the stable compiler with
# RUSTC_BOOTSTRAP=1 (see docs/fuzzing.md).
set -uo pipefail
cd "$(dirname "$0")/../fuzz"
seconds=${1:-600}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
    targets=(expr_parse csg_json read_mesh read_points mesh_grid)
fi
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
if rustup toolchain list 2>/dev/null | grep -q '^nightly'; then
    fuzz=(cargo +nightly fuzz)
else
    export RUSTC_BOOTSTRAP=1
    fuzz=(cargo fuzz)
fi
failed=()
for target in "${targets[@]}"; do
    echo "== $target for ${seconds}s"
    if ! CARGO_BUILD_JOBS=${CARGO_BUILD_JOBS:-1} "${fuzz[@]}" run "$target" -- \
        -max_total_time="$seconds" -rss_limit_mb=2048 -timeout=10 -print_final_stats=1; then
        failed+=("$target")
    fi
done
if [ ${#failed[@]} -gt 0 ]; then
    echo "failed: ${failed[*]} (inputs in fuzz/artifacts/)" >&2
    exit 1
fi
