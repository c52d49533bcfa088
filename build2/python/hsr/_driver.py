"""What the Dask drivers ``hsr.batch`` and ``hsr.city`` share: the parts of their command lines that are the
same (the reconstruct options passed on to every child are listed once, in C++: src/driver/driver.h
forwarded_options, as for ``hsr batch`` and ``hsr city``), the cluster, and the error handling."""
import contextlib
import logging
import os
import sys

from . import _hsr


def _attr(name):
    return name[2:].replace("-", "_")


def add_cluster_options(p):
    """--scheduler and --workers."""
    p.add_argument("--scheduler", help="address of a running Dask scheduler, e.g. tcp://10.0.0.5:8786")
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1,
                   help="LocalCluster worker processes when no scheduler is given (default: CPU count)")


def parse(p, driver, argv=None):
    """Adds ``driver``'s forwarded options and -q to the parser ``p`` and parses the command line; what follows
    ``--`` is kept for reconstruct (args.forwarded)."""
    argv = list(sys.argv[1:] if argv is None else argv)
    forwarded = []
    if "--" in argv:
        cut = argv.index("--")
        argv, forwarded = argv[:cut], argv[cut + 1:]
    for name, help in _hsr._forwarded_options(driver):
        p.add_argument(name, help=help)
    p.add_argument("-q", "--quiet", action="store_true", help="no progress lines")
    args = p.parse_args(argv)
    args.forwarded = forwarded
    return args


def reconstruct_args(args, driver):
    """The options of every child: what followed ``--``, then the forwarded options given, in the order of the
    list (the CLI's order: driver.h RunOptions::reconstruct_args)."""
    out = list(args.forwarded)
    for name, _ in _hsr._forwarded_options(driver):
        value = getattr(args, _attr(name))
        if value is not None:
            out += [name, value]
    return out


@contextlib.contextmanager
def client(args):
    """A client of the given scheduler, or of a new LocalCluster of single-threaded worker processes here."""
    from distributed import Client, LocalCluster
    cluster = None
    if args.scheduler:
        c = Client(args.scheduler)
    else:
        cluster = LocalCluster(n_workers=max(1, args.workers), threads_per_worker=1, processes=True,
                               dashboard_address=None, silence_logs=logging.ERROR)
        c = Client(cluster)
    try:
        yield c
    finally:
        c.close()
        if cluster is not None:
            cluster.close()


def run_guarded(driver, options, body):
    """body()'s exit code, once the hsr program is found to run; an hsr.Error is printed as the CLI prints it
    and gives the CLI's exit code."""
    try:
        if not os.access(options["hsr_cli"], os.X_OK):
            raise _hsr.Error("%s: cannot run the hsr program '%s' (give --hsr PATH or HSR_CLI)" % (driver, options["hsr_cli"]))
        return body()
    except _hsr.Error as e:
        print("hsr: %s" % e, file=sys.stderr)
        return _hsr._exit_code(getattr(e, "status", "bad-input"))


def usage_error(driver, message):
    """The error of a usage error of reconstruct (every child would hit it)."""
    return _hsr.Error("%s: reconstruct rejected the options (%s); nothing more was run" % (driver, message))
