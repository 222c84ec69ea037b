#!/usr/bin/env bash
# Measures generation speed as docs/performance.md describes: instruction
# counts (callgrind, deterministic) and wall/CPU time and peak memory of
# Candler buildings and of the synthetic city of examples/building.cga.
#
#   tools/perf/measure.sh [path/to/cga] [runs]
#
# Build first: cargo build --release -p cga-cli. Wall times are the best of
# `runs` runs (default 5); on a shared machine they vary with its load.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cga=${1:-${CARGO_TARGET_DIR:-$root/target}/release/cga}
runs=${2:-5}
cga=$(realpath "$cga")
# CityEngine's runtime packages and lots, outside the repository.
oracle=${CGA_SHARED:-$root/../shared}/prt-oracle
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT

# best of $runs: wall seconds, user+system seconds, peak resident KiB. Each
# run writes a new file: the output of the run before is removed first, out
# of the timing (truncating a file of 170 MB that is still in the page cache
# costs 25 ms, which is not the generator's work).
timed() {
    local best_w=1e9 best_c=1e9 peak=0
    for _ in $(seq "$runs"); do
        rm -f "$out"/*.glb
        /usr/bin/time -o "$out/time" -f "%e %U %S %M" "$@" >/dev/null 2>&1
        read -r w u s m <"$out/time"
        best_w=$(awk -v a="$w" -v b="$best_w" 'BEGIN { print (a < b) ? a : b }')
        best_c=$(awk -v a="$u" -v s="$s" -v b="$best_c" 'BEGIN { c = a + s; print (c < b) ? c : b }')
        peak=$m
    done
    echo "$best_w $best_c $peak"
}

cd "$oracle"
candler=(generate rules/candler/rules/candler.cga --lot lots/candler_footprint.obj)

if command -v valgrind >/dev/null; then
    for what in "GLB written|-o $out/c.glb" "derivation only|"; do
        label=${what%%|*}
        extra=${what#*|}
        ir=$(valgrind --tool=callgrind --callgrind-out-file="$out/cg" \
            "$cga" "${candler[@]}" --jobs 1 $extra 2>&1 | awk '/refs:/ { print $NF }')
        echo "Candler on its footprint, $label: $ir instructions"
    done
fi

read -r w c m < <(timed "$cga" "${candler[@]}" -o "$out/c.glb")
echo "Candler on its footprint (one building, GLB): wall $w s, CPU $c s, peak $((m / 1024)) MiB"

for jobs in 1 2; do
    read -r w c m < <(timed "$cga" generate rules/candler/rules/candler.cga \
        --lot grid:5x5:lots/candler_footprint.obj --jobs "$jobs" -o "$out/g.glb")
    per=$(awk -v w="$w" 'BEGIN { printf "%.1f", w / 25 * 1000 }')
    echo "25 Candler buildings (grid:5x5), --jobs $jobs: wall $w s ($per ms per building), CPU $c s, peak $((m / 1024)) MiB"
done

cd "$root"
for jobs in 1 2; do
    read -r w c m < <(timed "$cga" generate examples/building.cga --lot grid:30x30 \
        --jobs "$jobs" -o "$out/city.glb")
    rate=$(awk -v w="$w" 'BEGIN { printf "%.0f lots/s, %.0f shapes/s", 900 / w, 3802500 / w }')
    echo "City of 900 lots (examples/building.cga, grid:30x30), --jobs $jobs: wall $w s ($rate), CPU $c s, peak $((m / 1024)) MiB"
done

# The city of 10,000 lots, once (about half a minute; the GLB is 1.4 GB).
rm -f "$out"/*.glb
/usr/bin/time -o "$out/time" -f "%e %U %S %M" "$cga" generate examples/building.cga \
    --lot grid:100x100 --jobs 2 -o "$out/city.glb" --stats 2>&1 | grep '^stats' || true
read -r w u s m <"$out/time"
echo "City of 10,000 lots (grid:100x100), --jobs 2: wall $w s, CPU $(awk -v a="$u" -v b="$s" 'BEGIN { print a + b }') s, peak $((m / 1024)) MiB"
