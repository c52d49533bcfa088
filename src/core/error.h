// Error policy of hsr (one place, as the style guide asks).
//
// Stages report *user-facing* failures (bad input, no plane found, invalid output, budget exceeded) by
// throwing hsr::Error: a Status code, the stage that failed, and a one-line message that names the file
// or the quantity at fault. The boundaries (CLI, pipeline report, Python module) catch it and turn it
// into an exit code / status field; nothing half-written is left behind (see atomic_file.h).
// Programming errors (broken invariants) use HSR_ASSERT, which is always on and aborts with a location.
#pragma once

#include <stdexcept>
#include <string>

namespace hsr {

enum class Status {
  Ok = 0,
  FileNotFound,       ///< input path does not exist or cannot be opened
  BadFormat,          ///< unknown extension, corrupt or truncated file
  BadInput,           ///< NaN/inf, zero points, all points identical, ...
  NoPlanes,           ///< plane detection found nothing usable
  DegenerateInput,    ///< e.g. all points on one plane: no volume can be enclosed
  InvalidOutput,      ///< output mesh failed the validity checks
  BudgetExceeded,     ///< --max-seconds / --max-memory
  NotImplemented,     ///< pipeline stage not built yet
  Internal,           ///< a bug: please report
};

const char* status_name(Status s);
/// Process exit code for a status (0 for Ok, distinct small integers otherwise).
int exit_code(Status s);

class Error : public std::runtime_error {
 public:
  Error(Status status, std::string stage, const std::string& message)
      : std::runtime_error(message), status_(status), stage_(std::move(stage)) {}
  Status status() const { return status_; }
  const std::string& stage() const { return stage_; }
  /// "stage: message" on one line.
  std::string one_line() const { return stage_.empty() ? what() : stage_ + ": " + what(); }

 private:
  Status status_;
  std::string stage_;
};

[[noreturn]] void assertion_failed(const char* expr, const char* file, int line, const std::string& msg);

}  // namespace hsr

#define HSR_ASSERT(cond, msg) \
  do { if (!(cond)) ::hsr::assertion_failed(#cond, __FILE__, __LINE__, (msg)); } while (0)
