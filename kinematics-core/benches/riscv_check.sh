#!/bin/sh
# Builds the crate for a core without an FPU (riscv32imc, like the ESP32-C3) and checks that the
# library pulls in no floating-point routines and no panic paths.
# Usage: kinematics-core/benches/riscv_check.sh   (from the workspace root; needs llvm-nm)
set -eu
export CARGO_TARGET_DIR=${CARGO_TARGET_DIR:-target}
cargo build -q -p kinematics-core --target riscv32imc-unknown-none-elf --release
LIB=$CARGO_TARGET_DIR/riscv32imc-unknown-none-elf/release/libkinematics_core.rlib
BAD=$(llvm-nm -u "$LIB" 2>/dev/null | grep -v kinematics_core | grep -E 'panic|[sd]f[23]$|[sd]f[23]_|sinf?$|cosf?$|atan|sqrtf?$' | sort -u || true)
if [ -n "$BAD" ]; then
    echo "float or panic symbols referenced:"; echo "$BAD"; exit 1
fi
echo "riscv32imc build OK: no floating-point routines, no panic paths"
