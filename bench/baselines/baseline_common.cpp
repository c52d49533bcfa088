#include "baseline_common.h"

#include "core/atomic_file.h"
#include "core/log.h"

#include <chrono>
#include <csignal>
#include <cstdio>
#include <stdexcept>
#include <thread>

#include <sys/wait.h>
#include <unistd.h>

namespace hsr::bench {

std::string Args::get(const std::string& name, const std::string& fallback) const {
  for (const auto& [k, v] : options)
    if (k == name) return v;
  return fallback;
}

Args parse_args(int argc, char** argv, const std::vector<std::string>& known) {
  Args args;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a.rfind("--", 0) == 0) {
      bool ok = false;
      for (const auto& k : known) ok = ok || k == a;
      if (!ok) throw std::runtime_error("unknown option " + a);
      if (i + 1 >= argc) throw std::runtime_error("option " + a + " needs a value");
      args.options.emplace_back(a, argv[++i]);
    } else {
      args.positional.push_back(a);
    }
  }
  return args;
}

int run_with_time_limit(const std::function<int()>& work, double limit_seconds) {
  std::fflush(stdout);
  std::fflush(stderr);
  const pid_t child = fork();
  if (child < 0) throw std::runtime_error("fork failed");
  if (child == 0) {
    int code = kCrashed;
    try {
      code = work();
    } catch (const std::exception& e) {
      std::fprintf(stderr, "error: %s\n", e.what());
      code = kFailed;
    }
    std::fflush(stdout);
    std::fflush(stderr);
    _exit(code);
  }
  const auto start = std::chrono::steady_clock::now();
  for (;;) {
    int status = 0;
    const pid_t r = waitpid(child, &status, WNOHANG);
    if (r == child) {
      if (WIFEXITED(status)) return WEXITSTATUS(status);
      return kCrashed;
    }
    if (r < 0) return kCrashed;
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (limit_seconds > 0 && elapsed > limit_seconds) {
      kill(child, SIGKILL);
      waitpid(child, &status, 0);
      return kTimedOut;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
}

int finish_run(const char* name, nlohmann::json& report, double start, const std::string& report_path, int code,
               const std::string& message) {
  report["message"] = message;
  report["seconds"] = hsr::log::now_seconds() - start;
  report["peak_memory_mb"] = hsr::log::peak_memory_mb();
  write_report(report_path, report, code);
  std::printf("%s: %s%s%s\n", name, code == kOk ? "ok" : "failed", message.empty() ? "" : ": ", message.c_str());
  return code;
}

int run_baseline(const char* name, const char* method, double limit_seconds, const std::string& report_path,
                 const std::function<int()>& work) {
  const double start = hsr::log::now_seconds();
  const int code = run_with_time_limit(
      [&] {
        try {
          return work();
        } catch (const std::exception& e) {
          std::fprintf(stderr, "%s: %s\n", name, e.what());
          write_report(report_path, {{"method", method}, {"message", e.what()}}, kFailed);
          return static_cast<int>(kFailed);
        }
      },
      limit_seconds);
  if (code == kTimedOut || code == kCrashed) {
    char message[128];
    std::snprintf(message, sizeof message, code == kTimedOut ? "timed out after %g s" : "crashed (killed by a signal)",
                  limit_seconds);
    std::printf("%s: %s\n", name, message);
    write_report(report_path, {{"method", method}, {"message", message}, {"seconds", hsr::log::now_seconds() - start}},
                 code);
  }
  return code;
}

void write_report(const std::string& path, nlohmann::json report, int code) {
  if (path.empty()) return;
  const char* status = code == kOk         ? "ok"
                       : code == kFailed   ? "failed"
                       : code == kUsage    ? "usage"
                       : code == kTimedOut ? "timed_out"
                                           : "crashed";
  report["status"] = status;
  hsr::AtomicFile file(path, "bench");
  file.stream() << report.dump(2) << "\n";
  file.commit();
}

}  // namespace hsr::bench
