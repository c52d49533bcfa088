// hsr city's turns (src/driver/driver.h Turn, DECISIONS #235): a child holds its job's turn from its start until
// its steps 1 to 6 are done; the next child waits for it, and a turn given up (or its holder gone) lets it begin.
#include "core/threads.h"
#include "driver/driver.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include <sys/resource.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <thread>

namespace fs = std::filesystem;
using namespace hsr;

TEST(Turn, TheNextWaitsUntilTheTurnIsGivenUp) {
  const std::string path = (hsr::test::scratch_dir("turn") / ".turn.0").string();
  driver::Turn mine(path);
  std::atomic<bool> began{false};
  std::thread next([&] {
    driver::Turn theirs(path);  // another open file: flock makes it wait, as another process would
    began = true;
  });
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  EXPECT_FALSE(began.load()) << "the next began while the turn was held";
  mine.give_up();
  next.join();
  EXPECT_TRUE(began.load());
  mine.give_up();  // again: nothing
  driver::Turn none("");  // no turn: begins at once
}

TEST(Turn, WhatIsLeftRunsOnOneThreadAtTheLowestPriorityAndRethrows) {
  const int callers = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
  int nice_seen = 0, concurrency = 0;
  run_on_idle_core([&] {
    nice_seen = ::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid)));
    concurrency = tbb::this_task_arena::max_concurrency();
  });
  EXPECT_EQ(nice_seen, kIdleCoreNice);
  EXPECT_EQ(concurrency, 1);
  EXPECT_EQ(::getpriority(PRIO_PROCESS, static_cast<id_t>(::syscall(SYS_gettid))), callers);  // the caller's unchanged
  EXPECT_THROW(run_on_idle_core([] { throw std::runtime_error("failed"); }), std::runtime_error);
}
