// `hsr batch` as a user runs it, on a handful of tiny synth scans (a few thousand points each): one output,
// report and log per input, summary.csv in input order, a failed or crashed input recorded and skipped (exec'd
// and forked from the launcher),
// --resume, the same bytes whatever --jobs, forwarded reconstruct options (and a usage error stopping the
// batch), CityJSON outputs equal to the OBJ ones within the grid, and the CityJSONSeq of all buildings.
#include "eval/eval.h"
#include "io/cityjson.h"
#include "io/io.h"
#include "test_util.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <functional>
#include <tuple>
#include <sstream>
#include <fcntl.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace hsr;
using namespace hsr::test;

namespace {

/// Tiny scans made once: box and house (2 scans of the house with other seeds, so stems collide).
class Batch : public ::testing::Test {
 protected:
  static fs::path data;
  static void SetUpTestSuite() {
    data = fs::path(HSR_TEST_TMP_DIR) / "inputs";
    if (fs::exists(data / "house2" / "points.ply")) return;
    fs::create_directories(data);
    for (const auto& [model, dir, seed] : std::vector<std::tuple<std::string, std::string, int>>{
             {"box", "box", 1}, {"house", "house1", 1}, {"house", "house2", 2}}) {
      const CommandResult r = run_cli("synth " + model + " -o '" + (data / dir).string() + "' --points 2500 --seed " +
                                      std::to_string(seed) + " -q");
      ASSERT_EQ(r.exit_code, 0) << r.output;
    }
    write_file(data / "broken.xyz", "1 2 3\nnot numbers\n");
  }
  static std::string in(const std::string& dir) { return "'" + (data / dir / "points.ply").string() + "'"; }
  static std::string three() { return in("box") + " " + in("house1") + " " + in("house2"); }
};
fs::path Batch::data;

std::vector<std::vector<std::string>> read_csv(const fs::path& p) {
  std::vector<std::vector<std::string>> rows;
  std::istringstream in(read_file(p));
  std::string line;
  while (std::getline(in, line)) {
    std::vector<std::string> cells;
    std::string cell;
    bool quoted = false;
    for (char c : line) {
      if (c == '"') quoted = !quoted;
      else if (c == ',' && !quoted) cells.push_back(std::exchange(cell, ""));
      else cell += c;
    }
    cells.push_back(cell);
    rows.push_back(cells);
  }
  return rows;
}

/// The summary without its seconds column (timings differ between runs; nothing else may).
std::string summary_without_seconds(const fs::path& dir) {
  std::string out;
  for (auto row : read_csv(dir / "summary.csv")) {
    row.erase(row.begin() + 2);
    for (const auto& c : row) out += c + "|";
    out += "\n";
  }
  return out;
}

/// A CityJSON file's text without the hsr_seconds attributes.
std::string without_seconds(const std::string& text) {
  std::string out;
  std::istringstream in(text);
  std::string line;
  std::function<void(nlohmann::json&)> strip = [&](nlohmann::json& j) {
    if (j.is_object()) {
      j.erase("hsr_seconds");
      for (auto& [k, v] : j.items()) strip(v);
    } else if (j.is_array()) {
      for (auto& v : j) strip(v);
    }
  };
  while (std::getline(in, line)) {
    nlohmann::json j = nlohmann::json::parse(line);
    strip(j);
    out += j.dump() + "\n";
  }
  return out;
}

TEST_F(Batch, OneOutputReportAndLogPerInputAndTheSummaryInInputOrder) {
  const fs::path out = scratch_dir("order");
  const CommandResult r =
      run_cli("batch " + in("house1") + " '" + (data / "broken.xyz").string() + "' " + in("box") + " -o '" + out.string() + "' -j 2");
  EXPECT_EQ(r.exit_code, 1) << r.output;  // one input failed; the batch went on
  EXPECT_NE(r.output.find("batch: 3/3 done (2 ok, 1 failed)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("inputs/min"), std::string::npos) << r.output;
  const auto rows = read_csv(out / "summary.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[0], (std::vector<std::string>{"input", "status", "seconds", "facets", "validity", "p2m_mean", "message"}));
  EXPECT_EQ(rows[1][0], (data / "house1" / "points.ply").string());
  EXPECT_EQ(rows[1][1], "ok");
  EXPECT_EQ(rows[1][4], "valid");
  EXPECT_GE(std::stoi(rows[1][3]), 10);  // a house, not a box
  EXPECT_GT(std::stod(rows[1][5]), 0.0);
  EXPECT_EQ(rows[2][1], "bad-format");
  EXPECT_NE(rows[2][6].find("broken.xyz"), std::string::npos) << rows[2][6];
  EXPECT_EQ(rows[3][1], "ok");
  EXPECT_EQ(rows[3][3], "6");  // the box
  // Names: stems collide ("points"), so the folder is prepended; "broken" is unique.
  for (const char* f : {"house1_points.obj", "house1_points.report.json", "house1_points.log", "box_points.obj",
                        "box_points.report.json", "broken.log"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_FALSE(fs::exists(out / "broken.obj"));
  EXPECT_FALSE(fs::exists(out / "broken.report.json"));
  EXPECT_EQ(read_mesh((out / "box_points.obj").string()).faces.size(), 6u);
}

TEST_F(Batch, SameBytesWhateverTheNumberOfJobs) {
  const fs::path one = scratch_dir("jobs1"), three_jobs = scratch_dir("jobs3");
  ASSERT_EQ(run_cli("batch " + three() + " -o '" + one.string() + "' -j 1 -q --format city.json").exit_code, 0);
  ASSERT_EQ(run_cli("batch " + three() + " -o '" + three_jobs.string() + "' -j 3 -q --format city.json").exit_code, 0);
  EXPECT_EQ(summary_without_seconds(one), summary_without_seconds(three_jobs));
  for (const char* f : {"box_points.city.json", "house1_points.city.json", "house2_points.city.json", "buildings.city.jsonl"})
    EXPECT_EQ(without_seconds(read_file(one / f)), without_seconds(read_file(three_jobs / f))) << f;
}

TEST_F(Batch, CityJsonOutputsAreValidSolidsEqualToTheObjOutputs) {
  const fs::path obj = scratch_dir("as_obj"), city = scratch_dir("as_city");
  ASSERT_EQ(run_cli("batch " + three() + " -o '" + obj.string() + "' -q").exit_code, 0);
  ASSERT_EQ(run_cli("batch " + three() + " -o '" + city.string() + "' -q --format city.json --crs EPSG:28992").exit_code, 0);
  const CityModel seq = read_cityjson((city / "buildings.city.jsonl").string());
  EXPECT_EQ(seq.reference_system, "https://www.opengis.net/def/crs/EPSG/0/28992");
  ASSERT_EQ(seq.buildings.size(), 3u);
  const std::vector<std::string> names{"box_points", "house1_points", "house2_points"};
  for (std::size_t i = 0; i < names.size(); ++i) {
    EXPECT_EQ(seq.buildings[i].id, names[i]);  // input order
    const PolygonMesh ref = read_mesh((obj / (names[i] + ".obj")).string());
    for (const PolygonMesh& m : {read_mesh((city / (names[i] + ".city.json")).string()), seq.buildings[i].mesh}) {
      EXPECT_TRUE(check_validity(m).valid()) << names[i];
      ASSERT_EQ(m.faces, ref.faces) << names[i];
      ASSERT_EQ(m.vertices.size(), ref.vertices.size());
      for (std::size_t v = 0; v < ref.vertices.size(); ++v)
        EXPECT_LE((m.vertices[v] + m.origin - ref.vertices[v] - ref.origin).cwiseAbs().maxCoeff(), 0.0005 + 1e-9);
    }
    EXPECT_EQ(seq.buildings[i].attributes["hsr_valid"], true);
    EXPECT_EQ(seq.buildings[i].attributes["hsr_facets"], ref.faces.size());
  }
  // The sequence: a header line, then one feature per building.
  const std::string text = read_file(city / "buildings.city.jsonl");
  EXPECT_EQ(std::count(text.begin(), text.end(), '\n'), 4);
  EXPECT_EQ(nlohmann::json::parse(text.substr(0, text.find('\n')))["CityObjects"], nlohmann::json::object());
}

TEST_F(Batch, TheSequenceTakesTheFinestScaleABuildingNeeded) {
  // On a 50 cm grid the box (4 x 3 x 2 m) survives and the house (roof lines at other heights) does not: its
  // file falls back to a finer grid, and the sequence takes that grid for every building, each still equal
  // to its own file.
  const fs::path out = scratch_dir("finer");
  ASSERT_EQ(run_cli("batch " + in("box") + " " + in("house1") + " -o '" + out.string() +
                    "' -q --format city.json --cityjson-scale 0.5").exit_code, 0);
  const CityModel box = read_cityjson((out / "box_points.city.json").string());
  const CityModel house = read_cityjson((out / "house1_points.city.json").string());
  const CityModel seq = read_cityjson((out / "buildings.city.jsonl").string());
  EXPECT_EQ(box.scale, 0.5);
  EXPECT_LT(house.scale, 0.5);
  EXPECT_NE(read_file(out / "house1_points.log").find("written at scale"), std::string::npos);
  EXPECT_EQ(seq.scale, house.scale);
  ASSERT_EQ(seq.buildings.size(), 2u);
  for (const auto& [file, feature] : {std::pair{&box, &seq.buildings[0]}, std::pair{&house, &seq.buildings[1]}}) {
    const PolygonMesh& a = file->buildings[0].mesh;
    const PolygonMesh& b = feature->mesh;
    EXPECT_EQ(a.faces, b.faces);
    ASSERT_EQ(a.vertices.size(), b.vertices.size());
    for (std::size_t v = 0; v < a.vertices.size(); ++v) EXPECT_LE((a.vertices[v] + a.origin - b.vertices[v] - b.origin).norm(), 1e-9);
    EXPECT_TRUE(check_validity(b).valid());
  }
}

TEST_F(Batch, ResumeSkipsWhatIsDoneAndRedoesTheRest) {
  const fs::path out = scratch_dir("resume");
  ASSERT_EQ(run_cli("batch " + three() + " -o '" + out.string() + "' -q").exit_code, 0);
  const std::string first_summary = summary_without_seconds(out);
  fs::remove(out / "house2_points.obj");
  const std::string kept_log = read_file(out / "box_points.log");
  write_file(out / "box_points.log", "untouched");  // a resumed input's child is not run again
  const CommandResult r = run_cli("batch " + three() + " -o '" + out.string() + "' --resume");
  EXPECT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("2 of 3 inputs already done"), std::string::npos) << r.output;
  EXPECT_EQ(read_file(out / "box_points.log"), "untouched");
  EXPECT_TRUE(fs::exists(out / "house2_points.obj"));
  EXPECT_EQ(summary_without_seconds(out), first_summary);
}

TEST_F(Batch, ACrashingChildIsRecordedAndTheOthersRun) {
  const fs::path out = scratch_dir("crash");
  // A stand-in for hsr that dies by SIGSEGV on the house1 input and runs hsr for the others.
  const fs::path fake = out / "fake_hsr.sh";
  write_file(fake, "#!/bin/sh\ncase \"$2\" in *house1*) kill -SEGV $$;; esac\nexec '" + std::string(HSR_CLI_PATH) + "' \"$@\"\n");
  fs::permissions(fake, fs::perms::owner_all);
  const CommandResult r = run_cli("batch " + three() + " -o '" + (out / "o").string() + "' -q --hsr '" + fake.string() + "'");
  EXPECT_EQ(r.exit_code, 1) << r.output;
  const auto rows = read_csv(out / "o" / "summary.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[1][1], "ok");
  EXPECT_EQ(rows[2][1], "crashed (signal 11)");
  EXPECT_EQ(rows[3][1], "ok");
}

/// The process other than this one that holds `fifo` open, or -1 (scans /proc/PID/fd).
pid_t holder_of(const fs::path& fifo) {
  for (const auto& proc : fs::directory_iterator("/proc")) {
    const std::string name = proc.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos || std::stoi(name) == ::getpid()) continue;
    std::error_code ec;
    for (const auto& fd : fs::directory_iterator(proc.path() / "fd", ec)) {
      std::error_code link_ec;
      if (fs::read_symlink(fd.path(), link_ec) == fifo) return std::stoi(name);
    }
  }
  return -1;
}

TEST_F(Batch, ACrashThroughTheLauncherStopsOneInputAndTheOthersRun) {
  // The default path: children forked from the launcher (driver/launcher.h), not exec'd. The second input is a
  // FIFO: its child blocks reading it, the test finds that process and kills it by SIGSEGV, as a crash would.
  const fs::path out = scratch_dir("launcher_crash");
  const fs::path fifo = out / "fifo.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string cmd = std::string(HSR_CLI_PATH) + " batch " + in("box") + " '" + fifo.string() + "' " + in("house2") +
                          " -o '" + (out / "o").string() + "' -q -j 1 > '" + (out / "run.txt").string() + "' 2>&1";
  const pid_t run = ::fork();
  ASSERT_GE(run, 0);
  if (run == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  int writer = -1;  // opens once the child has the FIFO open for reading (ENXIO before)
  for (int i = 0; i < 1200 && writer < 0; ++i) {
    writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (writer < 0) ::usleep(50000);
  }
  ASSERT_GE(writer, 0) << "no child opened the FIFO in 60 s";
  pid_t child = -1;
  for (int i = 0; i < 200 && child < 0; ++i) {
    child = holder_of(fifo);
    if (child < 0) ::usleep(20000);
  }
  ASSERT_GT(child, 0);
  ::kill(child, SIGSEGV);
  ::close(writer);
  int status = 0;
  ::waitpid(run, &status, 0);
  EXPECT_EQ(WEXITSTATUS(status), 1) << read_file(out / "run.txt");
  const auto rows = read_csv(out / "o" / "summary.csv");
  ASSERT_EQ(rows.size(), 4u);
  EXPECT_EQ(rows[1][1], "ok");
  EXPECT_EQ(rows[2][1], "crashed (signal 11)");
  EXPECT_EQ(rows[3][1], "ok");  // the batch went on
}

/// When process `pid` started, seconds since the epoch (/proc/PID/stat's start time after /proc/stat's btime).
double process_start_time(pid_t pid) {
  std::istringstream boot(read_file("/proc/stat"));
  double btime = 0;
  for (std::string key; boot >> key;)
    if (key == "btime") boot >> btime;
  const std::string stat = read_file("/proc/" + std::to_string(pid) + "/stat");
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));  // after the command name, which may hold spaces
  std::string f;
  for (int i = 3; i <= 22; ++i) fields >> f;  // field 22: start time in clock ticks after boot
  return btime + std::stod(f) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

/// A shell command started in a child process (its pid in `run`; with `exec` in front of the program, the program
/// itself), then the write end of the FIFO it reads (`writer`) and the process holding the FIFO open
/// (`holder`, holder_of); -1 where one did not come within a minute.
struct FifoRun {
  pid_t run = -1;
  int writer = -1;
  pid_t holder = -1;
};
FifoRun start_reading_fifo(const std::string& cmd, const fs::path& fifo) {
  FifoRun r;
  r.run = ::fork();
  if (r.run < 0) return r;
  if (r.run == 0) {
    ::execl("/bin/sh", "sh", "-c", cmd.c_str(), static_cast<char*>(nullptr));
    std::_Exit(127);
  }
  for (int i = 0; i < 1200 && r.writer < 0; ++i) {
    r.writer = ::open(fifo.c_str(), O_WRONLY | O_NONBLOCK);
    if (r.writer < 0) ::usleep(50000);
  }
  for (int i = 0; i < 200 && r.writer >= 0 && r.holder < 0; ++i) {
    r.holder = holder_of(fifo);
    if (r.holder < 0) ::usleep(20000);
  }
  return r;
}

TEST_F(Batch, AWorkerRunsItsJobsInputsInTurnAndACrashEndsOnlyTheInputItWasRunning) {
  // One job: one worker runs box, then house1, then blocks reading the FIFO; the test kills it by SIGSEGV. The
  // process holding the FIFO must be the one that ran box (it started before box's log was last written: a
  // process of its own per input would start after), the FIFO input is "crashed", and house2 runs in a new worker.
  const fs::path out = scratch_dir("worker_crash");
  const fs::path fifo = out / "fifo.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string cmd = std::string(HSR_CLI_PATH) + " batch " + in("box") + " " + in("house1") + " '" + fifo.string() +
                          "' " + in("house2") + " -o '" + (out / "o").string() + "' -q -j 1 > '" +
                          (out / "run.txt").string() + "' 2>&1";
  const auto [run, writer, worker] = start_reading_fifo(cmd, fifo);
  ASSERT_GE(run, 0);
  ASSERT_GE(writer, 0) << "no child opened the FIFO in 60 s";
  ASSERT_GT(worker, 0);
  const double started = process_start_time(worker);
  const auto box_log = fs::last_write_time(out / "o" / "box_points.log");
  const double box_log_written =
      std::chrono::duration<double>(std::chrono::file_clock::to_sys(box_log).time_since_epoch()).count();
  ::kill(worker, SIGSEGV);
  ::close(writer);
  int status = 0;
  ::waitpid(run, &status, 0);
  EXPECT_LT(started, box_log_written) << "the FIFO's process started after box was done: not a worker";
  EXPECT_EQ(WEXITSTATUS(status), 1) << read_file(out / "run.txt");
  const auto rows = read_csv(out / "o" / "summary.csv");
  ASSERT_EQ(rows.size(), 5u);
  EXPECT_EQ(rows[1][1], "ok");
  EXPECT_EQ(rows[2][1], "ok");
  EXPECT_EQ(rows[3][1], "crashed (signal 11)");
  EXPECT_EQ(rows[4][1], "ok");  // a new worker
}

/// Process `pid`'s parent (/proc/PID/stat's fourth field), or -1.
pid_t parent_of(pid_t pid) {
  std::error_code ec;
  if (!fs::exists("/proc/" + std::to_string(pid) + "/stat", ec)) return -1;
  const std::string stat = read_file("/proc/" + std::to_string(pid) + "/stat");
  std::istringstream fields(stat.substr(stat.rfind(')') + 2));
  std::string state;
  pid_t parent = -1;
  fields >> state >> parent;
  return parent;
}

/// Whether process `pid` has TBB's malloc proxy mapped.
bool maps_tbb_proxy(pid_t pid) {
  return read_file("/proc/" + std::to_string(pid) + "/maps").find("libtbbmalloc_proxy") != std::string::npos;
}

TEST_F(Batch, AskedForTheLaunchersProcessesAllocateWithTbbAndTheDriverWithGlibc) {
  // DECISIONS #181: with HSR_WORKER_MALLOC=tbb the launcher is exec'd with TBB's malloc proxy preloaded, so a worker
  // (forked from it) has the proxy mapped and the driver (the worker's ancestor running `batch`) has not; by default
  // the worker is on glibc's malloc as the driver. The worker is found as the process holding a FIFO input open.
#if !defined(HSR_WORKER_ALLOCATOR)
  GTEST_SKIP() << "built without the workers' allocator (sanitizers, or no TBB::tbbmalloc_proxy)";
#else
  for (const bool glibc : {false, true}) {
    SCOPED_TRACE(glibc ? "default" : "HSR_WORKER_MALLOC=tbb");
    const fs::path out = scratch_dir(glibc ? "allocator_glibc" : "allocator_tbb");
    const fs::path fifo = out / "fifo.ply";
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    const std::string cmd = std::string(glibc ? "" : "HSR_WORKER_MALLOC=tbb ") + "exec " + HSR_CLI_PATH +
                            " batch '" + fifo.string() + "' -o '" + (out / "o").string() + "' -q -j 1 > '" +
                            (out / "run.txt").string() + "' 2>&1";
    const auto [run, writer, worker] = start_reading_fifo(cmd, fifo);
    ASSERT_GE(run, 0);
    ASSERT_GE(writer, 0) << "no child opened the FIFO in 60 s";
    ASSERT_GT(worker, 0);
    const bool worker_tbb = maps_tbb_proxy(worker), driver_tbb = maps_tbb_proxy(run);  // `exec`: run is the driver
    bool driver_is_ancestor = false;
    for (pid_t p = parent_of(worker); p > 1 && !driver_is_ancestor; p = parent_of(p)) driver_is_ancestor = p == run;
    ::kill(worker, SIGKILL);
    ::close(writer);
    int status = 0;
    ::waitpid(run, &status, 0);
    EXPECT_TRUE(driver_is_ancestor) << "the FIFO's holder is not the driver's descendant";
    EXPECT_EQ(worker_tbb, !glibc);
    EXPECT_FALSE(driver_tbb);
    EXPECT_EQ(WEXITSTATUS(status), 1) << read_file(out / "run.txt");  // the killed input failed, the batch ended
  }
#endif
}

/// Process `pid`'s anonymous resident memory (/proc/PID/smaps_rollup's Anonymous), bytes; -1 when unreadable.
long anonymous_bytes(pid_t pid) {
  std::istringstream in(read_file("/proc/" + std::to_string(pid) + "/smaps_rollup"));
  std::string key;
  long kb = -1;
  while (in >> key)
    if (key == "Anonymous:" && in >> kb) return kb * 1024;
  return -1;
}

TEST_F(Batch, TheLauncherAndASlotsMonitorHoldNoRequestBufferResident) {
  // DECISIONS #244: the launcher, each slot's monitor and each worker receive requests into a buffer of 1 MiB
  // (launcher.cpp kMaxRequestBytes) whose pages are written only by the messages (a few hundred bytes): the
  // launcher and the monitor, idle while the worker reads a FIFO input, each hold less anonymous memory than
  // the buffer's size (with a zeroed buffer: 1.4 and 2.4 MB).
#if defined(__SANITIZE_ADDRESS__)
  GTEST_SKIP() << "AddressSanitizer's shadow and quarantine are anonymous memory";
#endif
  constexpr long kRequestBufferBytes = 1 << 20;
  const fs::path out = scratch_dir("request_buffers");
  const fs::path fifo = out / "fifo.ply";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string cmd = "exec " + std::string(HSR_CLI_PATH) + " batch '" + fifo.string() + "' -o '" +
                          (out / "o").string() + "' -q -j 1 > '" + (out / "run.txt").string() + "' 2>&1";
  const auto [run, writer, worker] = start_reading_fifo(cmd, fifo);
  ASSERT_GE(run, 0);
  ASSERT_GE(writer, 0) << "no child opened the FIFO in 60 s";
  ASSERT_GT(worker, 0);
  const pid_t monitor = parent_of(worker), launcher = monitor > 0 ? parent_of(monitor) : -1;
  const long monitor_bytes = monitor > 0 ? anonymous_bytes(monitor) : -1;
  const long launcher_bytes = launcher > 0 ? anonymous_bytes(launcher) : -1;
  const pid_t driver = launcher > 0 ? parent_of(launcher) : -1;
  ::kill(worker, SIGKILL);
  ::close(writer);
  int status = 0;
  ::waitpid(run, &status, 0);
  EXPECT_EQ(driver, run) << "the worker's grandparent is not the driver's child";  // `exec`: run is the driver
  ASSERT_GE(monitor_bytes, 0);
  ASSERT_GE(launcher_bytes, 0);
  EXPECT_LT(monitor_bytes, kRequestBufferBytes);
  EXPECT_LT(launcher_bytes, kRequestBufferBytes);
}

TEST_F(Batch, WorkersAndFreshProcessesLeaveTheSameFiles) {
  // The workers (the default) against a process per input (--fresh-processes): meshes, logs, reports' figures
  // but time and memory, and the summary (a failed input included) the same.
  const fs::path out = scratch_dir("workers");
  const std::string inputs = three() + " '" + (data / "broken.xyz").string() + "'";  // two each for two workers
  const CommandResult workers = run_cli("batch " + inputs + " -o '" + (out / "o").string() + "' -q -j 2");
  fs::rename(out / "o", out / "w");
  const CommandResult fresh = run_cli("batch " + inputs + " -o '" + (out / "o").string() + "' -q -j 2 --fresh-processes");
  fs::rename(out / "o", out / "f");
  EXPECT_EQ(workers.exit_code, 1) << workers.output;  // broken.xyz fails, in both
  EXPECT_EQ(fresh.exit_code, 1) << fresh.output;
  EXPECT_EQ(summary_without_seconds(out / "w"), summary_without_seconds(out / "f"));
  int files = 0;
  for (const auto& entry : fs::directory_iterator(out / "w")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".obj" && entry.path().extension() != ".log") continue;
    ++files;
    EXPECT_EQ(read_file(entry.path()), read_file(out / "f" / name)) << name;
  }
  EXPECT_EQ(files, 4 + 3);  // four logs, three meshes (broken.xyz has none)
}

TEST_F(Batch, ChildrenThroughTheLauncherAreWhatExecdChildrenAre) {
  // By default the children are forked from the launcher (driver/launcher.h); --hsr naming the same program
  // by another path makes the driver exec it instead. Both must leave the same files: meshes, logs, and the
  // summary (a failed input included), seconds aside.
  const fs::path out = scratch_dir("launcher");
  const fs::path link = out / "hsr_by_another_path";
  fs::create_symlink(HSR_CLI_PATH, link);
  const std::string inputs = three() + " '" + (data / "broken.xyz").string() + "'";
  // The same output folder for both (the logs name it): the first run's is moved aside.
  const CommandResult launched = run_cli("batch " + inputs + " -o '" + (out / "o").string() + "' -q -j 2");
  fs::rename(out / "o", out / "l");
  const CommandResult execd = run_cli("batch " + inputs + " -o '" + (out / "o").string() + "' -q -j 2 --hsr '" + link.string() + "'");
  fs::rename(out / "o", out / "e");
  EXPECT_EQ(launched.exit_code, 1) << launched.output;  // broken.xyz fails, in both
  EXPECT_EQ(execd.exit_code, 1) << execd.output;
  EXPECT_EQ(summary_without_seconds(out / "l"), summary_without_seconds(out / "e"));
  int meshes = 0;
  for (const auto& entry : fs::directory_iterator(out / "l")) {
    const std::string name = entry.path().filename().string();
    if (entry.path().extension() != ".obj" && entry.path().extension() != ".log") continue;
    meshes += entry.path().extension() == ".obj";
    EXPECT_EQ(read_file(entry.path()), read_file(out / "e" / name)) << name;
  }
  EXPECT_EQ(meshes, 3);
}

TEST_F(Batch, ForwardedOptionsReachReconstructAndAUsageErrorStopsTheBatch) {
  const fs::path out = scratch_dir("forward");
  ASSERT_EQ(run_cli("batch " + in("house1") + " -o '" + out.string() + "' -q --partition bsp --lambda 2 -- --no-recovery").exit_code, 0);
  const auto report = nlohmann::json::parse(read_file(out / "points.report.json"));
  EXPECT_EQ(report["parameters"]["partition"]["method"], "bsp");
  EXPECT_EQ(report["parameters"]["extraction"]["lambda"], 2.0);
  EXPECT_EQ(report["parameters"]["hulls"]["recovered_planes"], false);
  const CommandResult bad = run_cli("batch " + three() + " -o '" + (out / "bad").string() + "' -j 1 -- --no-such-option");
  EXPECT_NE(bad.exit_code, 0);
  EXPECT_NE(bad.output.find("hsr: batch: reconstruct rejected the options"), std::string::npos) << bad.output;
  EXPECT_NE(bad.output.find("no-such-option"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(out / "bad" / "summary.csv"));
  EXPECT_FALSE(fs::exists(out / "bad" / "house1_points.log"));  // stopped after the first input
}

TEST_F(Batch, BadBatchArgumentsFailBeforeAnyRun) {
  const fs::path out = scratch_dir("args");
  for (const std::string& args : {in("box") + " " + in("box") + " -o '" + out.string() + "/a'",
                                  in("box") + " -o '" + out.string() + "/c' --format city.json --crs 28992"}) {
    const CommandResult r = run_cli("batch " + args);
    EXPECT_NE(r.exit_code, 0) << args;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_EQ(r.output.rfind("hsr: ", 0), 0u) << r.output;
  }
  EXPECT_NE(run_cli("batch " + in("box") + " -o '" + out.string() + "/b' --format stl").exit_code, 0);
  for (const char* d : {"a", "b", "c"}) EXPECT_FALSE(fs::exists(out / d / "summary.csv")) << d;
}

TEST_F(Batch, ReconstructWritesCityJsonWithTheRunsFiguresAndTheGivenScale) {
  const fs::path out = scratch_dir("single");
  const std::string model = (out / "house.city.json").string();
  const CommandResult r = run_cli("reconstruct " + in("house1") + " -o '" + model + "' --cityjson-scale 0.0001 --crs EPSG:7415 -q");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const nlohmann::json doc = nlohmann::json::parse(read_file(model));
  EXPECT_EQ(doc["transform"]["scale"], nlohmann::json::parse("[0.0001, 0.0001, 0.0001]"));
  EXPECT_EQ(doc["metadata"]["referenceSystem"], "https://www.opengis.net/def/crs/EPSG/0/7415");
  const nlohmann::json& b = doc["CityObjects"]["house"];
  EXPECT_EQ(b["type"], "Building");
  EXPECT_EQ(b["attributes"]["hsr_validity"], "valid");
  EXPECT_GE(b["attributes"]["hsr_facets"].get<int>(), 10);
  const nlohmann::json& sem = b["geometry"][0]["semantics"];
  std::vector<std::string> types;
  for (const auto& s : sem["surfaces"]) types.push_back(s["type"]);
  EXPECT_EQ(types, (std::vector<std::string>{"RoofSurface", "WallSurface", "GroundSurface"}));
  // hsr eval reads it back (read_mesh dispatch).
  const CommandResult e = run_cli("eval " + in("house1") + " '" + model + "'");
  EXPECT_EQ(e.exit_code, 0) << e.output;
  EXPECT_NE(e.output.find("valid"), std::string::npos) << e.output;
  EXPECT_NE(run_cli("reconstruct " + in("box") + " -o '" + (out / "x.city.json").string() + "' --crs 7415").exit_code, 0);
  EXPECT_FALSE(fs::exists(out / "x.city.json"));
}

}  // namespace
