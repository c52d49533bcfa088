// The launcher: child runs of `hsr batch` and `hsr city` without the program's start-up cost each.
//
// Why: a child `hsr reconstruct` started by exec pays the program's whole start-up before it reads a point.
// When GDAL was linked in, the dynamic loader mapped and relocated the ~110 shared libraries it brings
// (58,000 symbol relocations), about 45 ms of CPU on the 2-core test machine, as much as a small building's
// pipeline (perf on `hsr city` of a 50-building synth tile: 29 % of all samples in ld-linux). GDAL is now a
// module loaded on first use (core/module.h, DECISIONS #188) and a start costs about 8 ms, but an exec still
// costs more than a fork, and the launcher's copies start with no thread, no TBB scheduler and no GDAL state.
//
// How: `start_launcher`, called first thing in main(), forks a copy of the program before anything has run
// (no thread, no TBB scheduler, no GDAL state). The parent goes on as the driver; the copy (the launcher)
// waits for requests. For each child run it forks a fresh copy of itself, which returns from
// `start_launcher` into main() with the child's argv, exactly as a newly exec'd `hsr` would start, only
// already loaded. Each child is still its own process: a crash, a budget or an error stops that child only,
// and its exit status, log and files are what they would be after exec (DECISIONS: "The launcher").
//
// Workers (issue 43, DECISIONS #115): a child run may name a slot (one per job of the driver). The first run
// of a slot forks a worker, a fresh copy like any child, which then runs that slot's runs one after another
// in its own process (`run_child` per run, its log as stdout + stderr each time, its heap trimmed and its peak
// memory reset between runs), so a city's thousand small buildings pay one process start per job, not one
// each. Isolation is kept: a worker that crashes, is killed or ends itself (a budget's watchdog, exit())
// ends only the run it was doing, whose wait status is the worker's, and the slot's next run gets a new
// worker. A run that returns gives the wait status of a process that exited with its code.
#pragma once

#include <functional>
#include <string>
#include <vector>

namespace hsr::driver {

/// One child run in this process: its arguments (argv[0] first) to the program's exit code. Runs as main()
/// would (stdin /dev/null, stdout + stderr its log); it must leave no state a later run could see, except
/// what a fresh program would set up the same way (the log level is set per run, budgets are scoped).
using ChildRun = std::function<int(const std::vector<std::string>& argv)>;

/// Call first thing in main(), before anything else runs. When `argv` names a driver command (`batch` or
/// `city` as the first argument that is not a global flag), forks the launcher and returns false in the
/// caller (which goes on as the driver). Returns true in a child run started through the launcher, with
/// `child_argv` set to its arguments (argv[0] first); stdin is /dev/null and stdout + stderr go to its log.
/// A worker (a run with a slot) calls `run_child` for each of its runs and never returns.
/// Any other command, or a failed fork: returns false and child runs are exec'd as before.
bool start_launcher(int argc, char** argv, std::vector<std::string>& child_argv, const ChildRun& run_child);

/// True when this process started a launcher that can run children of this very program.
bool launcher_running();

/// Runs `argv` (argv[0] is this program) through the launcher with stdin from /dev/null and stdout + stderr
/// into `log`, and waits: what posix_spawn + waitpid would give. False with `error` set when it could not be
/// started. Safe to call from several threads at once. `slot` >= 0: run in that slot's worker (one slot per
/// thread that calls at a time; runs of one slot never overlap); -1: in a process of its own.
bool launch_and_wait(const std::vector<std::string>& argv, const std::string& log, int slot, int& wait_status,
                     std::string& error);

}  // namespace hsr::driver
