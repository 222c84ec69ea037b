#!/usr/bin/env bash
# Writes the models that performance work must not change into a directory,
# so two builds can be compared byte for byte:
#
#   tools/perf/outputs.sh path/to/old/cga /tmp/old
#   tools/perf/outputs.sh path/to/new/cga /tmp/new
#   diff -r /tmp/old /tmp/new && echo identical
#
# Candler (rect:20,30, its footprint, its footprint with Mode=3DPrint), the
# other oracle rule packages and the example city, as OBJ, GLB and glTF, with
# one and two workers, and without a model (reports only); prints and
# reports are kept too. The speed
# benchmarks (20 Candler buildings, envelope2002 on 20 lots) as GLB with and
# without instances.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cga=$(realpath "$1")
out=$(realpath -m "$2")
mkdir -p "$out"
# CityEngine's runtime packages and lots, outside the repository.
oracle=${CGA_SHARED:-$root/../shared}/prt-oracle

run() { # name dir args...
    local name=$1 dir=$2
    shift 2
    for ext in obj glb gltf; do
        (cd "$dir" && "$cga" generate "$@" --jobs 1 -o "$out/$name.$ext" \
            --report "$out/$name.$ext.report.json" >"$out/$name.$ext.stdout" 2>"$out/$name.$ext.stderr") || echo "$name.$ext failed" >&2
    done
    (cd "$dir" && "$cga" generate "$@" --jobs 2 -o "$out/$name.j2.glb" >/dev/null 2>&1) || echo "$name.j2 failed" >&2
    # Reports alone (no model): counts, prints and reports as above.
    (cd "$dir" && "$cga" generate "$@" --jobs 1 --report "$out/$name.none.report.json" \
        >"$out/$name.none.stdout" 2>"$out/$name.none.stderr") || echo "$name.none failed" >&2
    # The messages name the output folder.
    sed -i "s|$out|OUT|g" "$out/$name".*.stderr
}

# GLB only, with instances (the default) and without, two workers.
glb() { # name dir args...
    local name=$1 dir=$2
    shift 2
    (cd "$dir" && "$cga" generate "$@" --jobs 2 -o "$out/$name.glb" >"$out/$name.glb.stdout" 2>/dev/null) || echo "$name.glb failed" >&2
    (cd "$dir" && "$cga" generate "$@" --jobs 2 --no-instances -o "$out/$name.plain.glb" >/dev/null 2>&1) || echo "$name.plain failed" >&2
}

run candler.rect "$oracle" rules/candler/rules/candler.cga --lot rect:20,30
run candler.footprint "$oracle" rules/candler/rules/candler.cga --lot lots/candler_footprint.obj
run candler.3dprint "$oracle" rules/candler/rules/candler.cga --lot lots/candler_footprint.obj --attr Mode=3DPrint
run candler.grid "$oracle" rules/candler/rules/candler.cga --lot grid:2x2:lots/candler_footprint.obj
run identity "$oracle/rules/identity" rules/identity.cga
run fhv "$oracle/rules/FacesHolesVerticesrule" rules/FacesHolesVerticesrule.cga
run arrayAttrs "$oracle/rules/arrayAttrs" rules/arrayAttrs.cga
run arrayAttrs2d "$oracle/rules/arrayAttrs2d" rules/arrayAttrs2d.cga
run dynamic_imports "$oracle/rules/dynamic_imports" rules/prt3_dynamic_imports/ruleA.cga
run extrusion "$oracle/rules/extrusion_rule" rules/extrusion_rule.cga --attr minBuildingHeight=23 --attr maxBuildingHeight=23
run extrusion.seed "$oracle/rules/extrusion_rule" rules/extrusion_rule.cga --seed 7
run envelope "$oracle/rules/envelope2002" rules/typology/envelope2002.cga --lot "$oracle/lots/building_parcel.obj" --seed 666
run city "$root" examples/building.cga --lot grid:6x6
# The speed benchmarks: 20 Candler buildings, envelope2002 on 20 lots.
glb candler.grid20 "$oracle" rules/candler/rules/candler.cga --lot grid:5x4:lots/candler_footprint.obj
glb envelope.grid20 "$oracle/rules/envelope2002" rules/typology/envelope2002.cga --lot "grid:5x4:$oracle/lots/building_parcel.obj" --seed 666
glb city.grid "$root" examples/building.cga --lot grid:6x6
