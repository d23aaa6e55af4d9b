#!/bin/sh
# Instructions per call of IK (all branches + selection) and FK on the host, counted by
# callgrind as the difference between runs with N and 0 calls (so start-up cost cancels).
# Usage: kinematics-core/benches/callgrind.sh [N]   (from the workspace root)
set -eu
N=${1:-10000}
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target}
cargo build --release -q -p kinematics-core --example ik_count
BIN=$CARGO_TARGET_DIR/release/examples/ik_count
count() {
    valgrind --tool=callgrind --callgrind-out-file=/dev/null "$BIN" "$1" "$2" 2>&1 \
        | sed -n 's/.*Collected : \([0-9]*\).*/\1/p'
}
for what in ik ik-far fk; do
    base=$(count 0 "$what")
    many=$(count "$N" "$what")
    echo "$what: $(( (many - base) / N )) instructions per call (N=$N)"
done
