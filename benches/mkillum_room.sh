# Sourced by benches/mkillum.sh, mkillum_pays.sh and mkillum_equal_error.sh from the checkout's root: the
# testopt binaries and library (bin, lib) and a temporary folder (tmp, removed on exit)
# holding the reference mkillum room (../shared/reference/mkillum) with the BSDF window's XML.
export FENESTRA_NO_PROGRESS=1
bin=$(realpath "${CARGO_TARGET_DIR:-target}/testopt")
lib=$(realpath lib)
fix=$(realpath tests/fixtures)
ref=${FENESTRA_SHARED:-$(cd .. && pwd)/shared}/reference/mkillum
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
cp "$ref"/{materials.rad,room.rad,exterior.rad,window_glass.rad,window_bsdf.rad,sky.rad,skyfunc_glow.rad,sensors.pts,window_illum_glass.rad,window_illum_bsdf.rad} "$tmp/"
cp "$fix/threephase/blinds_kf.xml" "$tmp/"
