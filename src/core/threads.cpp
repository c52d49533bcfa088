#include "core/threads.h"

#include <tbb/global_control.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <cstdlib>
#include <exception>
#include <thread>
#include <string>

namespace hsr {

int resolve_thread_count(int requested) {
  if (requested > 0) return requested;
  if (const char* env = std::getenv("HSR_THREADS")) {
    char* end = nullptr;
    const long v = std::strtol(env, &end, 10);
    if (end != env && *end == '\0' && v > 0 && v < 100000) return static_cast<int>(v);
  }
  return 0;
}

struct ThreadLimit::Impl {
  tbb::global_control control;
  explicit Impl(int threads) : control(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threads)) {}
};

ThreadLimit::ThreadLimit(int threads) {
  if (threads > 0) impl_ = std::make_unique<Impl>(threads);
}

ThreadLimit::~ThreadLimit() = default;

void run_on_idle_core(const std::function<void()>& f) {
  std::exception_ptr failed;
  std::thread idle([&] {
    // Linux: a nice value is a thread's own (PRIO_PROCESS with the thread's id); a failure only leaves it at 0
    (void)::setpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)), kIdleCoreNice);
    try {
      tbb::task_arena one(1);
      one.execute(f);
    } catch (...) {
      failed = std::current_exception();
    }
  });
  idle.join();
  if (failed) std::rethrow_exception(failed);
}

}  // namespace hsr
