#!/usr/bin/env python3
"""The Python package's benchmark (docs/performance.md, section "Python"):
the engine through `cga` against CityEngine's runtime through PyPRT on the
same lots and machine, Dask on one and two workers, and the memory of
writing many lots to one file.

    pip install ./python geopandas dask distributed dask-geopandas
    pip install pyprt             # the reference (free for non-commercial use)
    tools/perf/python_bench.py candler [--copies 20] [--runs 3]
    tools/perf/python_bench.py frame [--lots 1000] [--pyprt-lots 100]
    tools/perf/python_bench.py dask [--lots 10000]
    tools/perf/python_bench.py memory [--lots 10000]

`candler`: the Candler rule package on N copies of its footprint (rows of
five, 100 m apart, as tools/perf/reference.py lays them), GLB written, and
into memory (our numpy meshes, and PyEncoder's content through `cga.pyprt`:
positions alone; PyPRT's PyEncoder lists). `frame`: Candler
on a GeoDataFrame of rectangular lots of 15-40 m, reports only
(`cga.generate_frame`, against PyPRT's PyEncoder without geometry on the
first `--pyprt-lots` of them).
`dask`: examples/building.cga on a dask-geopandas frame, LocalCluster of
one and of two single-threaded workers. `memory`: peak resident memory of
a process that writes N lots of examples/building.cga into one GLB.
"""

import argparse
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))


def footprint(oracle):
    from reference import footprint as read

    return np.array(read(os.path.join(oracle, "lots", "candler_footprint.obj")), dtype=np.float64)


def best(f, runs):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        f()
        times.append(time.perf_counter() - start)
    return min(times), times


def report(label, seconds, n, unit="lot"):
    print(f"{label}: {seconds:.3f} s, {seconds / n * 1000:.1f} ms per {unit}", flush=True)


def candler(args):
    import cga

    rpk = os.path.abspath(os.path.join(args.oracle, "rpk", "candler.rpk"))  # PRT takes absolute URIs
    lot = footprint(args.oracle)
    n = args.copies
    lots = [lot + [(i % 5) * 100.0, 0.0, -(i // 5) * 100.0] for i in range(n)]
    out = tempfile.mkdtemp()
    rules = cga.Rules.open(rpk)
    runs = iter(range(args.runs))

    def ours_glb_run():
        # A new file each run, as PyPRT's runs below write into a new
        # folder: a file written over is flushed by ext4 when it is closed
        # (9-134 ms for this GLB), a new one is not.
        rules.generate(lots, output=os.path.join(out, f"ours{next(runs)}.glb"), progress=False)

    # In memory first: the GLB runs leave hundreds of megabytes for the
    # kernel to write back in the seconds after, which slowed the runs
    # that came next by up to a half.
    ours_mem, _ = best(lambda: rules.generate(lots, progress=False), args.runs)
    report(f"cga, {n} Candler buildings, numpy meshes", ours_mem, n, "building")
    # What PyEncoder gives (vertices and faces alone), through the
    # PyPRT-compatible layer: the same script and encoder as `prt_mem` below.
    from cga import pyprt as cga_pyprt

    our_shapes = [cga_pyprt.InitialShape(l.ravel().tolist()) for l in lots]

    def ours_pyencoder():
        models = cga_pyprt.ModelGenerator(our_shapes).generate_model(
            [{}] * n, rpk, "com.esri.pyprt.PyEncoder", {"emitReport": True, "emitGeometry": True}
        )
        assert len(models) == n

    ours_pos, _ = best(ours_pyencoder, args.runs)
    report(f"cga, {n} Candler buildings, cga.pyprt PyEncoder (positions alone)", ours_pos, n, "building")
    ours_glb, _ = best(ours_glb_run, args.runs)
    report(f"cga, {n} Candler buildings, GLB written", ours_glb, n, "building")
    os.sync()
    if args.no_pyprt:
        shutil.rmtree(out)
        return
    import pyprt

    shapes = [pyprt.InitialShape(l.ravel().tolist()) for l in lots]

    def prt_glb():
        d = tempfile.mkdtemp()
        pyprt.ModelGenerator(shapes).generate_model(
            [{}] * n, rpk, "com.esri.prt.codecs.GLTFEncoder",
            {"outputPath": d, "baseName": "model", "outputFormat": "GLB"},
        )
        shutil.rmtree(d)

    def prt_mem():
        models = pyprt.ModelGenerator(shapes).generate_model(
            [{}] * n, rpk, "com.esri.pyprt.PyEncoder", {"emitReport": True, "emitGeometry": True}
        )
        assert len(models) == n

    prt_mem_t, _ = best(prt_mem, args.runs)
    report(f"PyPRT, {n} Candler buildings, PyEncoder", prt_mem_t, n, "building")
    prt_glb_t, _ = best(prt_glb, args.runs)
    report(f"PyPRT, {n} Candler buildings, GLB written", prt_glb_t, n, "building")
    os.sync()
    print(f"speed-up: GLB {prt_glb_t / ours_glb:.1f}x, in memory {prt_mem_t / ours_mem:.1f}x "
          f"(numpy meshes), {prt_mem_t / ours_pos:.1f}x (PyEncoder against PyEncoder)")
    shutil.rmtree(out)


def rect_frame(n, seed=1):
    import geopandas as gpd
    import shapely

    rng = np.random.default_rng(seed)
    w, d = rng.uniform(15, 40, n), rng.uniform(15, 40, n)
    cols = int(np.ceil(np.sqrt(n)))
    geoms = [shapely.box(60 * (i % cols), 60 * (i // cols), 60 * (i % cols) + w[i], 60 * (i // cols) + d[i]) for i in range(n)]
    return gpd.GeoDataFrame({"lot": np.arange(n)}, geometry=geoms)


def frame(args):
    import cga

    rpk = os.path.abspath(os.path.join(args.oracle, "rpk", "candler.rpk"))  # PRT takes absolute URIs
    rules = cga.Rules.open(rpk)
    gdf = rect_frame(args.lots)
    # Reports only: 1,000 Candler buildings make a GLB over glTF's 4 GiB.
    ours, _ = best(lambda: cga.generate_frame(gdf, rules, progress=False), args.runs)
    report(f"cga, Candler on a {args.lots}-lot GeoDataFrame, report table", ours, args.lots)
    if args.no_pyprt or not args.pyprt_lots:
        return
    import pyprt

    m = min(args.pyprt_lots, args.lots)
    shapes = []
    for g in gdf.geometry.iloc[:m]:
        ring = np.asarray(g.exterior.coords)[:-1]
        shapes.append(pyprt.InitialShape([c for x, y in ring for c in (x, 0.0, -y)]))
    start = time.perf_counter()
    models = pyprt.ModelGenerator(shapes).generate_model(
        [{}] * m, rpk, "com.esri.pyprt.PyEncoder", {"emitReport": True, "emitGeometry": False},
    )
    prt = time.perf_counter() - start
    assert len(models) == m
    report(f"PyPRT, Candler on {m} of these lots, reports (PyEncoder, no geometry)", prt, m)
    print(f"speed-up per lot: {(prt / m) / (ours / args.lots):.1f}x")


def dask_bench(args):
    import dask_geopandas
    from distributed import Client, LocalCluster

    import cga
    import cga.dask

    rules = cga.Rules.open(os.path.join(ROOT, "examples", "building.cga"))
    gdf = rect_frame(args.lots)
    ddf = dask_geopandas.from_geopandas(gdf, npartitions=args.partitions)
    results = {}
    for workers in (1, 2):
        with LocalCluster(n_workers=workers, threads_per_worker=1, dashboard_address=None) as cluster, Client(cluster):
            # Warm: the workers import the package and load the rules.
            cga.dask.generate(ddf.partitions[:workers], rules).compute()

            def run():
                out = tempfile.mkdtemp()
                table = cga.dask.generate(ddf, rules, out).compute()
                assert len(table) == args.lots and table["error"].isna().all()
                shutil.rmtree(out)

            results[workers], _ = best(run, args.runs)
        report(f"cga.dask, {args.lots} lots of examples/building.cga, {workers} worker(s), GLBs written", results[workers], args.lots)
    print(f"two workers against one: {results[1] / results[2]:.2f}x")


MEMORY_CHILD = """
import resource, sys, cga
sys.path.insert(0, {tools!r})
from python_bench import rect_frame
rules = cga.Rules.open({rules!r})
gdf = rect_frame({n})
rules.generate(gdf, output={out!r}, geometry=False, progress=False)
print(rules.last_write["triangles"], resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024)
"""


def memory(args):
    out = tempfile.mkdtemp()
    for n in sorted({max(args.lots // 10, 1), args.lots}):
        code = MEMORY_CHILD.format(
            tools=os.path.dirname(os.path.abspath(__file__)),
            rules=os.path.join(ROOT, "examples", "building.cga"),
            n=n, out=os.path.join(out, "city.glb"),
        )
        start = time.perf_counter()
        triangles, peak = subprocess.check_output([sys.executable, "-c", code], text=True).split()
        wall = time.perf_counter() - start
        size = os.path.getsize(os.path.join(out, "city.glb"))
        print(f"{n} lots into one GLB: {wall:.1f} s, {int(triangles):,} triangles, "
              f"{size / 1e6:.0f} MB, peak {peak} MiB", flush=True)
    shutil.rmtree(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=["candler", "frame", "dask", "memory"])
    ap.add_argument("--copies", type=int, default=20)
    ap.add_argument("--lots", type=int, default=None)
    ap.add_argument("--pyprt-lots", type=int, default=100, help="lots of the frame PyPRT generates (it is slow)")
    ap.add_argument("--partitions", type=int, default=8)
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--no-pyprt", action="store_true")
    ap.add_argument("--oracle", default=os.path.join(ROOT, "..", "shared", "prt-oracle"))
    args = ap.parse_args()
    if args.lots is None:
        args.lots = {"frame": 1000, "dask": 10000, "memory": 10000}.get(args.what, 0)
    {"candler": candler, "frame": frame, "dask": dask_bench, "memory": memory}[args.what](args)


if __name__ == "__main__":
    main()
