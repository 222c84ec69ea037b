#!/usr/bin/env bash
# Peak memory of a city of lots read from GIS files (GeoJSON, FlatGeobuf,
# GeoPackage) against the same lots from the built-in grid, into GLB and
# OBJ (docs/performance.md). Needs the release binary:
#   cargo build --release -p cga-cli
#   tools/perf/gis_memory.sh [COUNT]      # COUNT: 100000 by default
set -euo pipefail
cd "$(dirname "$0")/../.."
count=${1:-100000}
out=${TMPDIR:-/tmp}/cga-gis-memory
mkdir -p "$out"
cargo run -q -p cga-engine --example gis_lots -- "$count" "$out"
ls -l "$out"/lots.geojson "$out"/lots.fgb "$out"/lots.gpkg
printf 'attr height = 10\nLot --> extrude(height) Mass.\n' > "$out/lots.cga"
rows=$(( (count + 399) / 400 ))
for lot in "grid:400x$rows" "$out/lots.geojson" "$out/lots.fgb" "$out/lots.gpkg"; do
    for ext in glb obj; do
        printf '%s -> %s: ' "$(basename "$lot")" "$ext"
        target/release/cga generate "$out/lots.cga" --lot "$lot" -o "$out/city.$ext" \
            --stats --jobs 2 2>&1 | grep '^stats' | sed 's/.*written in/written in/'
    done
done
rm -f "$out"/city.*
