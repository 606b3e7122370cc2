#!/usr/bin/env bash
# The differential suite: every test named oracle_* compares fenestra with the
# reference Radiance binaries on the same input. Needs scripts/oracle.sh first;
# under CI=true a missing oracle fails.
set -euo pipefail
cd "$(dirname "$0")/.."
if [ -f .oracle/env ]; then set -a; . .oracle/env; set +a; fi
cargo test --workspace --profile testopt oracle_ "$@"
