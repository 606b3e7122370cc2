#!/usr/bin/env bash
# Runs fenestra's tests (unit, property, command-line and, when the reference
# implementation is installed by scripts/oracle.sh, differential tests).
# Optimised build (profile testopt): the numeric tests are heavy.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo test --workspace --profile testopt "$@"
