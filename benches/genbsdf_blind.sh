# Sourced by benches/genbsdf.sh and benches/genbsdf_equal_error.sh from the checkout's root: the oracle's
# environment (installed when missing), the testopt binaries (bin), the oracle's python (py) and a temporary
# folder (tmp, removed on exit unless KEEP is set) holding the reference blind converted by the oracle's mgf2rad
# (blind.rad); benches: this folder (its klems_lam.py for the scripts' Python).
[ -f .oracle/env ] || scripts/oracle.sh > /dev/null
set -a; . .oracle/env; set +a
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
benches=$PWD/benches
py="$PWD/.oracle/venv/bin/python"
tmp=$(mktemp -d); [ -n "${KEEP:-}" ] || trap 'rm -rf "$tmp"' EXIT; echo "work: $tmp"
"$FENESTRA_ORACLE_BIN/mgf2rad" tests/fixtures/genbsdf/blinds_curved20.mgf > "$tmp/blind.rad"
