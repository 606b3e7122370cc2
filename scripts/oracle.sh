#!/usr/bin/env bash
# Installs the reference implementation (Radiance 6.0a binaries from PyPI
# pyradiance==1.3.1) into .oracle/ and prints where its bin/ and lib/ are.
# The differential tests read .oracle/env (or the two variables it prints).
set -euo pipefail
top=$(cd "$(dirname "$0")/.." && pwd)
venv="$top/.oracle/venv"
if [ ! -x "$venv/bin/python" ]; then
  python3 -m venv "$venv"
fi
if ! "$venv/bin/python" -c 'import pyradiance' 2>/dev/null; then
  "$venv/bin/pip" install --quiet --disable-pip-version-check pyradiance==1.3.1
fi
pkg=$("$venv/bin/python" -c 'import os, pyradiance; print(os.path.dirname(pyradiance.__file__))')
[ -x "$pkg/bin/rmtxop" ] || { echo "oracle.sh: pyradiance has no bin/rmtxop under $pkg" >&2; exit 1; }
{
  echo "FENESTRA_ORACLE_BIN=$pkg/bin"
  echo "FENESTRA_ORACLE_LIB=$pkg/lib"
} > "$top/.oracle/env"
cat "$top/.oracle/env"
