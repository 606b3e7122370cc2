# Shared preamble of the example scripts (sourced): builds fenestra in release mode unless
# FENESTRA_BIN names a folder of built binaries, and puts them first on PATH.
# Sets: top (the checkout), FENESTRA_BIN, nproc.
top=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
if [ -z "${FENESTRA_BIN:-}" ]; then
  echo "== building fenestra (cargo build --release; 2-5 minutes the first time)" >&2
  cargo build --release --manifest-path "$top/Cargo.toml" --bins
  target=$(cargo metadata --format-version 1 --no-deps --manifest-path "$top/Cargo.toml" |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
  FENESTRA_BIN="$target/release"
fi
export PATH="$FENESTRA_BIN:$PATH"
nproc=$(nproc 2>/dev/null || echo 2)
