// Logging and progress lines on stderr. Verbosity is global (set once by the CLI / Python module).
#pragma once

#include <chrono>
#include <cstddef>
#include <string>

namespace hsr::log {

enum class Level { Quiet = 0, Info = 1, Verbose = 2 };
void set_level(Level level);
Level level();

void info(const std::string& msg);     ///< shown unless --quiet
void verbose(const std::string& msg);  ///< shown with --verbose
void warn(const std::string& msg);     ///< shown unless --quiet, prefixed "warning: "

/// Progress of one long step. Prints nothing for steps that finish within a second; after that,
/// a "[stage] message  done/total (xx%)" line at most every half second, and a final line with the
/// elapsed time. Thread-safe updates are not needed: call update() from one thread. update() also checks the
/// active run budget (core/budget.h) and throws Error(BudgetExceeded, stage) when it is spent.
class Progress {
 public:
  Progress(std::string stage, std::string what, std::size_t total = 0);
  ~Progress();
  void update(std::size_t done);
  void finish();

 private:
  std::string stage_, what_;
  std::size_t total_;
  std::chrono::steady_clock::time_point start_, last_print_;
  bool printed_ = false, finished_ = false;
};

/// Seconds since an arbitrary start; for per-stage timings.
double now_seconds();
/// CPU seconds used by this process so far, all threads (CLOCK_PROCESS_CPUTIME_ID).
double cpu_seconds();
/// Peak resident set size of this process in MB (from /proc/self/status VmHWM; 0 if unknown).
double peak_memory_mb();

}  // namespace hsr::log
