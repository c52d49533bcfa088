#include "core/log.h"

#include "core/budget.h"
#include "core/error.h"
#include "core/types.h"

#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <iostream>
#include <mutex>
#include <sstream>

namespace hsr {

BBox bounding_box(const std::vector<Vec3>& points) {
  BBox b;
  for (const auto& p : points) b.extend(p);
  return b;
}

const char* status_name(Status s) {
  switch (s) {
    case Status::Ok: return "ok";
    case Status::FileNotFound: return "file-not-found";
    case Status::BadFormat: return "bad-format";
    case Status::BadInput: return "bad-input";
    case Status::NoPlanes: return "no-planes";
    case Status::DegenerateInput: return "degenerate-input";
    case Status::InvalidOutput: return "invalid-output";
    case Status::BudgetExceeded: return "budget-exceeded";
    case Status::NotImplemented: return "not-implemented";
    case Status::Internal: return "internal-error";
  }
  return "unknown";
}

int exit_code(Status s) { return s == Status::Ok ? 0 : 1 + static_cast<int>(s); }

void assertion_failed(const char* expr, const char* file, int line, const std::string& msg) {
  std::fprintf(stderr, "hsr: internal error: %s (%s) at %s:%d\n", msg.c_str(), expr, file, line);
  std::abort();
}

namespace log {
namespace {
Level g_level = Level::Info;
std::mutex g_mutex;
void emit(const std::string& msg) {
  std::lock_guard<std::mutex> lock(g_mutex);
  std::cerr << msg << '\n';
}
}  // namespace

void set_level(Level l) { g_level = l; }
Level level() { return g_level; }
void info(const std::string& msg) { if (g_level >= Level::Info) emit(msg); }
void verbose(const std::string& msg) { if (g_level >= Level::Verbose) emit(msg); }
void warn(const std::string& msg) { if (g_level >= Level::Info) emit("warning: " + msg); }

double now_seconds() {
  using namespace std::chrono;
  static const auto t0 = steady_clock::now();
  return duration<double>(steady_clock::now() - t0).count();
}

double cpu_seconds() {
  timespec ts{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts) != 0) return 0.0;
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

double peak_memory_mb() {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream ss(line.substr(6));
      double kb = 0;
      ss >> kb;
      return kb / 1024.0;
    }
  }
  return 0.0;
}

Progress::Progress(std::string stage, std::string what, std::size_t total)
    : stage_(std::move(stage)), what_(std::move(what)), total_(total),
      start_(std::chrono::steady_clock::now()), last_print_(start_) {}

Progress::~Progress() { finish(); }

void Progress::update(std::size_t done) {
  check_budget(stage_);  // long loops report progress: that is where a run over its budget stops
  if (g_level == Level::Quiet) return;
  auto now = std::chrono::steady_clock::now();
  double since_start = std::chrono::duration<double>(now - start_).count();
  double since_print = std::chrono::duration<double>(now - last_print_).count();
  if (since_start < 1.0 || (printed_ && since_print < 0.5)) return;
  std::ostringstream s;
  s << "[" << stage_ << "] " << what_ << "  " << done;
  if (total_ > 0) s << "/" << total_ << " (" << (100 * done / total_) << "%)";
  emit(s.str());
  printed_ = true;
  last_print_ = now;
}

void Progress::finish() {
  if (finished_) return;
  finished_ = true;
  double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
  if (g_level == Level::Quiet || secs < 1.0) return;
  std::ostringstream s;
  s.precision(3);
  s << "[" << stage_ << "] " << what_ << "  done in " << secs << " s";
  emit(s.str());
}

}  // namespace log
}  // namespace hsr
