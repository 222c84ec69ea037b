#!/usr/bin/env python3
"""Times CityEngine's runtime (PRT, through PyPRT) on the benchmark of
tools/perf/measure.sh: the Candler rule package on N copies of its
footprint, GLB written, on this machine. The reference for the speed goal.
`--package envelope2002` times that package on copies of
lots/building_parcel.obj instead.

    pip install pyprt           # free for non-commercial use
    tools/perf/reference.py [--copies 25] [--runs 3] [--oracle ../shared/prt-oracle] [--package candler]

Copies are laid out in rows of five, 100 m apart (`--lot grid:5x5:...`
puts them 10 m apart; the rule does not look at its neighbours). Each run
writes into a new folder. Prints the wall time of each run and per
building.
"""
import argparse
import os
import shutil
import tempfile
import time

import pyprt


def footprint(obj):
    """The vertices of the first face of an OBJ file, in face order."""
    verts, face = [], None
    with open(obj) as f:
        for line in f:
            parts = line.split()
            if not parts:
                continue
            if parts[0] == "v":
                verts.append([float(x) for x in parts[1:4]])
            elif parts[0] == "f" and face is None:
                face = [int(p.split("/")[0]) for p in parts[1:]]
    face = face or list(range(1, len(verts) + 1))
    return [verts[i - 1 if i > 0 else i] for i in face]


def main():
    root = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--copies", type=int, default=25)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--oracle", default=os.path.join(root, "..", "shared", "prt-oracle"))
    ap.add_argument("--package", default="candler",
                    help="rule package of the oracle's rpk folder (envelope2002: on lots/building_parcel.obj)")
    args = ap.parse_args()
    rpk = os.path.abspath(os.path.join(args.oracle, "rpk", args.package + ".rpk"))
    lot_file = "candler_footprint.obj" if args.package == "candler" else "building_parcel.obj"
    lot = footprint(os.path.join(args.oracle, "lots", lot_file))
    shapes = []
    for i in range(args.copies):
        dx, dz = (i % 5) * 100.0, -(i // 5) * 100.0
        shapes.append(pyprt.InitialShape([c for x, y, z in lot for c in (x + dx, y, z + dz)]))
    for run in range(args.runs):
        out = tempfile.mkdtemp()
        gen = pyprt.ModelGenerator(shapes)
        start = time.perf_counter()
        gen.generate_model([{}] * args.copies, rpk, "com.esri.prt.codecs.GLTFEncoder",
                           {"outputPath": out, "baseName": "model", "outputFormat": "GLB"})
        wall = time.perf_counter() - start
        size = sum(os.path.getsize(os.path.join(out, f)) for f in os.listdir(out))
        shutil.rmtree(out)
        print(f"run {run + 1}: {args.copies} {args.package} lots in {wall:.3f} s, "
              f"{wall / args.copies * 1000:.1f} ms per building, {size / 1e6:.1f} MB written")


if __name__ == "__main__":
    main()
