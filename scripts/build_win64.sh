#!/usr/bin/env bash
# Build target/win64/JetPipeActuator.dll, the actuator FMU for 64-bit Windows, with Debian's
# rustc and its Windows standard library (rustc 1.63; this machine's rustup toolchain has no
# Windows target and none can be downloaded) and MinGW-w64 as the linker. The FMU's four
# crates are compiled here as cargo would: crates/fmi2, crates/fmi3 and crates/model as rlibs, then
# the root package (src/) as the cdylib; the model's two dependencies, nalgebra (0.32, with its own
# dependencies, at versions that build on 1.63) and smallvec, are fetched from crates.io by
# cargo at the versions of tools/win64/Cargo.lock and compiled here with rustc 1.63 one by one. Installs the Debian packages it needs when they are missing (as root),
# and wine64, on which fmu_tests/test_win64.py runs the DLL. The DLL exports the fmi2* and the
# fmi3* functions: both archives ship it (binaries/win64 and binaries/x86_64-windows).
set -euo pipefail
cd "$(dirname "$0")/.."

PACKAGES=(rustc libstd-rust-dev-windows gcc-mingw-w64-x86-64 wine64)
missing=()
for p in "${PACKAGES[@]}"; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
    echo "==> apt-get install ${missing[*]}"
    export DEBIAN_FRONTEND=noninteractive
    apt-get update -q
    apt-get install -y -q --no-install-recommends "${missing[@]}"
fi

RUSTC=/usr/bin/rustc
TARGET=x86_64-pc-windows-gnu
OUT=target/win64
DEPS=$OUT/deps
VENDOR=$OUT/vendor
mkdir -p "$DEPS"
echo "==> $("$RUSTC" --version) for $TARGET"

# Sources of the pinned dependencies (cargo only downloads; it does not compile here).
if [ ! -f "$VENDOR/.stamp" ] || ! cmp -s tools/win64/Cargo.lock "$VENDOR/.stamp"; then
    rm -rf "$VENDOR"
    cargo vendor --locked --manifest-path tools/win64/Cargo.toml "$VENDOR" >/dev/null
    cp tools/win64/Cargo.lock "$VENDOR/.stamp"
fi

COMMON=(--target "$TARGET" -C opt-level=3 -C panic=unwind --cap-lints allow -L "$DEPS")
rlib() { # crate-name edition source [args...]
    local name=$1 edition=$2 src=$3
    shift 3
    "$RUSTC" --crate-name "$name" --edition "$edition" --crate-type rlib "${COMMON[@]}" \
        -o "$DEPS/lib$name.rlib" "$VENDOR/$src" "$@"
}
x() { echo "--extern $1=$DEPS/lib$1.rlib"; }
if [ ! -f "$DEPS/libnalgebra.rlib" ] || [ "$VENDOR/.stamp" -nt "$DEPS/libnalgebra.rlib" ]; then
    echo "==> dependencies (paste, num-traits, approx, num-complex, num-integer, num-rational, rawpointer, matrixmultiply, bytemuck, safe_arch, wide, typenum, simba, nalgebra, smallvec)"
    "$RUSTC" --crate-name paste --edition 2018 --crate-type proc-macro -C opt-level=1 --cap-lints allow \
        -o "$DEPS/libpaste.so" "$VENDOR/paste/src/lib.rs" --extern proc_macro
    rlib num_traits 2021 num-traits/src/lib.rs --cfg 'feature="std"' --cfg has_total_cmp
    rlib num_integer 2018 num-integer/src/lib.rs --cfg 'feature="std"' $(x num_traits)
    rlib approx 2015 approx/src/lib.rs --cfg 'feature="std"' $(x num_traits)
    rlib num_complex 2021 num-complex/src/lib.rs --cfg 'feature="std"' $(x num_traits)
    rlib num_rational 2021 num-rational/src/lib.rs --cfg 'feature="std"' $(x num_traits) $(x num_integer)
    rlib rawpointer 2015 rawpointer/src/lib.rs
    rlib matrixmultiply 2018 matrixmultiply/src/lib.rs --cfg 'feature="std"' $(x rawpointer)
    rlib bytemuck 2018 bytemuck/src/lib.rs
    rlib safe_arch 2018 safe_arch/src/lib.rs --cfg 'feature="bytemuck"' $(x bytemuck)
    rlib wide 2018 wide/src/lib.rs --cfg 'feature="std"' $(x bytemuck) $(x safe_arch)
    rlib typenum 2018 typenum/src/lib.rs
    rlib simba 2018 simba/src/lib.rs --cfg 'feature="std"' --cfg 'feature="wide"' $(x approx) $(x num_complex) \
        $(x num_traits) --extern paste="$DEPS/libpaste.so" $(x wide)
    rlib nalgebra 2018 nalgebra/src/lib.rs --cfg 'feature="std"' --cfg 'feature="matrixmultiply"' $(x approx) \
        $(x matrixmultiply) $(x num_complex) $(x num_rational) $(x num_traits) $(x simba) $(x typenum)
    rlib smallvec 2018 smallvec/src/lib.rs
fi

# The workspace's crates (rebuilt every time: they are what changes).
VERSION=$(sed -n 's/^version = "\(.*\)"/\1/p' Cargo.toml | head -1)
OWN=(--edition 2021 "${COMMON[@]}" -C codegen-units=1)
echo "==> crates/fmi2, crates/fmi3, crates/model (rlibs)"
CARGO_PKG_VERSION="$VERSION" CARGO_PKG_NAME=jetpipe-fmi2 "$RUSTC" --crate-name fmi2 --crate-type rlib "${OWN[@]}" \
    -o "$DEPS/libfmi2.rlib" crates/fmi2/src/lib.rs
CARGO_PKG_VERSION="$VERSION" CARGO_PKG_NAME=jetpipe-fmi3 "$RUSTC" --crate-name fmi3 --crate-type rlib "${OWN[@]}" \
    -o "$DEPS/libfmi3.rlib" crates/fmi3/src/lib.rs $(x fmi2)
CARGO_PKG_VERSION="$VERSION" CARGO_PKG_NAME=jetpipe-model "$RUSTC" --crate-name jetpipe_model --crate-type rlib \
    "${OWN[@]}" -o "$DEPS/libjetpipe_model.rlib" crates/model/src/lib.rs $(x nalgebra) $(x smallvec)
echo "==> $OUT/JetPipeActuator.dll (src/)"
CARGO_PKG_VERSION="$VERSION" CARGO_PKG_NAME=jetpipe-fmu "$RUSTC" --crate-name JetPipeActuator --crate-type cdylib \
    "${OWN[@]}" -C linker=x86_64-w64-mingw32-gcc -C strip=symbols \
    -o "$OUT/JetPipeActuator.dll" src/lib.rs $(x fmi2) $(x fmi3) $(x jetpipe_model)
echo "==> wrote $OUT/JetPipeActuator.dll"
