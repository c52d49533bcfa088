// Thread count of a run (issue 16). Every parallel loop of hsr runs on TBB and is written so that its result
// does not depend on how many threads run it; this only decides how many may.
#pragma once

#include <functional>
#include <memory>

namespace hsr {

/// Threads a run may use: `requested` when > 0; else the environment variable HSR_THREADS when it holds a
/// positive integer; else 0 (as many as TBB sees cores).
int resolve_thread_count(int requested);

/// Caps TBB's parallelism at `threads` workers while alive (0: no cap). Scopes may nest (TBB keeps the
/// smallest active cap).
class ThreadLimit {
 public:
  explicit ThreadLimit(int threads);
  ~ThreadLimit();
  ThreadLimit(const ThreadLimit&) = delete;
  ThreadLimit& operator=(const ThreadLimit&) = delete;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// The nice value of run_on_idle_core's thread: the lowest priority, so that it takes a core only where no thread
/// of a normal priority wants it.
constexpr int kIdleCoreNice = 19;

/// Runs `f` on a thread of its own at nice kIdleCoreNice, its parallel loops on that one thread (a TBB arena of
/// one), and waits; rethrows what `f` throws. The result does not depend on it (every parallel loop is
/// deterministic). Why: `hsr city`'s building gives its turn up before step 7 (DECISIONS #235) and the next
/// building's first runs begin beside what is left; what is left should take only the core they leave idle, not
/// slow them down (they keep about 1.5 of 2 cores busy with one job).
void run_on_idle_core(const std::function<void()>& f);

}  // namespace hsr
