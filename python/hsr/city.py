"""Dask distributed driver of ``hsr city`` (README "City scale").

    python3 -m hsr.city TILE... -o OUT.city.jsonl|DIR [--footprints F] [--footprint-layer L] [--id-field NAME]
                        [--classes auto|file|filter] [--crs EPSG:N] [--scheduler tcp://HOST:PORT] [--workers N]
                        [--resume] [--lod 1.2,1.3,2.2] [--cityjson-scale S] [--buffer M] [--ring-inner M] [--ring-outer M]
                        [--min-points N] [--min-prism-points N] [--min-area M2] [--component-cell M] [--min-height M]
                        [--max-group-variation V] [--smrf-cell M]
                        [--smrf-slope S] [--smrf-window M] [--smrf-threshold M] [--partition P] [--lambda L]
                        [--detail D] [--max-seconds S] [--max-memory MB] [--hsr PROGRAM] [-q]
                        [-- other reconstruct options]

The same files as ``hsr city`` (the CityJSONSeq byte for byte; the summary but for its seconds): tiles and
buildings are the units Dask schedules. Each tile is planned by a task (``hsr city``'s own plan: read the
tile, split its points, find its buildings, write their points and footprints into the tile's work folder);
each of its buildings then runs as a task that starts the building's ``hsr reconstruct`` child process
exactly as ``hsr city`` and ``hsr batch`` do (a crash ends that child, not the worker); when a tile's
buildings are all back, its summary and sequence are written by the same code as ``hsr city``'s, in
building order. Without ``--scheduler`` a LocalCluster of ``--workers`` single-threaded worker processes runs
here; with one, the workers need this package, the hsr program (``--hsr`` or ``HSR_CLI``) and the tiles,
footprints and output at the same paths (a shared file system). Exit code, as ``hsr city``'s: 0 every
building modelled (groups that are not buildings are listed as such, not counted), 1 some building failed,
else the CLI's code (e.g. bad-input's when footprints were given and none lies on any tile: the line names
--crs).
"""
import argparse
import os
import sys
import time

from . import _driver, _hsr

# The tile stage's options (src/city/city.h CityParams) with their keys in the options' "params".
PARAMS = (("--buffer", "buffer", float), ("--ring-inner", "ring_inner", float), ("--ring-outer", "ring_outer", float),
          ("--min-points", "min_building_points", int), ("--min-prism-points", "min_prism_points", int),
          ("--min-area", "min_building_area", float),
          ("--component-cell", "component_cell", float), ("--min-height", "min_height_above_ground", float),
          ("--max-group-variation", "max_group_variation", float),
          ("--smrf-cell", "smrf_cell", float), ("--smrf-slope", "smrf_slope", float),
          ("--smrf-window", "smrf_max_window", float), ("--smrf-threshold", "smrf_elevation_threshold", float))


def _plan_one(options, files):
    """A Dask task: plans one tile; returns its plan (a dict)."""
    return _hsr._city_plan(options, files)


def _run_one(item):
    """A Dask task: one building's child process; returns its summary row (a dict)."""
    return _hsr._run_item(item)


def parse_args(argv=None):
    """Parses the command line; what follows ``--`` is kept for reconstruct."""
    p = argparse.ArgumentParser(prog="python3 -m hsr.city", description=__doc__.split("\n\n")[0])
    p.add_argument("tiles", nargs="+", metavar="TILE", help="survey tiles (LAS/LAZ), classified or not")
    p.add_argument("-o", "--output", required=True, help="OUT.city.jsonl (one tile) or a folder (as hsr city -o)")
    p.add_argument("--footprints", default="", help="footprint file (any GDAL vector format)")
    p.add_argument("--footprint-layer", default="", help="its layer (default: the first)")
    p.add_argument("--id-field", default="", help="field of the footprints holding the ids (default: the FID)")
    p.add_argument("--classes", default="auto", choices=["auto", "file", "filter"])
    p.add_argument("--crs", default="", help="EPSG:N of the points and of the sequence (default: the tile's)")
    _driver.add_cluster_options(p)
    p.add_argument("--resume", action="store_true", help="reuse plans and skip buildings already done")
    p.add_argument("--lod", default="1.2,1.3,2.2", help="LoDs of each feature, comma-separated (as hsr city --lod)")
    p.add_argument("--cityjson-scale", type=float, default=0.001, help="integer step of the coordinates (1 mm)")
    p.add_argument("--block", type=float, default=1000.0,
                   help="a larger tile with footprints and classes is planned in blocks of about this side, m (as hsr city --block)")
    p.add_argument("--hsr", default=os.environ.get("HSR_CLI", ""),
                   help="hsr program run per building (default: $HSR_CLI, else this build's)")
    for name, _, kind in PARAMS:
        p.add_argument(name, type=kind, help="as hsr city " + name)
    return _driver.parse(p, "city", argv)


def options_of(args):
    """The city options (city_run.h CityOptions) as the compiled steps take them."""
    params = {"classes": args.classes}
    for name, key, _ in PARAMS:
        value = getattr(args, name[2:].replace("-", "_"))
        if value is not None:
            params[key] = value
    return {"tiles": args.tiles, "output": args.output, "footprints": args.footprints,
            "footprint_layer": args.footprint_layer, "id_field": args.id_field, "crs": args.crs,
            "resume": args.resume, "cityjson_scale": args.cityjson_scale, "lod": args.lod, "block": args.block,
            "reconstruct_args": _driver.reconstruct_args(args, "city"),
            "hsr_cli": args.hsr or _hsr._cli_path(), "params": params}


class _Tile:
    """One tile's state while its buildings run."""

    def __init__(self, plan, rows, todo):
        self.plan, self.rows, self.todo, self.left = plan, rows, todo, len(todo)


def run_tasks(client, options, tiles, quiet):
    """Plans every tile on the cluster, runs their buildings there, finishes each tile as its last building
    returns; returns (failed buildings, the message of a usage error or None)."""
    from distributed import as_completed
    plans = client.map(_plan_one, [options] * len(tiles), tiles, key=["hsr-city-plan-%d" % i for i in range(len(tiles))],
                       pure=False)
    pending = as_completed(plans)
    state, owner, failures = {}, {}, 0
    done = failed = total = 0
    start = time.monotonic()
    for fut in pending:
        if fut.key.startswith("hsr-city-plan-"):
            t = int(fut.key.rsplit("-", 1)[1])
            try:
                plan = fut.result()
            except _hsr.Error:
                raise
            except Exception as e:  # a tile that cannot be read stops the run, as in hsr city
                raise _hsr.Error(str(e)) from e
            rows, todo = _hsr._city_initial_rows(options, plan)
            state[t] = _Tile(plan, rows, todo)
            total += len(todo)
            items = [plan["buildings"][i]["item"] for i in todo]
            keys = ["hsr-city-%d-%d" % (t, i) for i in todo]
            for f in client.map(_run_one, items, key=keys, pure=False):
                owner[f.key] = t
                pending.add(f)
            if not todo:
                failures += _hsr._city_finish(options, plan, rows)
            continue
        t = owner[fut.key]
        i = int(fut.key.rsplit("-", 1)[1])
        tile = state[t]
        try:
            tile.rows[i] = fut.result()
        except Exception as e:  # the worker died or the task could not run: recorded like a crash
            tile.rows[i] = {"input": tile.plan["buildings"][i]["item"]["input"], "status": "crashed (worker lost)",
                            "message": repr(e)}
        done += 1
        failed += tile.rows[i]["status"] != "ok"
        if tile.rows[i]["status"] == "usage-error":
            client.cancel(list(pending.futures))
            return failures, tile.rows[i]["message"]
        if not quiet:
            print(_hsr._progress_line("city", done, total, failed, done, time.monotonic() - start), file=sys.stderr,
                  flush=True)
        tile.left -= 1
        if tile.left == 0:
            failures += _hsr._city_finish(options, tile.plan, tile.rows)
    _hsr._city_require_footprints(options, [state[t].plan for t in sorted(state)])
    return failures, None


def run(args):
    """The whole run; returns the exit code."""
    options = options_of(args)

    def body():
        tiles = _hsr._city_tiles(options)
        if not options["output"].endswith(".city.jsonl"):
            os.makedirs(options["output"], exist_ok=True)
        with _driver.client(args) as client:
            failures, usage_error = run_tasks(client, options, tiles, args.quiet)
        if usage_error is not None:
            raise _driver.usage_error("city", usage_error)
        if not args.quiet:
            print("city: %d tile(s) done, %d building(s) failed" % (len(tiles), failures), file=sys.stderr)
        return 1 if failures else 0

    return _driver.run_guarded("city", options, body)


def main(argv=None):
    sys.exit(run(parse_args(argv)))


if __name__ == "__main__":
    main()
