// call_in_child (child_call.h): fork, a pipe, CBOR.
#include "city/child_call.h"

#include "city/city_internal.h"
#include "core/error.h"

#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>
#include <vector>

namespace hsr {

namespace {

[[noreturn]] void internal(const std::string& what) { throw Error(Status::Internal, kCityStage, what); }

/// The members of the child's message: its answer, or the error it threw.
constexpr const char* kAnswer = "answer";
constexpr const char* kErrorStatus = "status";
constexpr const char* kErrorStage = "stage";
constexpr const char* kErrorMessage = "message";

/// What the child sends: {answer} or {status, stage, message} of the error `call` threw.
nlohmann::json child_message(const std::function<nlohmann::json()>& call) {
  try {
    return {{kAnswer, call()}};
  } catch (const Error& e) {
    return {{kErrorStatus, static_cast<int>(e.status())}, {kErrorStage, e.stage()}, {kErrorMessage, e.what()}};
  } catch (const std::exception& e) {
    return {{kErrorStatus, static_cast<int>(Status::Internal)}, {kErrorStage, kCityStage}, {kErrorMessage, e.what()}};
  }
}

/// Writes all of `bytes` to `fd`; false when the pipe fails (the parent gone).
bool write_all(int fd, const std::vector<std::uint8_t>& bytes) {
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<std::size_t>(n);
  }
  return true;
}

/// The child: runs the call, sends its message, ends without running anything of the parent's exit.
[[noreturn]] void run_child(int fd, const std::function<nlohmann::json()>& call) {
  bool sent = false;
  try {
    sent = write_all(fd, nlohmann::json::to_cbor(child_message(call)));
  } catch (...) {
  }
  ::_exit(sent ? 0 : 1);
}

/// Everything the child writes until it closes its end.
std::vector<std::uint8_t> read_all(int fd) {
  std::vector<std::uint8_t> out;
  std::uint8_t buf[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buf, sizeof buf);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return out;
    out.insert(out.end(), buf, buf + n);
  }
}

/// The child's wait status, once it has ended.
int wait_for(pid_t pid) {
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return status;
}

/// Why a child that sent no answer ended: its signal, or its exit code.
std::string how_it_ended(int status) {
  if (WIFSIGNALED(status))
    return "ended by signal " + std::to_string(WTERMSIG(status)) + " (" + strsignal(WTERMSIG(status)) + ")";
  return "exited with code " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}

}  // namespace

nlohmann::json call_in_child(const std::string& what, const std::function<nlohmann::json()>& call) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) internal(what + ": no pipe for its child process (" + std::strerror(errno) + ")");
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    internal(what + ": its child process could not start (" + std::strerror(e) + ")");
  }
  if (pid == 0) {
    ::close(fds[0]);
    run_child(fds[1], call);
  }
  ::close(fds[1]);
  const std::vector<std::uint8_t> bytes = read_all(fds[0]);
  ::close(fds[0]);
  const int status = wait_for(pid);
  const nlohmann::json message = nlohmann::json::from_cbor(bytes, true, false);
  const bool exited = WIFEXITED(status) && WEXITSTATUS(status) == 0;
  if (!exited || !message.is_object()) internal(what + ": its child process " + how_it_ended(status) + " without an answer");
  if (message.contains(kAnswer)) return message.at(kAnswer);
  throw Error(static_cast<Status>(message.at(kErrorStatus).get<int>()), message.at(kErrorStage).get<std::string>(),
              message.at(kErrorMessage).get<std::string>());
}

}  // namespace hsr
