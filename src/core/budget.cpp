#include "core/budget.h"

#include "core/error.h"

#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <mutex>
#include <thread>

namespace hsr {

namespace {

using Clock = std::chrono::steady_clock;

struct ActiveBudget {
  std::mutex mutex;
  std::condition_variable wake;
  bool active = false;
  Budget budget;
  Clock::time_point start;
  std::string stage;  // last stage passed to check_budget (guarded by mutex)
  std::thread watchdog;
  // Lock-free fast path for check_budget().
  std::atomic<bool> active_flag{false};
  std::atomic<long long> last_memory_check_ns{0};
};

ActiveBudget& state() {
  static ActiveBudget s;
  return s;
}

std::string format_number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

[[noreturn]] void hard_stop(const std::string& stage, const std::string& what) {
  std::fprintf(stderr, "hsr: %s: %s (stopped by the watchdog)\n", stage.empty() ? "reconstruct" : stage.c_str(),
               what.c_str());
  std::fflush(stderr);
  std::_Exit(exit_code(Status::BudgetExceeded));
}

void watchdog_loop() {
  ActiveBudget& s = state();
  std::unique_lock lock(s.mutex);
  const auto poll = std::chrono::milliseconds(50);
  while (s.active) {
    s.wake.wait_for(lock, poll);
    if (!s.active) break;
    const double elapsed = std::chrono::duration<double>(Clock::now() - s.start).count();
    if (s.budget.max_seconds > 0 && elapsed > s.budget.max_seconds + s.budget.hard_stop_grace)
      hard_stop(s.stage, "time budget of " + format_number(s.budget.max_seconds) + " s exceeded");
    if (s.budget.max_memory_mb > 0) {
      const double mb = resident_memory_mb();
      if (mb > s.budget.max_memory_mb)
        hard_stop(s.stage, "memory budget of " + format_number(s.budget.max_memory_mb) + " MB exceeded (" +
                               format_number(mb) + " MB resident)");
    }
  }
}

}  // namespace

double resident_memory_mb() {
  FILE* f = std::fopen("/proc/self/statm", "r");
  if (!f) return 0.0;
  long pages_total = 0, pages_resident = 0;
  const int got = std::fscanf(f, "%ld %ld", &pages_total, &pages_resident);
  std::fclose(f);
  if (got != 2) return 0.0;
  return static_cast<double>(pages_resident) * static_cast<double>(::sysconf(_SC_PAGESIZE)) / (1024.0 * 1024.0);
}

double physical_memory_mb() {
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages <= 0 || page <= 0) return 0.0;
  return static_cast<double>(pages) * static_cast<double>(page) / (1024.0 * 1024.0);
}

double default_memory_budget_mb() { return std::floor(kDefaultMemoryShare * physical_memory_mb()); }

BudgetScope::BudgetScope(const Budget& budget) {
  if (!budget.limited()) return;
  ActiveBudget& s = state();
  std::lock_guard lock(s.mutex);
  if (s.active) return;
  owner_ = true;
  s.active = true;
  s.budget = budget;
  s.start = Clock::now();
  s.stage.clear();
  s.last_memory_check_ns = 0;
  s.active_flag = true;
  if (budget.hard_stop) s.watchdog = std::thread(watchdog_loop);
}

BudgetScope::~BudgetScope() {
  if (!owner_) return;
  ActiveBudget& s = state();
  std::thread watchdog;
  {
    std::lock_guard lock(s.mutex);
    s.active = false;
    s.active_flag = false;
    watchdog = std::move(s.watchdog);
  }
  s.wake.notify_all();
  if (watchdog.joinable()) watchdog.join();
}

void check_budget(const std::string& stage) {
  ActiveBudget& s = state();
  if (!s.active_flag.load(std::memory_order_relaxed)) return;
  std::unique_lock lock(s.mutex);
  if (!s.active) return;
  s.stage = stage;
  const Budget b = s.budget;
  const auto now = Clock::now();
  const double elapsed = std::chrono::duration<double>(now - s.start).count();
  lock.unlock();
  if (b.max_seconds > 0 && elapsed > b.max_seconds)
    throw Error(Status::BudgetExceeded, stage,
                "time budget of " + format_number(b.max_seconds) + " s exceeded (" + format_number(elapsed) +
                    " s elapsed)");
  if (b.max_memory_mb > 0) {
    const long long ns = std::chrono::duration_cast<std::chrono::nanoseconds>(now.time_since_epoch()).count();
    long long last = s.last_memory_check_ns.load();
    if (ns - last >= 50'000'000 && s.last_memory_check_ns.compare_exchange_strong(last, ns)) {
      const double mb = resident_memory_mb();
      if (mb > b.max_memory_mb)
        throw Error(Status::BudgetExceeded, stage,
                    "memory budget of " + format_number(b.max_memory_mb) + " MB exceeded (" + format_number(mb) +
                        " MB resident)");
    }
  }
}

}  // namespace hsr
