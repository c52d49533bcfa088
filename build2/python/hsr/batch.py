"""Dask distributed driver of ``hsr batch`` (README "City scale").

    python3 -m hsr.batch INPUT... -o DIR [--format obj|ply|off|city.json] [--scheduler tcp://HOST:PORT]
                         [--workers N] [--resume] [--cityjson-scale S] [--crs EPSG:NNNN] [--hsr PROGRAM]
                         [--scene S] [--ground-z Z] [--partition P] [--lambda L] [--detail D] [--max-seconds S]
                         [--max-memory MB] [-q] [-- other reconstruct options]

The same outputs and summary as ``hsr batch``: it plans with the same code (names, files, command lines),
and each Dask task runs one input's ``hsr reconstruct`` child process exactly as ``hsr batch`` does, so a
crash ends that child and not the worker; the summary and the CityJSONSeq are written by the same code at
the end, in input order. Without ``--scheduler`` a LocalCluster of ``--workers`` single-threaded worker
processes runs on this machine; with one, the scheduler's workers run the tasks, and they need this
package, the hsr program (``--hsr`` or ``HSR_CLI``; default: the build's own) and the inputs and DIR at the
same paths (a shared file system). Exit code: 0 all inputs ok, 1 some failed, else the CLI's code.
"""
import argparse
import os
import sys
import time

from . import _driver, _hsr


def _run_one(item):
    """One Dask task: an input's child process; returns its summary row (a dict)."""
    return _hsr._run_item(item)


def parse_args(argv=None):
    """Parses the command line; what follows ``--`` is kept for reconstruct."""
    p = argparse.ArgumentParser(prog="python3 -m hsr.batch", description=__doc__.split("\n\n")[0])
    p.add_argument("inputs", nargs="+", metavar="INPUT", help="input point files, one building or object each")
    p.add_argument("-o", "--output", required=True, help="output folder (as hsr batch -o)")
    p.add_argument("--format", default="obj", choices=["obj", "ply", "off", "city.json"])
    _driver.add_cluster_options(p)
    p.add_argument("--resume", action="store_true", help="skip inputs whose output and report exist")
    p.add_argument("--cityjson-scale", type=float, default=0.001, help="city.json: integer step (1 mm)")
    p.add_argument("--crs", default="", help="city.json: reference system EPSG:NNNN")
    p.add_argument("--hsr", default=os.environ.get("HSR_CLI", ""),
                   help="hsr program run per input (default: $HSR_CLI, else this build's)")
    return _driver.parse(p, "batch", argv)


def options_of(args):
    """The batch options (batch_run.h BatchOptions) as the compiled steps take them."""
    return {"inputs": args.inputs, "out_dir": args.output, "format": args.format, "resume": args.resume,
            "reconstruct_args": _driver.reconstruct_args(args, "batch"), "cityjson_scale": args.cityjson_scale,
            "crs": args.crs, "hsr_cli": args.hsr or _hsr._cli_path()}


def run_tasks(client, items, todo, rows, quiet):
    """Runs items[todo] on the cluster, filling rows; returns the message of a usage error, or None."""
    from distributed import as_completed
    futures = client.map(_run_one, [items[i] for i in todo], key=["hsr-batch-%d" % i for i in todo], pure=False)
    index = {f.key: i for f, i in zip(futures, todo)}
    done, failed, ran, start = len(items) - len(todo), 0, 0, time.monotonic()
    for fut in as_completed(futures):
        i = index[fut.key]
        try:
            rows[i] = fut.result()
        except Exception as e:  # the worker died or the task could not run: recorded like a crash
            rows[i] = {"input": items[i]["input"], "status": "crashed (worker lost)", "message": repr(e)}
        done, ran = done + 1, ran + 1
        failed += rows[i]["status"] != "ok"
        if rows[i]["status"] == "usage-error":
            for f in futures:
                f.cancel()
            return rows[i]["message"]
        if not quiet:
            print(_hsr._progress_line("batch", done, len(items), failed, ran, time.monotonic() - start),
                  file=sys.stderr, flush=True)
    return None


def run(args):
    """The whole batch; returns the exit code."""
    options = options_of(args)

    def body():
        items = _hsr._batch_plan(options)
        rows = [_hsr._done_row(it) if args.resume else None for it in items]
        todo = [i for i, r in enumerate(rows) if r is None]
        if not args.quiet and len(todo) < len(items):
            print("batch: %d of %d inputs already done (--resume)" % (len(items) - len(todo), len(items)), file=sys.stderr)
        usage_error = None
        if todo:
            with _driver.client(args) as client:
                usage_error = run_tasks(client, items, todo, rows, args.quiet)
        if usage_error is not None:
            raise _driver.usage_error("batch", usage_error)
        failures = _hsr._batch_finish(options, items, rows)
        if not args.quiet:
            print("batch: %d of %d inputs ok; summary in %s" % (len(items) - failures, len(items),
                                                              os.path.join(args.output, "summary.csv")), file=sys.stderr)
        return 1 if failures else 0

    return _driver.run_guarded("batch", options, body)


def main(argv=None):
    sys.exit(run(parse_args(argv)))


if __name__ == "__main__":
    main()
