#!/usr/bin/env bash
# Builds modal-bake and the C library (dcr-capi) for Windows x86-64 (target
# x86_64-pc-windows-gnu, cross-compiled with Debian's MinGW-w64 gcc) and prints the path of
# modal-bake.exe:
#
#     bash scripts/build_windows.sh        # -> ${CARGO_TARGET_DIR:-target}/x86_64-pc-windows-gnu/release/modal-bake.exe
#
# Beside it: dcr_capi.dll with its import library libdcr_capi.dll.a, and the static
# libdcr_capi.a (a C or C++ engine links either with the header crates/dcr-capi/include/dcr.h;
# the static one also needs -lws2_32 -luserenv -lntdll).
#
# Installs what it needs when it can: the target's standard library (rustup target add) and
# the cross compiler (apt: gcc-mingw-w64-x86-64, as root). The program and the DLL link only
# Windows' own DLLs (kernel32, ntdll, msvcrt, bcryptprimitives, ...): they run on Windows 10
# and 11 as they are.
# `python3 scripts/windows_check.py` runs it under Wine; `scripts/package_blender_addon.py
# --binary` on it builds the Windows package of the Blender extension.
#
#     bash scripts/build_windows.sh --tests
#
# also builds the test programs of the crates whose tests run on Windows (dcr-files,
# dcr-runtime, modal-bake) and prints, after the program's path, one line per test program:
# its package's folder, a tab, the program (windows_check.py runs them under Wine).
set -euo pipefail
TESTS=0
case "${1:-}" in
  "") ;;
  --tests) TESTS=1 ;;
  -h|--help) sed -n '2,/^set -euo/p' "$0" | sed '$d; s/^# \{0,1\}//'; exit 0 ;;
  *) echo "error: unknown argument '$1' (usage: bash scripts/build_windows.sh [--tests])" >&2; exit 2 ;;
esac
cd "$(dirname "$0")/.."
TARGET=x86_64-pc-windows-gnu

if command -v rustup >/dev/null 2>&1; then
  if ! rustup target list --installed ${RUSTUP_TOOLCHAIN:+--toolchain "$RUSTUP_TOOLCHAIN"} | grep -qx "$TARGET"; then
    echo "installing Rust's standard library for $TARGET (rustup)" >&2
    rustup target add "$TARGET" ${RUSTUP_TOOLCHAIN:+--toolchain "$RUSTUP_TOOLCHAIN"} >&2
  fi
elif ! rustc --print sysroot >/dev/null 2>&1 || [ ! -d "$(rustc --print sysroot)/lib/rustlib/$TARGET" ]; then
  echo "error: Rust's standard library for $TARGET is missing and rustup is not available to add it" >&2
  exit 1
fi
if ! command -v x86_64-w64-mingw32-gcc >/dev/null 2>&1; then
  if command -v apt-get >/dev/null 2>&1 && [ "$(id -u)" = 0 ]; then
    echo "installing the MinGW-w64 cross compiler (apt: gcc-mingw-w64-x86-64)" >&2
    apt-get update -qq && apt-get install -y -qq gcc-mingw-w64-x86-64 >/dev/null
  else
    echo "error: no x86_64-w64-mingw32-gcc (Debian: apt-get install gcc-mingw-w64-x86-64): it links the program and builds METIS" >&2
    exit 1
  fi
fi
# Debian's MinGW gcc is the linker and the C compiler of METIS (metis-sys builds it with cc).
export CARGO_TARGET_X86_64_PC_WINDOWS_GNU_LINKER=x86_64-w64-mingw32-gcc
cargo build --release --locked --target "$TARGET" -p modal-bake -p dcr-capi >&2
echo "${CARGO_TARGET_DIR:-target}/$TARGET/release/modal-bake.exe"
if [ "$TESTS" = 1 ]; then
  cargo test --release --locked --target "$TARGET" -p dcr-files -p dcr-runtime -p modal-bake \
    --no-run --message-format=json-render-diagnostics |
    python3 -c '
import json, os, sys
for line in sys.stdin:
    m = json.loads(line)
    if m.get("reason") == "compiler-artifact" and m.get("profile", {}).get("test") \
            and m.get("executable"):
        print(os.path.dirname(m["manifest_path"]) + "\t" + m["executable"])'
fi
