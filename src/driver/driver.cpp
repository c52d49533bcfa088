// The drivers' shared machinery (driver.h): forwarded options, names, child processes, summary, sequence.
#include "driver/driver.h"
#include "driver/launcher.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "eval/eval.h"
#include "io/cityjson.h"

#include <CLI/CLI.hpp>
#include <tbb/parallel_for.h>

#include <fcntl.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <condition_variable>
#include <cstring>
#include <deque>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <thread>

extern char** environ;

namespace hsr::driver {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const std::string& what) { throw Error(Status::BadInput, "batch", what); }

}  // namespace

// ------------------------------------------------------------------------------------------ forwarded options

const std::vector<ForwardedOption>& forwarded_options() {
  static const std::string help = "Passed to reconstruct (see hsr reconstruct --help)";
  // `hsr city` sets --scene building and each building's --ground-z (from its ground ring) on every child
  // itself (city_run.cpp child_argv): a city's buildings are always building scenes standing on their own
  // ground, so it does not take these two; `hsr batch` knows nothing of its inputs and passes them on.
  static const std::vector<ForwardedOption> options{
      {"--scene", help, true, false},       {"--ground-z", help, true, false},   {"--partition", help, true, true},
      {"--lambda", help, true, true},       {"--detail", help, true, true},      {"--max-seconds", help, true, true},
      {"--max-memory", help, true, true}};
  return options;
}

std::vector<ForwardedOption> forwarded_options(const std::string& driver) {
  if (driver != "batch" && driver != "city") bad("no driver '" + driver + "' (batch, city)");
  std::vector<ForwardedOption> out;
  for (const ForwardedOption& o : forwarded_options())
    if (driver == "batch" ? o.batch : o.city) out.push_back(o);
  return out;
}

void add_forwarded_options(CLI::App& sub, const std::string& driver, std::vector<std::string>& reconstruct_args) {
  for (const ForwardedOption& o : forwarded_options(driver))
    sub.add_option_function<std::string>(
        o.name, [&reconstruct_args, name = o.name](const std::string& v) { reconstruct_args.insert(reconstruct_args.end(), {name, v}); },
        o.help);
}

int take_forwarded_args(int argc, char** argv, const std::string& subcommand, std::vector<std::string>& reconstruct_args) {
  int sub = 1;
  while (sub < argc && argv[sub] != subcommand) ++sub;
  for (int k = sub + 1; k < argc; ++k)
    if (std::string(argv[k]) == "--") {
      reconstruct_args.assign(argv + k + 1, argv + argc);
      return k;
    }
  return argc;
}

// ------------------------------------------------------------------------------------------ names and files

std::string safe_file_name(const std::string& s) {
  std::string out = s;
  for (char& c : out)
    if (!std::isalnum(static_cast<unsigned char>(c)) && c != '.' && c != '-' && c != '_') c = '_';
  return out;
}

namespace {

/// The stem, prefixed by `depth` parent folder names ("house_1_points").
std::string name_at_depth(const fs::path& path, std::size_t depth) {
  std::vector<std::string> parts{path.stem().string()};
  fs::path dir = path.parent_path();
  for (std::size_t d = 0; d < depth && !dir.empty() && dir != dir.root_path(); ++d, dir = dir.parent_path())
    parts.push_back(dir.filename().string());
  std::string name;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) name += (name.empty() ? "" : "_") + *it;
  return safe_file_name(name);
}

}  // namespace

/// Unique names: the file stem, deepened by parent folders only for the inputs whose names collide; the
/// input's index as a last resort (same stem and folders, different extension).
std::vector<std::string> unique_names(const std::vector<std::string>& inputs) {
  std::vector<fs::path> paths;
  for (const auto& in : inputs) paths.push_back(fs::absolute(in).lexically_normal());
  std::vector<std::size_t> depth(inputs.size(), 0);
  std::vector<std::string> names(inputs.size());
  for (int round = 0; round < 64; ++round) {
    std::map<std::string, std::vector<std::size_t>> users;
    for (std::size_t i = 0; i < inputs.size(); ++i) users[names[i] = name_at_depth(paths[i], depth[i])].push_back(i);
    bool collided = false;
    for (const auto& [name, who] : users)
      if (who.size() > 1) {
        collided = true;
        for (std::size_t i : who) ++depth[i];
      }
    if (!collided) return names;
  }
  for (std::size_t i = 0; i < names.size(); ++i) names[i] += "_" + std::to_string(i + 1);
  return names;
}

void require_distinct(const std::vector<std::string>& paths, const std::string& stage, const std::string& what) {
  std::set<fs::path> seen;
  for (const auto& p : paths)
    if (!seen.insert(fs::absolute(p).lexically_normal()).second)
      throw Error(Status::BadInput, stage, what + " given twice: " + p);
}

std::string cli_path(const RunOptions& options, const std::string& stage) {
  if (!options.hsr_cli.empty()) return options.hsr_cli;
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error(Status::BadInput, stage, "cannot find this program's path (/proc/self/exe): " + ec.message());
  return self.string();
}

std::string format_number(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

void write_json(const std::string& path, const nlohmann::json& j, const std::string& stage) {
  AtomicFile f(path, stage);
  f.stream() << j.dump(1) << '\n';
  f.commit();
}

nlohmann::json read_json(const std::string& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in, nullptr, false);
}

// ------------------------------------------------------------------------------------------ child runs

namespace {

/// The child's one-line error: the last line of its log that starts with "hsr: " (without the prefix), or
/// else the first non-empty line (CLI11's usage errors have no prefix).
std::string error_line(const std::string& log_path) {
  std::ifstream in(log_path);
  std::string line, last, first;
  while (std::getline(in, line)) {
    if (line.rfind("hsr: ", 0) == 0) last = line.substr(5);
    if (first.empty()) first = line;
  }
  return last.empty() ? first : last;
}

/// This program's path, as cli_path gives it when no other program is named.
const std::string& self_path() {
  static const std::string path = [] {
    std::error_code ec;
    return fs::read_symlink("/proc/self/exe", ec).string();
  }();
  return path;
}

/// Spawns argv with stdin from /dev/null and stdout + stderr into `log`; waits. False if it could not start.
/// A child of this very program starts through the launcher (launcher.h: no start-up cost); another
/// program (`--hsr`), or no launcher, by posix_spawn.
bool spawn_and_wait(const Item& item, int slot, int& wait_status, std::string& error) {
  if (!item.argv.empty() && item.argv[0] == self_path() && launcher_running())
    return launch_and_wait(item.argv, item.log, slot, wait_status, error);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 0, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, 1, item.log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  std::vector<char*> argv;
  for (const auto& a : item.argv) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    error = "cannot start '" + item.argv[0] + "': " + std::strerror(rc);
    return false;
  }
  while (waitpid(pid, &wait_status, 0) < 0)
    if (errno != EINTR) {
      error = std::string("waitpid: ") + std::strerror(errno);
      return false;
    }
  return true;
}

/// The status name of a child's exit code (core/error.h exit_code), "usage-error" for CLI11's (>= 100).
std::string status_of_exit(int code) {
  if (code >= 100) return "usage-error";
  for (int s = 0; s <= static_cast<int>(Status::Internal); ++s)
    if (exit_code(static_cast<Status>(s)) == code) return status_name(static_cast<Status>(s));
  return "exit-" + std::to_string(code);
}

Row row_from_report(const std::string& input, const nlohmann::json& report) {
  Row row;
  row.input = input;
  row.seconds = report.value("/seconds/total"_json_pointer, 0.0);
  row.facets = report.value("/counts/output_faces"_json_pointer, -1L);
  row.p2m = report.value("/accuracy/p2m_mean"_json_pointer, -1.0);
  row.validity = cityjson_attributes(report).value("hsr_validity", "");
  return row;
}

}  // namespace

std::optional<Row> done_row(const Item& item) {
  if (!fs::exists(item.output) || !fs::exists(item.report)) return std::nullopt;
  const nlohmann::json report = read_json(item.report);
  if (!report.is_object() || report.value("input", "") != item.input || report.value("output", "") != item.output)
    return std::nullopt;
  return row_from_report(item.input, report);
}

Row run_item(const Item& item, int slot) {
  std::error_code ec;
  fs::remove(item.output, ec);  // what is left afterwards is this run's
  fs::remove(item.report, ec);
  const double t0 = log::now_seconds();
  int wait_status = 0;
  std::string error;
  const bool ran = spawn_and_wait(item, slot, wait_status, error);
  Row row;
  row.input = item.input;
  row.seconds = log::now_seconds() - t0;
  if (!ran) {
    row.status = status_name(Status::Internal);
    row.message = error;
  } else if (WIFSIGNALED(wait_status)) {
    row.status = "crashed (signal " + std::to_string(WTERMSIG(wait_status)) + ")";
    row.message = error_line(item.log);
    if (row.message.empty()) row.message = std::string("killed by ") + strsignal(WTERMSIG(wait_status));
  } else if (WEXITSTATUS(wait_status) != 0) {
    row.status = status_of_exit(WEXITSTATUS(wait_status));
    row.message = error_line(item.log);
  } else if (auto done = done_row(item)) {
    return *done;
  } else {
    row.status = status_name(Status::Internal);
    row.message = "reconstruct exited 0 without writing " + item.output + " and its report";
  }
  return row;
}

Turn::Turn(const std::string& path) {
  if (path.empty()) return;
  fd_ = ::open(path.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  int rc = fd_ < 0 ? -1 : 0;
  if (fd_ >= 0)
    while ((rc = ::flock(fd_, LOCK_EX)) < 0 && errno == EINTR) {
    }
  if (rc < 0) {
    log::warn("reconstruct: cannot take the turn " + path + " (" + std::strerror(errno) + "): run without it");
    give_up();
  }
}

void Turn::give_up() {
  if (fd_ >= 0) ::close(fd_);  // closing the file gives its lock up
  fd_ = -1;
}

std::string progress_line(const std::string& label, std::size_t done, std::size_t total, std::size_t failed,
                          std::size_t ran, double elapsed) {
  char buf[200];
  const double per_min = elapsed > 0 ? 60.0 * static_cast<double>(ran) / elapsed : 0.0;
  const double eta_s = per_min > 0 ? 60.0 * static_cast<double>(total - done) / per_min : 0.0;
  std::string eta;
  if (done == total) eta = "done";
  else if (per_min <= 0) eta = "ETA unknown";
  else if (eta_s < 60) eta = "ETA " + std::to_string(static_cast<int>(std::ceil(eta_s))) + " s";
  else eta = "ETA " + std::to_string(static_cast<int>(std::ceil(eta_s / 60))) + " min";
  std::snprintf(buf, sizeof buf, "%s: %zu/%zu done (%zu ok, %zu failed), %.1f inputs/min, %s", label.c_str(), done,
                total, done - failed, failed, per_min, eta.c_str());
  return buf;
}

/// The children of one job at once when they run by turns (run_items' `turns`): one in its turn, one finishing.
/// Three measured no faster on the AHN3 tile with two surfaces (0.92 x against two's 0.92 x of one at a time,
/// DECISIONS #235), and each child is a process holding its memory.
constexpr unsigned kChildrenPerTurn = 2;

void run_items(const std::vector<Item>& items, const std::vector<std::size_t>& todo, unsigned jobs_wanted,
               bool fresh_processes, std::vector<Row>& rows, std::size_t already_done, const std::string& label,
               const std::string& progress, const std::function<void(std::size_t)>& on_done, const std::string& turns) {
  const unsigned jobs = jobs_wanted ? jobs_wanted : std::max(1u, std::thread::hardware_concurrency());
  // a turn is an option of this program's `reconstruct` only (another --hsr would reject it)
  const bool by_turns = !turns.empty() && !todo.empty() && !items[todo[0]].argv.empty() && items[todo[0]].argv[0] == self_path();
  const unsigned lanes = by_turns ? kChildrenPerTurn * jobs : jobs;
  std::atomic<std::size_t> next{0};
  std::atomic<bool> stop{false};
  std::mutex mu;
  std::size_t done = already_done, failed = 0, ran = 0;
  std::string usage_error;
  const double t0 = log::now_seconds();
  auto worker = [&](int slot) {
    for (std::size_t k; !stop && (k = next++) < todo.size();) {
      Item with_turn;
      if (by_turns) {
        with_turn = items[todo[k]];
        with_turn.argv.insert(with_turn.argv.end(), {"--turn", turns + "." + std::to_string(slot % jobs)});
      }
      Row row = run_item(by_turns ? with_turn : items[todo[k]], fresh_processes ? -1 : slot);
      {
        std::lock_guard<std::mutex> lock(mu);
        if (row.status == "usage-error") {
          stop = true;
          usage_error = row.message;
        }
        ++done;
        ++ran;
        if (!row.ok()) ++failed;
        rows[todo[k]] = std::move(row);
        log::info(progress_line(progress.empty() ? label : progress, done, items.size(), failed, ran, log::now_seconds() - t0));
      }
      if (on_done) on_done(todo[k]);
    }
  };
  std::vector<std::thread> pool;
  for (unsigned j = 0; j < std::min<std::size_t>(lanes, todo.size()); ++j) pool.emplace_back(worker, static_cast<int>(j));
  for (auto& t : pool) t.join();
  if (!usage_error.empty())
    throw Error(Status::BadInput, label, "reconstruct rejected the options (" + usage_error + "); nothing more was run");
}

// ------------------------------------------------------------------------------------------ outputs

namespace {

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string q = "\"";
  for (char c : s) q += c == '"' ? std::string("\"\"") : std::string(1, c == '\n' ? ' ' : c);
  return q + "\"";
}

}  // namespace

void write_summary_csv(const std::string& path, const std::vector<Row>& rows, const std::vector<std::string>& extra_header,
                       const std::vector<std::vector<std::string>>& extra) {
  if (!extra.empty() && extra.size() != rows.size()) bad("summary: " + std::to_string(extra.size()) + " extra rows for " + std::to_string(rows.size()));
  AtomicFile f(path, "batch");
  f.stream() << "input,status,seconds,facets,validity,p2m_mean,message";
  for (const std::string& h : extra_header) f.stream() << ',' << csv_field(h);
  f.stream() << '\n';
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const Row& r = rows[i];
    char secs[32], p2m[32];
    std::snprintf(secs, sizeof secs, "%.3f", r.seconds);
    std::snprintf(p2m, sizeof p2m, "%.6g", r.p2m);
    f.stream() << csv_field(r.input) << ',' << r.status << ',' << secs << ','
               << (r.facets >= 0 ? std::to_string(r.facets) : "") << ',' << csv_field(r.validity) << ','
               << (r.p2m >= 0 ? p2m : "") << ',' << csv_field(r.message);
    if (!extra.empty())
      for (const std::string& v : extra[i]) f.stream() << ',' << csv_field(v);
    f.stream() << '\n';
  }
  f.commit();
}

PreparedFeature prepare_feature(const SequenceEntry& entry) {
  PreparedFeature f;
  try {
    f.model = read_cityjson(entry.cityjson);
    if (f.model->buildings.size() != 1)
      throw Error(Status::BadFormat, "batch", entry.cityjson + " holds no single building");
  } catch (const Error& e) {
    f.model.reset();
    f.read_warning = "sequence: " + entry.input + " left out: " + e.one_line();
    return f;
  }
  const CityBuilding& b = f.model->buildings.front();
  f.attributes = entry.before;
  for (const auto& [key, value] : b.attributes.items()) f.attributes[key] = value;
  for (const auto& [key, value] : entry.after.items()) f.attributes[key] = value;
  for (const std::string& key : entry.drop) f.attributes.erase(key);
  if (!entry.lods) return f;
  try {
    FeatureLods more = entry.lods(b, f.attributes, f.model->scale);
    for (const auto& [key, value] : more.attributes.items()) f.attributes[key] = value;
    if (more.keep_read) f.solids.push_back({"2.2", b.mesh});
    for (CityJsonGeometry& g : more.solids) f.solids.push_back(std::move(g));
    if (f.solids.empty()) throw Error(Status::InvalidOutput, "batch", "none of the LoDs asked for could be made");
  } catch (const Error& e) {
    f.solids.clear();
    f.warning = "sequence: " + entry.input + " left out: " + e.one_line();
  }
  return f;
}

std::size_t write_cityjson_sequence(const std::string& path, double scale, const std::string& crs,
                                    const std::vector<SequenceEntry>& entries) {
  return write_cityjson_sequence(path, scale, crs, entries, std::vector<std::optional<PreparedFeature>>(entries.size()));
}

std::size_t write_cityjson_sequence(const std::string& path, double scale, const std::string& crs,
                                    const std::vector<SequenceEntry>& entries,
                                    std::vector<std::optional<PreparedFeature>> prepared) {
  if (prepared.size() != entries.size()) bad("sequence: " + std::to_string(prepared.size()) + " prepared for " + std::to_string(entries.size()) + " entries");
  CityJsonParams params;
  params.scale = scale;
  params.crs = crs;
  params.validate = validity_problem;
  // Each building is read, given its LoDs and checked in a slot of its own, in parallel (a tile's thousand
  // buildings were 6 s of one core after its runs), unless prepared before; the slots are then taken in
  // order, warnings included, so the bytes do not depend on the threads.
  tbb::parallel_for(std::size_t(0), entries.size(), [&](std::size_t i) {
    if (!prepared[i]) prepared[i] = prepare_feature(entries[i]);
  });
  const CityModel* first = nullptr;
  for (const std::optional<PreparedFeature>& f : prepared) {
    if (!f->read_warning.empty()) log::warn(f->read_warning);
    if (!f->model) continue;
    params.scale = std::min(params.scale, f->model->scale);
    if (!first) first = &*f->model;
  }
  const Vec3 translate = first ? first->translate : Vec3::Zero();
  std::vector<std::optional<nlohmann::json>> features_made(entries.size());
  tbb::parallel_for(std::size_t(0), entries.size(), [&](std::size_t i) {
    PreparedFeature& f = *prepared[i];
    if (!f.model || !f.warning.empty()) return;
    const SequenceEntry& entry = entries[i];
    CityBuilding& b = f.model->buildings.front();
    CityJsonParams p = params;
    p.id = entry.id;
    p.attributes = std::move(f.attributes);
    p.surface_attributes = entry.surface_attributes;
    try {
      if (!f.solids.empty()) {  // the LoDs' solids (prepare_feature leaves none only without LoDs)
        features_made[i] = cityjson_feature(f.solids, p, translate);
        // The extent: all the solids' (the child's file has its own only).
        const nlohmann::json& e = (*features_made[i])["CityObjects"].begin().value()["geographicalExtent"];
        b.extent = e.get<std::vector<double>>();
      } else {
        features_made[i] = cityjson_feature(b.mesh, p, translate);
      }
    } catch (const Error& e) {
      features_made[i].reset();
      f.warning = "sequence: " + entry.input + " left out: " + e.one_line();
    }
  });
  std::vector<nlohmann::json> features;
  std::vector<double> extent{INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < entries.size(); ++i) {
    const PreparedFeature& f = *prepared[i];
    if (!f.warning.empty()) log::warn(f.warning);
    if (!features_made[i]) continue;
    features.push_back(std::move(*features_made[i]));
    const CityBuilding& b = f.model->buildings.front();
    for (int k = 0; k < 6 && b.extent.size() == 6; ++k)
      extent[k] = k < 3 ? std::min(extent[k], b.extent[k]) : std::max(extent[k], b.extent[k]);
  }
  if (features.empty()) extent.clear();
  write_cityjsonseq(path, cityjson_seq_header(params, translate, extent), features);
  return features.size();
}

struct FeatureMaker::State {
  const std::vector<SequenceEntry>& entries;
  std::vector<std::optional<PreparedFeature>> made;
  std::deque<std::size_t> queue;
  std::mutex mu;
  std::condition_variable wake, idle;
  bool closing = false, busy = false;
  std::exception_ptr thrown;
  std::thread thread;
  explicit State(const std::vector<SequenceEntry>& e) : entries(e), made(e.size()) {}
  void loop() {
    std::unique_lock<std::mutex> lock(mu);
    for (;;) {
      wake.wait(lock, [&] { return closing || !queue.empty(); });
      if (queue.empty()) return;  // closing
      const std::size_t i = queue.front();
      queue.pop_front();
      busy = true;
      lock.unlock();
      std::optional<PreparedFeature> f;
      std::exception_ptr e;
      try {
        f = prepare_feature(entries[i]);
      } catch (...) {
        e = std::current_exception();
      }
      lock.lock();
      busy = false;
      made[i] = std::move(f);
      if (e && !thrown) thrown = e;
      idle.notify_all();
    }
  }
};

FeatureMaker::FeatureMaker(const std::vector<SequenceEntry>& entries) : state_(std::make_unique<State>(entries)) {
  state_->thread = std::thread([s = state_.get()] { s->loop(); });
}

FeatureMaker::~FeatureMaker() {
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    state_->closing = true;
    state_->queue.clear();
  }
  state_->wake.notify_all();
  state_->thread.join();
}

void FeatureMaker::add(std::size_t i) {
  {
    std::lock_guard<std::mutex> lock(state_->mu);
    if (i >= state_->entries.size()) return;
    state_->queue.push_back(i);
  }
  state_->wake.notify_one();
}

std::vector<std::optional<PreparedFeature>> FeatureMaker::take() {
  std::unique_lock<std::mutex> lock(state_->mu);
  state_->idle.wait(lock, [&] { return state_->queue.empty() && !state_->busy; });
  if (state_->thrown) std::rethrow_exception(state_->thrown);
  return std::move(state_->made);
}

std::string validity_problem(const PolygonMesh& mesh) {
  const Validity v = check_validity(mesh);
  return v.valid() ? std::string() : v.summary();
}

// ------------------------------------------------------------------------------------------ JSON forms

nlohmann::json to_json(const RunOptions& o) {
  return {{"jobs", o.jobs}, {"resume", o.resume}, {"cityjson_scale", o.cityjson_scale}, {"crs", o.crs},
          {"reconstruct_args", o.reconstruct_args}, {"hsr_cli", o.hsr_cli}};
}

void read_run_options(const nlohmann::json& j, RunOptions& o) {
  o.jobs = j.value("jobs", o.jobs);
  o.resume = j.value("resume", o.resume);
  o.cityjson_scale = j.value("cityjson_scale", o.cityjson_scale);
  o.crs = j.value("crs", o.crs);
  o.reconstruct_args = j.value("reconstruct_args", o.reconstruct_args);
  o.hsr_cli = j.value("hsr_cli", o.hsr_cli);
}

nlohmann::json to_json(const Item& it) {
  return {{"input", it.input}, {"name", it.name}, {"output", it.output}, {"report", it.report}, {"log", it.log}, {"argv", it.argv}};
}

Item item_from_json(const nlohmann::json& j) {
  Item it;
  it.input = j.at("input").get<std::string>();
  it.name = j.at("name").get<std::string>();
  it.output = j.at("output").get<std::string>();
  it.report = j.at("report").get<std::string>();
  it.log = j.at("log").get<std::string>();
  it.argv = j.at("argv").get<std::vector<std::string>>();
  if (it.argv.empty()) bad("item without a command line");
  return it;
}

nlohmann::json to_json(const Row& r) {
  return {{"input", r.input}, {"status", r.status}, {"message", r.message}, {"seconds", r.seconds},
          {"facets", r.facets}, {"validity", r.validity}, {"p2m", r.p2m}};
}

Row row_from_json(const nlohmann::json& j) {
  Row r;
  r.input = j.at("input").get<std::string>();
  r.status = j.value("status", r.status);
  r.message = j.value("message", r.message);
  r.seconds = j.value("seconds", r.seconds);
  r.facets = j.value("facets", r.facets);
  r.validity = j.value("validity", r.validity);
  r.p2m = j.value("p2m", r.p2m);
  return r;
}

}  // namespace hsr::driver
