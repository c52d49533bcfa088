"""Tests of the package layout and of the Dask driver ``python3 -m hsr.batch`` (python/hsr/batch.py): the
same outputs and summary as ``hsr batch`` on a few tiny synth scans, with a LocalCluster of 2 workers and
with a scheduler given by address; failures recorded, --resume, usage errors. Run by ctest (python_batch)
or by hand: PYTHONPATH=build/python /usr/bin/python3 -m pytest python/tests/test_batch.py
"""
import csv
import json
import logging
import os
import pydoc
import subprocess
import sys
import tempfile

import pytest

import hsr
import hsr.batch

CLI = hsr._hsr._cli_path()
TMP = os.environ.get("HSR_TEST_TMP_DIR") or tempfile.mkdtemp(prefix="hsr_batch_")
os.makedirs(TMP, exist_ok=True)


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, **kw)


@pytest.fixture(scope="module")
def inputs():
    """Three tiny scans (box, two houses whose files share the stem 'points') and a broken file."""
    base = os.path.join(TMP, "batch_inputs")
    paths = []
    for model, name, seed in (("box", "box", 1), ("house", "house1", 1), ("house", "house2", 2)):
        d = os.path.join(base, name)
        if not os.path.exists(os.path.join(d, "points.ply")):
            r = run([CLI, "synth", model, "-o", d, "--points", "2500", "--seed", str(seed), "-q"])
            assert r.returncode == 0, r.stderr
        paths.append(os.path.join(d, "points.ply"))
    broken = os.path.join(base, "broken.xyz")
    with open(broken, "w") as f:
        f.write("1 2 3\nnot numbers\n")
    return paths, broken


def out_dir(name):
    d = os.path.join(TMP, "batch_out", name)
    subprocess.run(["rm", "-rf", d], check=True)
    return d


def driver(args, **kw):
    return run([sys.executable, "-m", "hsr.batch"] + args, **kw)


def summary_rows(d):
    """summary.csv without its seconds column (timings are the only thing allowed to differ)."""
    with open(os.path.join(d, "summary.csv"), newline="") as f:
        return [row[:2] + row[3:] for row in csv.reader(f)]


def without_seconds(path):
    def strip(o):
        if isinstance(o, dict):
            return {k: strip(v) for k, v in o.items() if k != "hsr_seconds"}
        if isinstance(o, list):
            return [strip(v) for v in o]
        return o
    with open(path) as f:
        return [strip(json.loads(line)) for line in f]


def test_package_re_exports_the_compiled_module_unchanged():
    assert os.path.basename(hsr.__file__) == "__init__.py"
    assert hsr._hsr.__name__ == "hsr._hsr"
    for name in ("reconstruct", "read_points", "read_mesh", "write_mesh", "detect_planes", "visibility",
                 "recover_planes", "partition", "extract", "evaluate", "synth", "synth_models", "triangulate",
                 "Error", "Structure"):
        assert getattr(hsr, name) is getattr(hsr._hsr, name), name
        assert name in hsr.__all__
    assert hsr.__version__ == hsr._hsr.__version__
    assert issubclass(hsr.Error, RuntimeError)
    assert "reconstruct" in pydoc.render_doc(hsr)  # help(hsr) still documents every function


def test_write_mesh_writes_city_json():
    import numpy as np
    v = np.array([[x, y, z] for z in (0, 1) for y in (0, 1) for x in (0, 1)], dtype=float)
    faces = [[0, 2, 3, 1], [4, 5, 7, 6], [0, 1, 5, 4], [2, 6, 7, 3], [0, 4, 6, 2], [1, 3, 7, 5]]
    path = os.path.join(TMP, "box.city.json")
    hsr.write_mesh(path, v, faces)
    with open(path) as f:
        doc = json.load(f)
    assert doc["type"] == "CityJSON" and doc["version"] == "2.0"
    back = hsr.read_mesh(path)
    assert [list(f) for f in back["faces"]] == faces
    assert np.abs(back["vertices"] - v).max() < 1e-12


def test_local_cluster_gives_the_outputs_and_summary_of_hsr_batch(inputs):
    paths, broken = inputs
    args = paths + [broken, "--format", "city.json", "--crs", "EPSG:7415", "--lambda", "0.5"]
    a, b = out_dir("cli"), out_dir("dask")
    r = run([CLI, "batch"] + args + ["-o", a, "-j", "2", "-q"])
    assert r.returncode == 1, r.stderr  # the broken input failed, the others ran
    r = driver(args + ["-o", b, "--workers", "2"])
    assert r.returncode == 1, r.stderr
    assert "batch: 4/4 done (3 ok, 1 failed)" in r.stderr
    assert summary_rows(a) == summary_rows(b)
    rows = summary_rows(b)
    assert [row[1] for row in rows[1:]] == ["ok", "ok", "ok", "bad-format"]
    names = sorted(os.listdir(a))
    assert names == sorted(os.listdir(b))
    for name in names:
        if name.endswith(".city.json") or name.endswith(".city.jsonl"):
            assert without_seconds(os.path.join(a, name)) == without_seconds(os.path.join(b, name)), name
    seq = without_seconds(os.path.join(b, "buildings.city.jsonl"))
    assert [f["id"] for f in seq[1:]] == ["box_points", "house1_points", "house2_points"]


def test_scheduler_by_address_and_resume(inputs):
    from distributed import LocalCluster
    paths, _ = inputs
    d = out_dir("scheduler")
    with LocalCluster(n_workers=1, threads_per_worker=2, processes=True, host="127.0.0.1",
                      dashboard_address=None, silence_logs=logging.ERROR) as cluster:
        r = driver(paths + ["-o", d, "--scheduler", cluster.scheduler_address, "-q"])
        assert r.returncode == 0, r.stderr
        first = summary_rows(d)
        assert [row[1] for row in first[1:]] == ["ok", "ok", "ok"]
        os.remove(os.path.join(d, "house1_points.obj"))
        with open(os.path.join(d, "box_points.log"), "w") as f:
            f.write("untouched")
        r = driver(paths + ["-o", d, "--scheduler", cluster.scheduler_address, "--resume"])
        assert r.returncode == 0, r.stderr
        assert "2 of 3 inputs already done" in r.stderr
    with open(os.path.join(d, "box_points.log")) as f:
        assert f.read() == "untouched"
    assert os.path.exists(os.path.join(d, "house1_points.obj"))
    assert summary_rows(d) == first


def test_usage_errors_stop_before_or_at_the_first_input(inputs):
    paths, _ = inputs
    d = out_dir("usage")
    r = driver(paths + ["-o", d, "--workers", "1", "--", "--no-such-option"])
    assert r.returncode != 0
    assert "hsr: batch: reconstruct rejected the options" in r.stderr
    assert "no-such-option" in r.stderr
    assert not os.path.exists(os.path.join(d, "summary.csv"))
    r = driver([paths[0], paths[0], "-o", out_dir("twice")])
    assert r.returncode == hsr._hsr._exit_code("bad-input")
    assert r.stderr.strip().startswith("hsr: batch: input given twice")
    r = driver([paths[0], "-o", out_dir("nohsr"), "--hsr", "/nonexistent/hsr"])
    assert r.returncode != 0 and "cannot run the hsr program" in r.stderr
