"""cga.dask on a LocalCluster: the same reports and triangles as one
process, models written per partition, and complete results when a task
raises once or a worker is killed mid-run."""

import os
import signal
import threading
import time

import numpy as np
import pytest
import shapely

import cga
from glb import glb_json

dask_geopandas = pytest.importorskip("dask_geopandas")
gpd = pytest.importorskip("geopandas")
distributed = pytest.importorskip("distributed")
import cga.dask  # noqa: E402

# Random heights: equal results need equal seeds per lot, whatever the
# partition a lot is in.
RULES = """
attr floors = 4
attr tile = 2
Lot --> extrude(rand(5, 30)) report("height", scope.sy) report("floors", floors)
        comp(f) { side : Side | top : report("roof", geometry.area) Roof. }
Side --> split(y) { ~3 : split(x) { ~tile : Tile. }* }*
"""


def frame(n):
    rng = np.random.default_rng(1)
    w = rng.uniform(8, 20, n)
    d = rng.uniform(8, 25, n)
    geoms = [shapely.box(100 * (i % 40), 100 * (i // 40), 100 * (i % 40) + w[i], 100 * (i // 40) + d[i]) for i in range(n)]
    # One lot that cannot be made: a failure is a row, not a lost partition.
    if n > 123:
        geoms[123] = shapely.Polygon([(0, 0), (1, 1), (0, 0)])
    return gpd.GeoDataFrame({"floors": (np.arange(n) % 9 + 1).astype(float), "other": "x"}, geometry=geoms)


@pytest.fixture(scope="module")
def cluster():
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                                  dashboard_address=None) as c, distributed.Client(c) as client:
        yield client


def glb_triangles(path):
    doc = glb_json(path)
    return sum(
        doc["accessors"][p["indices"]]["count"] // 3
        for m in doc["meshes"] for p in m["primitives"]
    )


def one_process(rules, gdf):
    models = rules.generate(gdf, invalid="report")
    return models


def test_partitions_give_what_one_process_gives(cluster, tmp_path):
    rules = cga.Rules.from_string(RULES)
    gdf = frame(1000)
    ddf = dask_geopandas.from_geopandas(gdf, npartitions=8)
    reports = cga.dask.generate(ddf, rules, tmp_path / "out", report_keys=["height", "roof"])
    table = reports.compute()
    assert len(table) == 1000
    assert list(table.index) == list(gdf.index)
    want = one_process(rules, gdf)
    assert table["triangles"].tolist() == [m.triangles for m in want]
    assert table["shapes"].tolist() == [m.shapes for m in want]
    assert table["reports"].tolist() == [m.reports for m in want]
    assert table["height"].tolist() == pytest.approx([m.reports.get("height", np.nan) for m in want], nan_ok=True)
    # Heights are random and differ between lots; floors came from the column.
    assert table["height"].nunique() > 900
    assert table["reports"].iloc[5]["floors"] == 6.0
    # The invalid lot is a row with its error.
    assert "2 distinct points" in table["error"].iloc[123]
    assert table["error"].isna().sum() == 999
    files = sorted(os.listdir(tmp_path / "out"))
    assert files == [f"part-{i:05d}.glb" for i in range(8)]
    assert all((tmp_path / "out" / f).read_bytes()[:4] == b"glTF" for f in files)
    # The files hold the triangles the table counts (no instanced assets
    # here: each primitive's indices are its triangles).
    assert sum(glb_triangles(tmp_path / "out" / f) for f in files) == table["triangles"].sum()
    assert table["triangles"].sum() > 100000
    wide = cga.dask.report_columns(table)
    assert wide["roof"].iloc[0] == pytest.approx(want[0].reports["roof"])


class FailOnce:
    """A partition step that raises the first time it meets partition 3
    (a marker file tells the retry, in any worker process)."""

    def __init__(self, marker):
        self.marker = str(marker)

    def __call__(self, part, partition_info=None):
        if partition_info and partition_info["number"] == 3 and not os.path.exists(self.marker):
            open(self.marker, "w").close()
            raise RuntimeError("a task that fails once")
        return part


def test_a_task_that_raises_once_is_retried(cluster, tmp_path):
    import cloudpickle

    cloudpickle.register_pickle_by_value(__import__(__name__))
    rules = cga.Rules.from_string(RULES)
    gdf = frame(200)
    ddf = dask_geopandas.from_geopandas(gdf, npartitions=8).map_partitions(
        FailOnce(tmp_path / "failed"), meta=gdf.iloc[:0]
    )
    table = cga.dask.generate(ddf, rules).compute(retries=2)
    assert os.path.exists(tmp_path / "failed")
    assert table["triangles"].tolist() == [m.triangles for m in one_process(rules, gdf)]


def test_a_killed_worker_still_gives_the_complete_result(cluster, tmp_path):
    rules = cga.Rules.from_string(RULES.replace("attr tile = 2", "attr tile = 0.25"))
    gdf = frame(1000)
    ddf = dask_geopandas.from_geopandas(gdf, npartitions=8)
    out = tmp_path / "out"
    future = cluster.compute(cga.dask.generate(ddf, rules, out))
    pids = cluster.run(os.getpid)
    # Kill a worker once the first partition is written, mid-run.
    deadline = time.time() + 60
    while not (out.exists() and os.listdir(out)) and time.time() < deadline:
        time.sleep(0.02)
    killed = not future.done()
    os.kill(next(iter(pids.values())), signal.SIGKILL)
    table = future.result(timeout=120)
    assert killed, "the run ended before the worker was killed"
    want = one_process(rules, gdf)
    assert table["triangles"].tolist() == [m.triangles for m in want]
    assert table["reports"].tolist() == [m.reports for m in want]
    assert sorted(os.listdir(out)) == [f"part-{i:05d}.glb" for i in range(8)]


def test_a_bag_of_lots(cluster):
    import dask.bag

    rules = cga.Rules.from_string(RULES)
    gdf = frame(100)
    features = [
        {"type": "Feature", "properties": {"floors": f}, "geometry": shapely.geometry.mapping(g)}
        for f, g in zip(gdf["floors"], gdf.geometry)
    ]
    bag = dask.bag.from_sequence(features, npartitions=4)
    table = cga.dask.generate(bag, rules).compute()
    want = rules.generate(features, invalid="report")
    assert list(table.index) == list(range(100))
    assert table["triangles"].tolist() == [m.triangles for m in want]
    assert table["reports"].tolist() == [m.reports for m in want]
    assert table["reports"].iloc[5]["floors"] == 6.0


def test_a_partition_that_fails_leaves_no_half_file(tmp_path, monkeypatch):
    rules = cga.Rules.from_string(RULES)

    def stops_half_way(self, lots, output=None, **kwargs):
        with open(output, "wb") as f:
            f.write(b"glTF, half of it")
        raise RuntimeError("stopped half way")

    monkeypatch.setattr(cga.Rules, "generate", stops_half_way)
    kwargs = dict(attrs=None, seed=0, start_rule=None, jobs=1, limits=None)
    with pytest.raises(RuntimeError, match="half way"):
        cga.dask._generate_partition(frame(10), [0], rules, str(tmp_path), [], kwargs)
    assert os.listdir(tmp_path) == []
