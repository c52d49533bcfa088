// Shared plumbing of the peer baselines (bench/baselines): command line, a wall-clock limit enforced by
// running the work in a forked child, and the JSON summary that bench/run.sh reads.
// Plain header (no CGAL): the CGAL work stays in each baseline's .cpp.
#pragma once

#include <nlohmann/json.hpp>

#include <functional>
#include <string>
#include <vector>

namespace hsr::bench {

/// Exit codes shared by the baselines (bench/run.sh maps them to the table's status column).
enum ExitCode : int {
  kOk = 0,         ///< mesh written
  kFailed = 1,     ///< the method ran but produced no mesh (reason in the report's "message")
  kUsage = 2,      ///< bad command line or unreadable input
  kTimedOut = 3,   ///< killed at the time limit; no mesh written
  kCrashed = 4,    ///< the worker died on a signal (e.g. an assertion in CGAL)
};

/// Command line: positional arguments and `--name value` options (every option takes a value).
struct Args {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> options;
  /// Value of --name, or `fallback` when absent.
  std::string get(const std::string& name, const std::string& fallback = "") const;
};
/// Parses argv; throws std::runtime_error on an option without a value or one not in `known`.
Args parse_args(int argc, char** argv, const std::vector<std::string>& known);

/// Runs `work` (returning an ExitCode) in a forked child process and waits at most `limit_seconds`
/// (<= 0: no limit). On the limit the child is killed (SIGKILL) and kTimedOut is returned; a child killed
/// by a signal gives kCrashed. Forking keeps a runaway solver (GLPK has no time limit through CGAL 5.5's
/// traits) from outliving the limit, and keeps the parent able to report it.
int run_with_time_limit(const std::function<int()>& work, double limit_seconds);

/// A baseline's main after its command line: runs `work` under run_with_time_limit; an exception from
/// `work` becomes kFailed with its message, a time-out or crash a line on stdout; in both cases `report_path`
/// gets a report with `method`, the message (and seconds). Returns the exit code.
int run_baseline(const char* name, const char* method, double limit_seconds, const std::string& report_path,
                 const std::function<int()>& work);

/// Writes `report` plus "status" (ok / failed / usage / timed_out / crashed from `code`) to `path`
/// atomically; does nothing when path is empty.
void write_report(const std::string& path, nlohmann::json report, int code);

/// Ends a baseline run: records message, seconds since `start` and peak memory in `report`, writes it
/// (write_report), prints "<name>: ok|failed[: message]" and returns `code`.
int finish_run(const char* name, nlohmann::json& report, double start, const std::string& report_path, int code,
               const std::string& message);

}  // namespace hsr::bench
