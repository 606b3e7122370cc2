#!/usr/bin/env bash
# Runs fenestra's tests: unit, property, command-line and differential (against the
# reference implementation, Radiance 6.0a from PyPI pyradiance, installed here by
# scripts/oracle.sh when it is missing). Ends with how many differential tests ran and
# how many were skipped (and why). Optimised build (profile testopt): the numeric tests are heavy.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -z "${FENESTRA_ORACLE_BIN:-}" ] && [ ! -f .oracle/env ]; then
  echo "test.sh: installing the reference implementation for the differential tests (scripts/oracle.sh)" >&2
  scripts/oracle.sh > /dev/null || echo "test.sh: could not install it (no python3 venv/pip or no network?); differential tests will be skipped" >&2
fi
skips=$(mktemp); log=$(mktemp); trap 'rm -f "$skips" "$log"' EXIT
export FENESTRA_SKIP_LOG="$skips"
status=0
cargo test --workspace --profile testopt "$@" 2>&1 | tee "$log" || status=$?
ran=$(grep -cE '^test oracle_[A-Za-z0-9_]* \.\.\. ok$' "$log" || true)
skipped=$(wc -l < "$skips")
if [ "$ran" -eq 0 ] && [ "$skipped" -eq 0 ]; then
  echo "test.sh: no differential tests in this run" >&2
else
  echo "test.sh: differential tests against Radiance: $((ran > skipped ? ran - skipped : 0)) ran, $skipped skipped" >&2
fi
if [ "$skipped" -gt 0 ]; then
  echo "test.sh: $skipped skipped because the reference implementation was not found: run scripts/oracle.sh" >&2
fi
exit "$status"
