// The launcher (launcher.h): a copy of the program forked before main() does anything, which forks child runs.
//
// Processes: the driver (the parent), the launcher L (single-threaded, forked first thing in main), and per
// child run a monitor M forked by L and the child C forked by M. M opens the child's stdin and log, waits for
// C and sends its wait status back; L never waits, so it keeps taking requests while children run.
// A run with a slot goes to that slot's monitor S instead (forked by L on the slot's first run, with a socket
// pair of its own): S keeps one worker W (forked by S, started again after it ends), hands it the run, and
// sends back W's reply, or W's wait status when W ended during the run.
// Messages go over SOCK_SEQPACKET socket pairs (one message per request or reply, never interleaved):
//   request  u64 id, i32 slot (-1: none), u32 count, then count strings (u32 length + bytes): the log path, then argv
//   reply    u64 id, i32 kind (0: wait status, 1: errno of a failed start), i32 value
#include "driver/launcher.h"

#include "core/memory.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

namespace hsr::driver {

namespace {

/// The largest request the launcher takes (a child's argv and log path), bytes.
constexpr std::size_t kMaxRequestBytes = 1 << 20;
/// The most worker slots (a driver's jobs at once) the launcher keeps.
constexpr std::int32_t kMaxSlots = 4096;

/// A request's buffer of kMaxRequestBytes whose pages are not written before a message fills them, so that only
/// what the messages reach is resident. Why: a zeroed vector made the launcher, each slot monitor and each worker
/// hold the whole MiB resident (about 3 MB of the processes' summed PSS at `hsr city -j 1` by turns, DECISIONS
/// #244), for messages of a few hundred bytes.
class RequestBuffer {
 public:
  char* data() { return bytes_.get(); }
  std::size_t size() const { return kMaxRequestBytes; }

 private:
  std::unique_ptr<char[]> bytes_{new char[kMaxRequestBytes]};  // default-initialized: no byte written
};

enum ReplyKind : std::int32_t { kWaitStatus = 0, kStartErrno = 1 };

struct Reply {
  std::uint64_t id = 0;
  std::int32_t kind = kWaitStatus;
  std::int32_t value = 0;
};

/// The driver's side: its socket end and the replies not yet taken by their waiting thread.
struct DriverSide {
  int fd = -1;
  pid_t launcher = -1;
  std::mutex send_mu;  ///< one request at a time on the socket
  std::mutex mu;       ///< guards what follows
  std::condition_variable cv;
  std::map<std::uint64_t, Reply> replies;
  std::uint64_t next_id = 1;
  bool reader_started = false;
  bool launcher_gone = false;
};

DriverSide& driver_side() {
  static DriverSide* side = new DriverSide;  // never destroyed: the detached reply reader may outlive main()
  return *side;
}

bool is_driver_command(int argc, char** argv) {
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (!a.empty() && a[0] == '-') continue;  // global flags (-q, -v) come before the command
    return a == "batch" || a == "city";
  }
  return false;
}

void put_u32(std::string& buf, std::uint32_t v) { buf.append(reinterpret_cast<const char*>(&v), sizeof v); }

std::string encode_request(std::uint64_t id, std::int32_t slot, const std::string& log,
                           const std::vector<std::string>& argv) {
  std::string buf(reinterpret_cast<const char*>(&id), sizeof id);
  buf.append(reinterpret_cast<const char*>(&slot), sizeof slot);
  put_u32(buf, static_cast<std::uint32_t>(argv.size() + 1));
  put_u32(buf, static_cast<std::uint32_t>(log.size()));
  buf += log;
  for (const std::string& a : argv) {
    put_u32(buf, static_cast<std::uint32_t>(a.size()));
    buf += a;
  }
  return buf;
}

/// Parses a request; false when it is malformed.
bool decode_request(const char* p, std::size_t n, std::uint64_t& id, std::int32_t& slot,
                    std::vector<std::string>& strings) {
  auto take = [&](void* out, std::size_t k) {
    if (n < k) return false;
    std::memcpy(out, p, k);
    p += k;
    n -= k;
    return true;
  };
  std::uint32_t count = 0;
  if (!take(&id, sizeof id) || !take(&slot, sizeof slot) || !take(&count, sizeof count) || count < 2) return false;
  strings.clear();
  for (std::uint32_t i = 0; i < count; ++i) {
    std::uint32_t len = 0;
    if (!take(&len, sizeof len) || n < len) return false;
    strings.emplace_back(p, len);
    p += len;
    n -= len;
  }
  return n == 0;
}

void send_reply(int fd, std::uint64_t id, ReplyKind kind, int value) {
  const Reply r{id, kind, value};
  (void)::send(fd, &r, sizeof r, MSG_NOSIGNAL);  // the driver may be gone; nothing to tell then
}

/// The monitor M of one request: opens the child's stdin and log (a failure is a failed start, as with
/// posix_spawn), forks the child, waits for it and sends its wait status. Returns only in the child.
bool run_monitor(int fd, std::uint64_t id, const std::vector<std::string>& strings) {
  signal(SIGCHLD, SIG_DFL);  // L ignores it to reap monitors; M must wait for its child
  const int in = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  const int out = in < 0 ? -1 : ::open(strings[0].c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (in < 0 || out < 0) {
    send_reply(fd, id, kStartErrno, errno);
    _exit(0);
  }
  const pid_t child = fork();
  if (child < 0) {
    send_reply(fd, id, kStartErrno, errno);
    _exit(0);
  }
  if (child == 0) {
    ::close(fd);
    if (::dup2(in, 0) < 0 || ::dup2(out, 1) < 0 || ::dup2(out, 2) < 0) _exit(127);
    ::close(in);
    ::close(out);
    return true;
  }
  int status = 0;
  while (waitpid(child, &status, 0) < 0)
    if (errno != EINTR) {
      send_reply(fd, id, kStartErrno, errno);
      _exit(0);
    }
  send_reply(fd, id, kWaitStatus, status);
  _exit(0);
}

/// Forks with a new socket pair between the two processes: the pid (0 in the child) and in `mine` this side's
/// end (the parent's in the parent, the child's in the child; the other end closed); -1 with errno set when the
/// pair or the fork fails.
pid_t fork_with_socket(int& mine) {
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) return -1;
  const pid_t pid = fork();
  if (pid < 0) {
    const int e = errno;
    ::close(sv[0]);
    ::close(sv[1]);
    errno = e;
    return -1;
  }
  ::close(sv[pid == 0 ? 0 : 1]);
  mine = sv[pid == 0 ? 1 : 0];
  return pid;
}

/// Opens /dev/null as stdin and `log` as stdout + stderr of this process; false with errno set when either fails.
bool redirect_to_log(const std::string& log) {
  const int in = ::open("/dev/null", O_RDONLY | O_CLOEXEC);
  if (in < 0) return false;
  const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (out < 0) {
    const int e = errno;
    ::close(in);
    errno = e;
    return false;
  }
  const bool ok = ::dup2(in, 0) >= 0 && ::dup2(out, 1) >= 0 && ::dup2(out, 2) >= 0;
  ::close(in);
  ::close(out);
  return ok;
}

/// The free heap a worker keeps from one run to the next, in bytes (release_free_memory_above): above it, the
/// free pages go back to the system before the next run. 64 MiB: a building's run of a city tile leaves a few MB
/// (the AHN3 tile's largest, 25,000 points, peaks near 30 MB), a large one more; handing back everything after
/// every run cost 200 madvise calls a building and the page faults of taking the pages again (DECISIONS #200).
constexpr std::size_t kWorkerKeptFreeHeapBytes = std::size_t{64} << 20;

/// Between two runs of a worker: what the run printed reaches its log before the reply, the stream formats are
/// a fresh program's, the heap's free pages beyond kWorkerKeptFreeHeapBytes go back to the system and the peak
/// resident memory (VmHWM, which each report states) starts again from what the worker holds (its kept free
/// heap with it), so the next run's figures are its own.
void end_worker_run(const std::ios& fresh_format) {
  std::cout.flush();
  std::cerr.flush();
  std::fflush(nullptr);
  for (std::ostream* os : {&std::cout, &std::cerr, &std::clog}) {
    os->copyfmt(fresh_format);
    os->clear();
  }
  release_free_memory_above(kWorkerKeptFreeHeapBytes);
  const int fd = ::open("/proc/self/clear_refs", O_WRONLY | O_CLOEXEC);
  if (fd >= 0) {
    (void)!::write(fd, "5", 1);  // 5: reset the peak resident set size (proc(5)); without it, the peak stays
    ::close(fd);
  }
}

/// The worker W of a slot: runs each request it is handed with `run_child` and replies with the wait status
/// of a process that exited with the run's code. Ends when its monitor's end closes (or with the run that
/// ends it: a crash, a budget's watchdog, exit()).
[[noreturn]] void run_worker(int fd, const ChildRun& run_child) {
  std::ios fresh_format(nullptr);
  fresh_format.copyfmt(std::cout);
  RequestBuffer buf;
  for (;;) {
    const ssize_t n = ::recv(fd, buf.data(), buf.size(), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) _exit(0);
    std::uint64_t id = 0;
    std::int32_t slot = 0;
    std::vector<std::string> strings;
    if (!decode_request(buf.data(), static_cast<std::size_t>(n), id, slot, strings)) {
      send_reply(fd, id, kStartErrno, EINVAL);
      continue;
    }
    if (!redirect_to_log(strings[0])) {
      send_reply(fd, id, kStartErrno, errno);
      continue;
    }
    const int code = run_child(std::vector<std::string>(strings.begin() + 1, strings.end()));
    end_worker_run(fresh_format);
    send_reply(fd, id, kWaitStatus, W_EXITCODE(code & 0xff, 0));
  }
}

/// The monitor S of a slot: takes the slot's requests from L, runs each in its worker (forking one when there is
/// none) and sends the driver the worker's reply, or, when the worker ended during the run, its wait status.
[[noreturn]] void run_slot(int driver_fd, int from_launcher, const ChildRun& run_child) {
  signal(SIGCHLD, SIG_DFL);  // L ignores it; S waits for its worker
  pid_t worker = -1;
  int to_worker = -1;
  auto reap = [&](int& status) {
    if (to_worker >= 0) ::close(to_worker);
    to_worker = -1;
    while (waitpid(worker, &status, 0) < 0 && errno == EINTR) {
    }
    worker = -1;
  };
  auto start_worker = [&]() {
    int mine = -1;
    const pid_t pid = fork_with_socket(mine);
    if (pid < 0) return false;
    if (pid == 0) {
      ::close(from_launcher);
      ::close(driver_fd);
      signal(SIGCHLD, SIG_DFL);
      run_worker(mine, run_child);
    }
    worker = pid;
    to_worker = mine;
    return true;
  };
  RequestBuffer buf;
  for (;;) {
    const ssize_t n = ::recv(from_launcher, buf.data(), buf.size(), 0);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the launcher is gone: end the worker too
    std::uint64_t id = 0;
    std::memcpy(&id, buf.data(), std::min(sizeof id, static_cast<std::size_t>(n)));
    bool sent = false;
    for (int attempt = 0; attempt < 2 && !sent; ++attempt) {  // a worker that ended while idle is started again
      if (worker < 0 && !start_worker()) break;
      sent = ::send(to_worker, buf.data(), static_cast<std::size_t>(n), MSG_NOSIGNAL) == n;
      if (!sent) {
        int ignored = 0;
        reap(ignored);
      }
    }
    if (!sent) {
      send_reply(driver_fd, id, kStartErrno, errno ? errno : EPIPE);
      continue;
    }
    Reply r;
    ssize_t k;
    do k = ::recv(to_worker, &r, sizeof r, 0);
    while (k < 0 && errno == EINTR);
    if (k == static_cast<ssize_t>(sizeof r)) {
      send_reply(driver_fd, id, static_cast<ReplyKind>(r.kind), r.value);
      continue;
    }
    int status = 0;  // the worker ended during the run: its end is the run's
    reap(status);
    send_reply(driver_fd, id, kWaitStatus, status);
  }
  if (worker > 0) {
    int ignored = 0;
    reap(ignored);
  }
  _exit(0);
}

/// L's end of a new slot monitor's socket (the monitor forked), or -1 with errno set.
int start_slot(int driver_fd, const std::vector<int>& slot_fds, const ChildRun& run_child) {
  int mine = -1;
  const pid_t pid = fork_with_socket(mine);
  if (pid < 0) return -1;
  if (pid == 0) {
    for (int fd : slot_fds)  // the other slots' ends: their monitors must see L's close, not this copy's
      if (fd >= 0) ::close(fd);
    run_slot(driver_fd, mine, run_child);
  }
  return mine;
}

/// The launcher L: takes requests until the driver's end closes, then ends the slots' workers and waits for
/// every process it started. Returns only in a child run without a slot.
bool serve(int fd, std::vector<std::string>& child_argv, const ChildRun& run_child) {
  signal(SIGCHLD, SIG_IGN);  // monitors are reaped by the kernel
  RequestBuffer buf;
  std::vector<int> slot_fds;  // L's end of each slot monitor's socket, -1: none started
  for (;;) {
    const ssize_t n = ::recv(fd, buf.data(), buf.size(), MSG_TRUNC);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // the driver is gone
    std::uint64_t id = 0;
    std::int32_t slot = -1;
    std::vector<std::string> strings;
    if (static_cast<std::size_t>(n) > buf.size() ||
        !decode_request(buf.data(), static_cast<std::size_t>(n), id, slot, strings) || slot >= kMaxSlots) {
      if (static_cast<std::size_t>(n) >= sizeof id) std::memcpy(&id, buf.data(), sizeof id);
      send_reply(fd, id, kStartErrno, E2BIG);
      continue;
    }
    if (slot >= 0) {
      if (slot_fds.size() <= static_cast<std::size_t>(slot)) slot_fds.resize(static_cast<std::size_t>(slot) + 1, -1);
      int& to_slot = slot_fds[static_cast<std::size_t>(slot)];
      if (to_slot < 0) to_slot = start_slot(fd, slot_fds, run_child);
      if (to_slot < 0 || ::send(to_slot, buf.data(), static_cast<std::size_t>(n), MSG_NOSIGNAL) != n)
        send_reply(fd, id, kStartErrno, errno);
      continue;
    }
    const pid_t monitor = fork();
    if (monitor < 0) {
      send_reply(fd, id, kStartErrno, errno);
      continue;
    }
    if (monitor == 0) {
      for (int s : slot_fds)  // the slots' ends stay L's alone (see start_slot)
        if (s >= 0) ::close(s);
      if (run_monitor(fd, id, strings)) {
        child_argv.assign(strings.begin() + 1, strings.end());
        return true;
      }
    }
  }
  for (int s : slot_fds)
    if (s >= 0) ::close(s);
  // With SIGCHLD ignored, wait() returns once every child has ended: nothing L started outlives it.
  while (::wait(nullptr) >= 0 || errno == EINTR) {
  }
  _exit(0);
}

/// The driver's reply reader: hands each reply to its waiting thread; when the launcher is gone, wakes all.
void read_replies() {
  DriverSide& side = driver_side();
  for (;;) {
    Reply r;
    const ssize_t n = ::recv(side.fd, &r, sizeof r, 0);
    if (n < 0 && errno == EINTR) continue;
    std::lock_guard<std::mutex> lock(side.mu);
    if (n != static_cast<ssize_t>(sizeof r)) {
      side.launcher_gone = true;
      side.cv.notify_all();
      return;
    }
    side.replies[r.id] = r;
    side.cv.notify_all();
  }
}

/// At the driver's exit: ends the launcher (its socket's end of file) and waits for it, so that nothing of
/// this program is left running after it, not even for an instant.
void stop_launcher() {
  DriverSide& side = driver_side();
  if (side.fd < 0) return;
  ::shutdown(side.fd, SHUT_RDWR);  // also wakes the reply reader
  while (waitpid(side.launcher, nullptr, 0) < 0 && errno == EINTR) {
  }
}

/// The argument that starts this program as the launcher, exec'd by exec_launcher_with_allocator.
constexpr const char* kLauncherArg = "--hsr-launcher-process";
/// The environment variable naming the launcher's socket end in that process.
constexpr const char* kLauncherFdEnv = "HSR_LAUNCHER_FD";

/// With HSR_WORKER_MALLOC=tbb in the environment, the forked launcher becomes this program again, exec'd with
/// TBB's scalable allocator preloaded (HSR_WORKER_ALLOCATOR, the path of libtbbmalloc_proxy found at build time;
/// DECISIONS #181), so that every child run and worker it forks allocates with it while the driver keeps glibc's
/// malloc. Why: the pipelines make and drop many small vectors (glibc's malloc and free about 12 % of a city
/// tile's profile); in the driver, which reads and splits a survey's tiles in large vectors, TBB's allocator made
/// a survey 1.3 x slower (#173), so only the processes that run buildings get it. Not the default: 3-4 % less
/// wall on a city tile for a third more memory summed over the processes (#181). Returns only when it did not
/// exec (not asked for, no allocator built in, the library missing, or exec failed): the launcher then serves as
/// forked, with glibc's malloc (the same runs, the same bytes).
void exec_launcher_with_allocator(int fd) {
#if defined(HSR_WORKER_ALLOCATOR)
  const char* choice = std::getenv("HSR_WORKER_MALLOC");
  if (!choice || std::string(choice) != "tbb") return;
  if (::access(HSR_WORKER_ALLOCATOR, R_OK) != 0) return;
  char self[4096];
  const ssize_t len = ::readlink("/proc/self/exe", self, sizeof self - 1);
  if (len <= 0) return;
  self[len] = '\0';
  const int flags = ::fcntl(fd, F_GETFD);
  if (flags < 0 || ::fcntl(fd, F_SETFD, flags & ~FD_CLOEXEC) != 0) return;
  const char* preload = std::getenv("LD_PRELOAD");
  const std::string preload_value =
      std::string(HSR_WORKER_ALLOCATOR) + (preload && *preload ? std::string(":") + preload : std::string());
  ::setenv("LD_PRELOAD", preload_value.c_str(), 1);
  ::setenv(kLauncherFdEnv, std::to_string(fd).c_str(), 1);
  char* const args[] = {self, const_cast<char*>(kLauncherArg), nullptr};
  ::execv(self, args);
  // exec failed: serve as forked
  if (preload) ::setenv("LD_PRELOAD", preload, 1);
  else ::unsetenv("LD_PRELOAD");
  ::unsetenv(kLauncherFdEnv);
  (void)::fcntl(fd, F_SETFD, flags);
#else
  (void)fd;
#endif
}

/// In the exec'd launcher (kLauncherArg): its socket end, the environment as the driver's (the preload is
/// done: the children it forks keep the allocator, a program they exec does not get it). -1: not the launcher.
int exec_launcher_fd(int argc, char** argv) {
  if (argc != 2 || std::string(argv[1]) != kLauncherArg) return -1;
  const char* value = std::getenv(kLauncherFdEnv);
  const int fd = value ? std::atoi(value) : -1;
  ::unsetenv(kLauncherFdEnv);
  const char* preload = std::getenv("LD_PRELOAD");
#if defined(HSR_WORKER_ALLOCATOR)
  if (preload) {  // take the allocator back out of the list exec_launcher_with_allocator put it first in
    const std::string list = preload, own = HSR_WORKER_ALLOCATOR;
    if (list == own) ::unsetenv("LD_PRELOAD");
    else if (list.rfind(own + ":", 0) == 0) ::setenv("LD_PRELOAD", list.substr(own.size() + 1).c_str(), 1);
  }
#else
  (void)preload;
#endif
  if (fd < 0 || ::fcntl(fd, F_SETFD, FD_CLOEXEC) != 0) {  // not started by a driver
    std::cerr << "hsr: " << kLauncherArg << " is hsr batch's and hsr city's own (their launcher), not a command\n";
    _exit(2);
  }
  return fd;
}

}  // namespace

bool start_launcher(int argc, char** argv, std::vector<std::string>& child_argv, const ChildRun& run_child) {
  const int exec_fd = exec_launcher_fd(argc, argv);
  if (exec_fd >= 0) return serve(exec_fd, child_argv, run_child);
  if (!is_driver_command(argc, argv)) return false;
  int sv[2];
  if (::socketpair(AF_UNIX, SOCK_SEQPACKET | SOCK_CLOEXEC, 0, sv) != 0) return false;
  const pid_t launcher = fork();
  if (launcher < 0) {
    ::close(sv[0]);
    ::close(sv[1]);
    return false;
  }
  if (launcher == 0) {
    ::close(sv[0]);
    // The launcher prints nothing; it must not hold the driver's output open (a reader of the driver's output
    // waits for every holder to close it, and a monitor lives as long as its child).
    const int null = ::open("/dev/null", O_RDWR);
    if (null >= 0) {
      for (int fd = 0; fd <= 2; ++fd) ::dup2(null, fd);
      if (null > 2) ::close(null);
    }
    exec_launcher_with_allocator(sv[1]);  // returns only when it did not exec
    return serve(sv[1], child_argv, run_child);
  }
  ::close(sv[1]);
  driver_side().fd = sv[0];
  driver_side().launcher = launcher;
  std::atexit(stop_launcher);
  return false;
}

bool launcher_running() {
  DriverSide& side = driver_side();
  std::lock_guard<std::mutex> lock(side.mu);
  return side.fd >= 0 && !side.launcher_gone;
}

bool launch_and_wait(const std::vector<std::string>& argv, const std::string& log, int slot, int& wait_status,
                     std::string& error) {
  DriverSide& side = driver_side();
  std::uint64_t id = 0;
  {
    std::lock_guard<std::mutex> lock(side.mu);
    if (side.fd < 0 || side.launcher_gone) {
      error = "the launcher is not running";
      return false;
    }
    id = side.next_id++;
    if (!side.reader_started) {
      std::thread(read_replies).detach();
      side.reader_started = true;
    }
  }
  const std::string request = encode_request(id, slot < 0 ? -1 : slot, log, argv);
  if (request.size() > kMaxRequestBytes) {
    error = "the child's arguments exceed " + std::to_string(kMaxRequestBytes) + " bytes";
    return false;
  }
  {
    std::lock_guard<std::mutex> lock(side.send_mu);
    if (::send(side.fd, request.data(), request.size(), MSG_NOSIGNAL) != static_cast<ssize_t>(request.size())) {
      error = std::string("the launcher did not take the request: ") + std::strerror(errno);
      return false;
    }
  }
  std::unique_lock<std::mutex> lock(side.mu);
  side.cv.wait(lock, [&] { return side.replies.count(id) > 0 || side.launcher_gone; });
  auto it = side.replies.find(id);
  if (it == side.replies.end()) {
    error = "the launcher stopped before '" + argv[0] + "' ended";
    return false;
  }
  const Reply r = it->second;
  side.replies.erase(it);
  if (r.kind == kStartErrno) {
    error = "cannot start '" + argv[0] + "': " + std::strerror(r.value);
    return false;
  }
  wait_status = r.value;
  return true;
}

}  // namespace hsr::driver
