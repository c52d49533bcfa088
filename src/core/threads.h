// Thread count of a run (issue 16). Every parallel loop of hsr runs on TBB and is written so that its result
// does not depend on how many threads run it; this only decides how many may.
#pragma once

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

}  // namespace hsr
