// Resource guards of a run (`hsr reconstruct --max-seconds / --max-memory`, issue "Reliability").
//
// A BudgetScope makes a Budget the active one of the process while a run lasts. check_budget(stage) throws
// hsr::Error(Status::BudgetExceeded, stage, ...) once the time is up or the peak resident memory is above the
// limit; the pipeline calls it between stages, and log::Progress::update() calls it, so every long loop that
// reports progress is also interruptible. Without an active scope check_budget() does nothing.
// For what cooperative checks cannot stop (one long call inside a library), Budget::hard_stop starts a
// watchdog thread: once the time is up by a grace period, or the resident memory is above the limit, it
// prints "hsr: <stage>: ..." and ends the process with the BudgetExceeded exit code. Only the CLI uses it
// (outputs are written atomically after the run, so no partial output file can exist at that point).
#pragma once

#include <string>

namespace hsr {

struct Budget {
  double max_seconds = 0.0;    ///< wall-clock seconds from the start of the scope; 0: no limit
  double max_memory_mb = 0.0;  ///< resident memory of the whole process, MB; 0: no limit
  /// Also end the process from a watchdog thread when the checks are not reached in time (CLI only).
  bool hard_stop = false;
  /// Watchdog grace after max_seconds before the hard stop, seconds.
  double hard_stop_grace = 2.0;
  bool limited() const { return max_seconds > 0.0 || max_memory_mb > 0.0; }
};

/// Activates `budget` for the process until destruction (scopes do not nest: an inner scope is ignored).
class BudgetScope {
 public:
  explicit BudgetScope(const Budget& budget);
  ~BudgetScope();
  BudgetScope(const BudgetScope&) = delete;
  BudgetScope& operator=(const BudgetScope&) = delete;

 private:
  bool owner_ = false;
};

/// Throws Error(BudgetExceeded, stage, "<what> budget of <limit> exceeded ...") when the active budget is
/// spent. Cheap enough for inner loops: one clock read; resident memory is read at most every 50 ms.
/// Also records `stage` as the current stage (named by the watchdog). Thread-safe.
void check_budget(const std::string& stage);

/// Current resident set size of the process in MB (/proc/self/statm; 0 if unknown).
double resident_memory_mb();

/// Physical memory of the machine in MB (sysconf; 0 if unknown).
double physical_memory_mb();

/// The CLI's memory budget when --max-memory is not given: this share of the physical memory, so that a run
/// too big for the machine stops with one line (and no output) before the kernel kills it. The rest is
/// left to the system and to other processes; the watchdog samples every 50 ms, so a run may overshoot by
/// what it allocates in that time.
constexpr double kDefaultMemoryShare = 0.75;
/// kDefaultMemoryShare of physical_memory_mb(); 0 (no limit) when the physical memory is unknown.
double default_memory_budget_mb();

}  // namespace hsr
