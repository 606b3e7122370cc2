#!/usr/bin/env bash
# Every speed benchmark against the oracle, one after the other on an otherwise idle machine, each one's output
# kept in bench-out/DATE/NAME.txt with the commit, the machine and the load before it: the run behind the
# "re-measured" figures of docs/benchmarks.md and the README.
# Usage: benches/all.sh [names…]   (default: gendaymtx rcalc rmtxop dctimestep rtrace rtcontrib rfluxmtx mkillum
#        genbsdf; needs .oracle/env, hyperfine and a testopt build: cargo build --profile testopt)
set -euo pipefail
cd "$(dirname "$0")/.."
set -a; . .oracle/env; set +a
names=("$@")
[ ${#names[@]} -gt 0 ] || names=(gendaymtx rcalc rmtxop dctimestep rtrace rtcontrib rfluxmtx mkillum genbsdf)
out=bench-out/$(date -u +%Y-%m-%d)
mkdir -p "$out"
machine="$(nproc) cores, $(awk '/MemTotal/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo), $(sed -n 's/^model name\s*: //p' /proc/cpuinfo | head -1)"
for n in "${names[@]}"; do
  f="$out/$n.txt"
  {
    echo "# benches/$n.sh, $(date -u '+%Y-%m-%d %H:%M UTC'), commit $(git rev-parse --short HEAD), $machine"
    echo "# load average before: $(cut -d' ' -f1-3 /proc/loadavg)"
  } > "$f"
  echo "== $n" >&2
  case $n in
    gendaymtx) benches/gendaymtx.sh target/testopt/gendaymtx ;;
    rmtxop) benches/rmtxop.sh target/testopt ;;
    *) "benches/$n.sh" ;;
  esac >> "$f" 2>&1 || echo "# FAILED with status $?" >> "$f"
done
echo "outputs in $out" >&2
