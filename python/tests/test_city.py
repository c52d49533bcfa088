"""The Dask driver ``python3 -m hsr.city`` (python/hsr/city.py) against ``hsr city`` on a small synthetic
tile (4 buildings, one terraced): the same CityJSONSeq byte for byte and the same summary (but for its
seconds), on a LocalCluster of 2 workers; two tiles at once; a failed building listed; --resume. Run by
ctest (python_city) or by hand: PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests/test_city.py
"""
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

import pytest

import hsr

CLI = hsr._hsr._cli_path()
TMP = os.environ.get("HSR_TEST_TMP_DIR") or tempfile.mkdtemp(prefix="hsr_city_")
os.makedirs(TMP, exist_ok=True)


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, **kw)


@pytest.fixture(scope="module")
def tile():
    d = os.path.join(TMP, "city_tile")
    if not os.path.exists(os.path.join(d, "truth.json")):
        r = run([CLI, "synth", "city", "--buildings", "4", "--terraced", "1", "--seed", "2", "-o", d, "-q"])
        assert r.returncode == 0, r.stderr
    return d


def out_dir(name):
    d = os.path.join(TMP, "city_out", name)
    shutil.rmtree(d, ignore_errors=True)
    os.makedirs(d)
    return d


def summary_rows(path):
    with open(path, newline="") as f:
        return [row[:2] + row[3:] for row in csv.reader(f)]


def read(path):
    with open(path, "rb") as f:
        return f.read()


def test_dask_run_equals_the_local_one(tile):
    d = out_dir("equal")
    args = [os.path.join(tile, "tile.las"), "--footprints", os.path.join(tile, "footprints.geojson"), "--id-field", "id"]
    local = run([CLI, "city"] + args + ["-o", os.path.join(d, "local.city.jsonl"), "-j", "2"])
    assert local.returncode == 0, local.stderr
    dask = run([sys.executable, "-m", "hsr.city"] + args + ["-o", os.path.join(d, "dask.city.jsonl"), "--workers", "2"])
    assert dask.returncode == 0, dask.stderr
    assert read(os.path.join(d, "dask.city.jsonl")) == read(os.path.join(d, "local.city.jsonl"))
    local_rows = summary_rows(os.path.join(d, "local.summary.csv"))
    dask_rows = summary_rows(os.path.join(d, "dask.summary.csv"))
    strip = lambda rows: [[c.replace("/dask.work/", "/X.work/").replace("/local.work/", "/X.work/") for c in r] for r in rows]
    assert strip(dask_rows) == strip(local_rows)
    assert len(local_rows) == 5 and all(r[1] == "ok" for r in local_rows[1:])


def test_two_tiles_into_a_folder_and_resume(tile):
    d = out_dir("folder")
    tiles = [os.path.join(tile, "tile.las"), os.path.join(tile, "tile_unclassified.las")]
    first = run([sys.executable, "-m", "hsr.city"] + tiles + ["-o", d, "--workers", "2", "-q"])
    assert first.returncode == 0, first.stderr
    for stem in ("tile", "tile_unclassified"):
        assert os.path.exists(os.path.join(d, stem + ".city.jsonl"))
        assert os.path.exists(os.path.join(d, stem + ".summary.csv"))
    before = read(os.path.join(d, "tile.city.jsonl"))
    local = run([CLI, "city"] + tiles + ["-o", os.path.join(d, "cli"), "-j", "2", "-q"])
    assert local.returncode == 0, local.stderr
    for stem in ("tile", "tile_unclassified"):
        assert read(os.path.join(d, "cli", stem + ".city.jsonl")) == read(os.path.join(d, stem + ".city.jsonl"))
    again = run([sys.executable, "-m", "hsr.city"] + tiles + ["-o", d, "--workers", "1", "--resume"])
    assert again.returncode == 0, again.stderr
    assert read(os.path.join(d, "tile.city.jsonl")) == before


def test_bad_tile_is_one_line(tile):
    d = out_dir("bad")
    bad = os.path.join(d, "broken.las")
    with open(bad, "wb") as f:
        f.write(b"LASF broken")
    r = run([sys.executable, "-m", "hsr.city", bad, "-o", os.path.join(d, "b.city.jsonl"), "--workers", "1"])
    assert r.returncode != 0
    assert "hsr: " in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not os.path.exists(os.path.join(d, "b.city.jsonl"))


def test_groups_that_are_not_buildings_exit_zero(tile):
    d = out_dir("not_buildings")
    r = run([sys.executable, "-m", "hsr.city", os.path.join(tile, "tile_unclassified.las"), "-o",
             os.path.join(d, "v.city.jsonl"), "--max-group-variation", "0", "--workers", "1", "-q"])
    assert r.returncode == 0, r.stderr
    with open(os.path.join(d, "v.summary.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == 3 and all(row["status"] == "not-a-building" for row in rows), rows


def far_footprints(tile, path):
    """The tile's footprints moved 100 km east (their CRS kept)."""
    with open(os.path.join(tile, "footprints.geojson")) as f:
        gj = json.load(f)
    for feat in gj["features"]:
        g = feat["geometry"]
        polys = g["coordinates"] if g["type"] == "MultiPolygon" else [g["coordinates"]]
        for poly in polys:
            for ring in poly:
                for v in ring:
                    v[0] += 1e5
    with open(path, "w") as f:
        json.dump(gj, f)


def test_footprints_on_no_tile_are_one_line_naming_crs(tile):
    d = out_dir("no_footprint")
    far = os.path.join(d, "far.geojson")
    far_footprints(tile, far)
    bad_input = hsr._hsr._exit_code("bad-input")
    for tiles, out in (([os.path.join(tile, "tile.las")], os.path.join(d, "a.city.jsonl")),
                       ([os.path.join(tile, "tile.las"), os.path.join(tile, "tile_unclassified.las")], os.path.join(d, "two"))):
        r = run([sys.executable, "-m", "hsr.city"] + tiles + ["-o", out, "--footprints", far, "--id-field", "id",
                                                             "--workers", "1", "-q"])
        assert r.returncode == bad_input, r.stderr
        lines = [l for l in r.stderr.splitlines() if l.startswith("hsr: ")]
        assert len(lines) == 1 and "none of the 4 footprints" in lines[0] and "--crs" in lines[0], r.stderr
        assert "Traceback" not in r.stderr
    assert not os.path.exists(os.path.join(d, "a.city.jsonl"))


def test_lod_chooses_as_hsr_city_and_a_bad_lod_is_one_line(tile):
    d = out_dir("lod")
    las, fp = os.path.join(tile, "tile.las"), os.path.join(tile, "footprints.geojson")
    r = run([CLI, "city", las, "-o", os.path.join(d, "c.city.jsonl"), "--footprints", fp, "--lod", "1.2,2.2", "-q"])
    assert r.returncode == 0, r.stderr
    r = run([sys.executable, "-m", "hsr.city", las, "-o", os.path.join(d, "p.city.jsonl"), "--footprints", fp,
             "--lod", "1.2,2.2", "--workers", "1", "-q"])
    assert r.returncode == 0, r.stderr
    assert read(os.path.join(d, "p.city.jsonl")) == read(os.path.join(d, "c.city.jsonl"))
    lines = read(os.path.join(d, "p.city.jsonl")).decode().splitlines()[1:]
    for line in lines:
        (building,) = json.loads(line)["CityObjects"].values()
        assert [g["lod"] for g in building["geometry"]] == ["2.2", "1.2"]
    r = run([sys.executable, "-m", "hsr.city", las, "-o", os.path.join(d, "b.city.jsonl"), "--lod", "1.5",
             "--workers", "1"])
    assert r.returncode != 0
    assert "--lod: '1.5' is not one of 1.2, 1.3, 2.2" in r.stderr and "Traceback" not in r.stderr, r.stderr
    assert not os.path.exists(os.path.join(d, "b.city.jsonl"))
