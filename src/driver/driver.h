// The machinery of the drivers of many runs, `hsr batch` (batch_run.h) and `hsr city` (city_run.h), held once
// (README "City scale"; DESIGN.md §4).
//
// A driver plans Items, one child run each: `hsr reconstruct INPUT -o OUTPUT --report REPORT ...`, a child
// process of the same binary (or of --hsr), its stdout and stderr (warnings included) in LOG. A crash, a
// watchdog's _Exit or an out-of-memory kill ends that child only, and the process-global state (log level,
// the run budget of core/budget.h) stays per item. Each item gives a Row of the summary CSV; --resume takes
// the row of an item already done from its report. Successful CityJSON outputs are gathered into one
// CityJSONSeq (write_cityjson_sequence). Items, rows and options have JSON forms for the Python drivers
// (python/hsr/batch.py, python/hsr/city.py), which run the same steps in Dask tasks and so write the same
// files.
//
// The reconstruct options a driver passes on to its children (--lambda, --max-seconds, ...) are listed once
// here (forwarded_options) for both CLIs and both Python drivers.
#pragma once

#include "core/types.h"
#include "io/cityjson.h"

#include <nlohmann/json.hpp>

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace hsr::driver {

/// The options every driver has.
struct RunOptions {
  unsigned jobs = 0;               ///< children at once; 0: one per hardware thread
  bool resume = false;             ///< skip items whose output and report (for this item) exist
  double cityjson_scale = 0.001;   ///< the children's and the sequence's transform scale, file units
  std::string crs;                 ///< "EPSG:N" or ""; also the sequence's reference system
  /// Options for every `reconstruct`, after the ones the driver sets itself: what follows `--` on the
  /// command line, then the forwarded options given (forwarded_options).
  std::vector<std::string> reconstruct_args;
  std::string hsr_cli;             ///< binary run for each item; "": this process's own (/proc/self/exe)
  /// Each item in a process of its own (forked from the launcher), not in one worker per job that runs its
  /// job's items in turn (driver/launcher.h, DECISIONS #115). Both keep a crash or a budget to one item and
  /// give the same files; the workers save a process start per item.
  bool fresh_processes = false;
};

/// One child run: its input, unique NAME and files, and its whole command line.
struct Item {
  std::string input, name, output, report, log;
  std::vector<std::string> argv;
};

/// One row of a summary CSV.
struct Row {
  std::string input;
  std::string status = "ok";  ///< "ok", a status name (core/error.h: bad-format, invalid-output, ...),
                              ///< "crashed (signal N)" or "usage-error"
  std::string message;        ///< the child's one-line error, or ""
  double seconds = 0;         ///< the pipeline's total (report), or the failed attempt's wall time
  long facets = -1;           ///< output faces, -1: none
  std::string validity;       ///< "valid", the failed checks, or ""
  double p2m = -1;            ///< mean point-to-mesh distance (fraction of the bbox diagonal), -1: none
  bool ok() const { return status == "ok"; }
};

// ------------------------------------------------------------------------------------------ forwarded options

/// A reconstruct option a driver's CLI takes and passes on to every child (`--lambda 0.5` given to `hsr
/// batch` is `--lambda 0.5` on each child's command line).
struct ForwardedOption {
  std::string name;  ///< reconstruct's option, e.g. "--lambda"
  std::string help;
  bool batch = true;  ///< `hsr batch` (python3 -m hsr.batch) takes it
  bool city = true;   ///< `hsr city` (python3 -m hsr.city) takes it
};
/// Every forwarded option, in the order their values go onto the command line (after the `--` ones).
const std::vector<ForwardedOption>& forwarded_options();
/// The forwarded options of one driver ("batch" or "city"); throws for another name.
std::vector<ForwardedOption> forwarded_options(const std::string& driver);
/// Registers `driver`'s forwarded options on its subcommand; each one given is appended to `reconstruct_args`.
void add_forwarded_options(CLI::App& sub, const std::string& driver, std::vector<std::string>& reconstruct_args);
/// Arguments after a `--` that follows the `subcommand` are reconstruct's: moved into `reconstruct_args`.
/// Returns the argc to parse (argv up to the `--`).
int take_forwarded_args(int argc, char** argv, const std::string& subcommand, std::vector<std::string>& reconstruct_args);

// ------------------------------------------------------------------------------------------ names and files

/// `s` with every character other than a letter, digit, '.', '-' or '_' turned into '_'.
std::string safe_file_name(const std::string& s);
/// Unique names for the inputs: the file stem, prefixed by parent folders only where stems collide.
std::vector<std::string> unique_names(const std::vector<std::string>& inputs);
/// Throws Error(BadInput, stage, "<what> given twice: PATH") when two paths name the same file.
void require_distinct(const std::vector<std::string>& paths, const std::string& stage, const std::string& what);
/// The program run for each item: options.hsr_cli, else this process's own.
std::string cli_path(const RunOptions& options, const std::string& stage);
/// `v` with all its digits ("%.17g"), for command lines.
std::string format_number(double v);
/// Writes `j` at `path` (indent 1, atomically).
void write_json(const std::string& path, const nlohmann::json& j, const std::string& stage);
/// The JSON at `path`; a discarded value when it cannot be read or parsed.
nlohmann::json read_json(const std::string& path);

// ------------------------------------------------------------------------------------------ child runs

/// --resume: the row of an item already done (output and report exist, the report names this input and
/// output), else nullopt.
std::optional<Row> done_row(const Item& item);
/// Runs the child and waits for it; never throws for the item's own failure (it is in the row). `slot` >= 0:
/// in that slot's worker when the child is this program run through the launcher (launch_and_wait).
Row run_item(const Item& item, int slot = -1);
/// Runs items[todo[k]] with `jobs` children at once (0: one per hardware thread; job j in worker slot j unless
/// `fresh_processes`: RunOptions::fresh_processes), filling rows[todo[k]], a
/// progress line after each ("<progress>: 3/12 done ..."; `progress` empty: the label). After a usage error it
/// starts no new one and, once the running ones are back, throws Error(BadInput, label, "reconstruct rejected
/// the options ...").
/// `done`, when given, is called with each index todo[k] once rows[todo[k]] is filled (on the thread that ran
/// it, outside any lock).
/// `turns` non-empty (and the children this program): two children per job, job j's turn the lock file
/// "<turns>.<j>" (Turn), which each child holds from its start to the end of its first run and step 0, so that a
/// child's later runs and writing go beside the next child's first runs (DECISIONS #235); the same files either way.
void run_items(const std::vector<Item>& items, const std::vector<std::size_t>& todo, unsigned jobs, bool fresh_processes,
               std::vector<Row>& rows, std::size_t already_done, const std::string& label, const std::string& progress = "",
               const std::function<void(std::size_t)>& done = {}, const std::string& turns = "");

/// A child's turn (DECISIONS #235): an exclusive lock (flock) on a file, held from the child's start until its
/// building's first run and step 0 are done (PipelineParams::turn_over; steps 1 to 6 before #249). Why: a
/// building's run keeps about 1.5 of the 2 cores busy with one job; steps 5 to 7's runs, the self-check and the writing after it need no more than the core
/// the next building's first runs leave idle, so `hsr city` runs a job's buildings two at a time, one in its turn
/// and one finishing. The lock is the process's: a crash, a watchdog's end or an error gives the turn up with it.
class Turn {
 public:
  /// Waits for the lock on `path` (created if missing); empty: no turn. A file that cannot be locked: a warning,
  /// no turn (the run goes on beside the others: the same files, only the schedule differs).
  explicit Turn(const std::string& path);
  Turn(const Turn&) = delete;
  Turn& operator=(const Turn&) = delete;
  ~Turn() { give_up(); }
  /// Gives the turn up (the next child may begin); again: nothing.
  void give_up();

 private:
  int fd_ = -1;
};
/// "<label>: 12/112 done (11 ok, 1 failed), 5.2 inputs/min, ETA 19 min" (rate over the `ran` items run in
/// `elapsed` seconds; resumed ones count as done but not in the rate).
std::string progress_line(const std::string& label, std::size_t done, std::size_t total, std::size_t failed,
                          std::size_t ran, double elapsed);

// ------------------------------------------------------------------------------------------ outputs

/// The summary CSV's columns (`input, status, seconds, facets, validity, p2m_mean, message`), one row each,
/// then the `extra_header` columns with `extra[i]`'s values (extra empty, or one list per row), at `path`.
void write_summary_csv(const std::string& path, const std::vector<Row>& rows,
                       const std::vector<std::string>& extra_header = {},
                       const std::vector<std::vector<std::string>>& extra = {});
/// One building of a CityJSONSeq: the .city.json a child wrote (one building), the id to give it, and
/// attributes: `before` come first, then the file's own (the run's figures), then `after`; keys in
/// `drop` are left out (e.g. timings, for byte-identical sequences).
/// What a feature carries besides the child's solid (hsr city: LoD 1.2 and 1.3, src/city/lods.h).
struct FeatureLods {
  bool keep_read = true;                   ///< write the child's solid (LoD 2.2) first
  std::vector<CityJsonGeometry> solids;   ///< then these
  nlohmann::json attributes = nlohmann::json::object();  ///< added after `after`
};
struct SequenceEntry {
  std::string input;     ///< for messages
  std::string cityjson;  ///< the child's output
  std::string id;
  nlohmann::json before = nlohmann::json::object(), after = nlohmann::json::object();
  std::vector<std::string> drop;
  /// Given the building read back, its attributes so far and its file's scale: the feature's other solids
  /// and attributes. Empty: the child's solid only.
  std::function<FeatureLods(const CityBuilding&, const nlohmann::json& attributes, double scale)> lods;
  /// CityJsonParams::surface_attributes of this feature.
  std::function<nlohmann::json(const std::string&, const PolygonMesh&, std::size_t)> surface_attributes;
};
/// Writes `path` as a CityJSONSeq of the entries, in order: a header with the first building's translate and
/// the finest scale any needed (`scale` or finer), `crs` ("EPSG:N" or ""), then one CityJSONFeature each.
/// An entry whose file cannot be read, or whose solid fails at the shared scale (CityJsonParams::validate,
/// eval's check), is left out with a warning. Returns the number of features written.
std::size_t write_cityjson_sequence(const std::string& path, double scale, const std::string& crs,
                                    const std::vector<SequenceEntry>& entries);
/// One entry's share of write_cityjson_sequence that depends on no other entry: its file read back, its
/// attributes (`before`, the file's, `after`, less `drop`, then the LoDs') and its solids. Invariants: `model`
/// is set unless `read_warning` is; unless either warning is set, the attributes hold and `solids` is empty
/// exactly when the entry asked for no LoDs (SequenceEntry::lods; the feature is then the file's own solid).
struct PreparedFeature {
  std::optional<CityModel> model;        ///< the child's file (one building)
  std::string read_warning;              ///< "sequence: INPUT left out: ..." (the file could not be read)
  nlohmann::json attributes = nlohmann::json::object();
  std::vector<CityJsonGeometry> solids;  ///< the LoDs' solids to write, in order (none: the file's solid)
  std::string warning;                   ///< "sequence: INPUT left out: ..." (the LoDs failed)
};
/// The entry's PreparedFeature (never throws for the entry's own files: the warnings say it).
PreparedFeature prepare_feature(const SequenceEntry& entry);
/// write_cityjson_sequence with some entries prepared already (`prepared[i]` of entries[i], or none: prepared
/// here): the same bytes as without.
std::size_t write_cityjson_sequence(const std::string& path, double scale, const std::string& crs,
                                    const std::vector<SequenceEntry>& entries,
                                    std::vector<std::optional<PreparedFeature>> prepared);

/// Prepares entries (prepare_feature) on one thread of its own, each as soon as it is given (add), in the order
/// given; take() waits for those given and returns them by index. Why: hsr city's LoDs (three solids checked
/// and their RMS distances per building) were made after the tile's last building, 8 % of a tile's CPU as a
/// tail with every worker idle (issue 43); made while the workers run, they take a core the children leave free.
/// Each is made from its entry alone, so the files do not depend on the order.
class FeatureMaker {
 public:
  /// `entries` outlives the maker; add(i) prepares entries[i].
  explicit FeatureMaker(const std::vector<SequenceEntry>& entries);
  ~FeatureMaker();
  FeatureMaker(const FeatureMaker&) = delete;
  FeatureMaker& operator=(const FeatureMaker&) = delete;
  void add(std::size_t i);
  /// Waits for every entry given; rethrows what the thread threw beyond an entry's warnings (out of memory).
  std::vector<std::optional<PreparedFeature>> take();

 private:
  struct State;
  std::unique_ptr<State> state_;
};
/// "" when eval's check_validity finds `mesh` valid, else its summary: the CityJsonParams::validate of the
/// CLI's CityJSON outputs and of the sequence.
std::string validity_problem(const PolygonMesh& mesh);

// ------------------------------------------------------------------------------------------ JSON forms

nlohmann::json to_json(const RunOptions& o);
/// Fills the RunOptions fields `j` has.
void read_run_options(const nlohmann::json& j, RunOptions& o);
nlohmann::json to_json(const Item& item);
Item item_from_json(const nlohmann::json& j);
nlohmann::json to_json(const Row& row);
Row row_from_json(const nlohmann::json& j);

}  // namespace hsr::driver
