// `hsr batch INPUT... -o DIR`: many independent reconstructions (README "City scale"; DESIGN.md §4).
//
// Each input runs as a child process of the same binary, `hsr reconstruct INPUT -o DIR/NAME.FMT --report
// DIR/NAME.report.json ...`, its stdout and stderr (warnings included) in DIR/NAME.log: a crash, a
// watchdog's _Exit or an out-of-memory kill ends that child only, and the process-global state (log level, the run budget of
// core/budget.h) stays per input. At the end DIR/summary.csv has one row per input in input order
// (whatever the number of jobs), and with --format city.json DIR/buildings.city.jsonl holds every
// building that succeeded as a CityJSONSeq. A failed input is recorded and skipped; an option that
// `reconstruct` rejects (a usage error, which every input would hit) stops the batch.
//
// The same steps serve the Dask driver (python/hsr/batch.py): plan_batch(), done_row() for --resume,
// run_item() per input in a worker, finish_batch() for the summary and the sequence, so both drivers give
// the same files.
#pragma once

#include "core/types.h"

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace hsr::batch {

struct BatchOptions {
  std::vector<std::string> inputs;  ///< point files, in the order of the summary
  std::string out_dir;              ///< created if missing
  std::string format = "obj";       ///< output format: obj | ply | off | city.json
  unsigned jobs = 0;                ///< children at once; 0: one per hardware thread
  bool resume = false;              ///< skip inputs whose output and report (for this input) exist
  /// Options for every `reconstruct` (after the ones batch knows: --partition, --lambda, --max-seconds,
  /// --max-memory, --cityjson-scale, --crs), e.g. what follows `--` on the command line.
  std::vector<std::string> reconstruct_args;
  double cityjson_scale = 0.001;    ///< also the sequence's transform scale
  std::string crs;                  ///< "EPSG:NNNN" or ""; also the sequence's reference system
  std::string hsr_cli;              ///< binary run for each input; "": this process's own (/proc/self/exe)
};

/// One input's plan: its unique NAME (file stem; prefixed by its folders when stems collide) and files.
struct BatchItem {
  std::string input, name, output, report, log;
  std::vector<std::string> argv;  ///< the child's whole command line
};

/// One row of summary.csv.
struct BatchRow {
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

/// Names, paths and command lines; creates out_dir. Throws Error(BadInput, "batch") for no input, an
/// input given twice, an unknown format or an empty out_dir.
std::vector<BatchItem> plan_batch(const BatchOptions& options);
/// --resume: the row of an input already done (output and report exist, the report names this input and
/// output), else nullopt.
std::optional<BatchRow> done_row(const BatchItem& item);
/// Runs the child and waits for it; never throws for the input's own failure (it is in the row).
BatchRow run_item(const BatchItem& item);
/// Writes DIR/summary.csv and, for city.json, DIR/buildings.city.jsonl. Returns the number of failed rows.
std::size_t finish_batch(const BatchOptions& options, const std::vector<BatchItem>& items, const std::vector<BatchRow>& rows);
/// "batch: 12/112 done (11 ok, 1 failed), 5.2 inputs/min, ETA 19 min" (rate over the `ran` inputs run
/// in `elapsed` seconds; resumed ones count as done but not in the rate).
std::string progress_line(std::size_t done, std::size_t total, std::size_t failed, std::size_t ran, double elapsed);

// Pieces `hsr city` (city_run.h) reuses.

/// `s` with every character other than a letter, digit, '.', '-' or '_' turned into '_'.
std::string safe_file_name(const std::string& s);
/// Unique names for the inputs: the file stem, prefixed by parent folders only where stems collide.
std::vector<std::string> unique_names(const std::vector<std::string>& inputs);
/// Runs items[todo[k]] with `jobs` children at once (0: one per hardware thread), filling rows[todo[k]], a
/// progress line after each ("<label>: 3/12 done ..."); stops starting new ones after a usage error and
/// returns its message ("" when none).
std::string run_items(const std::vector<BatchItem>& items, const std::vector<std::size_t>& todo, unsigned jobs,
                      std::vector<BatchRow>& rows, std::size_t already_done = 0, const std::string& label = "batch");
/// summary.csv's columns (`input, status, seconds, facets, validity, p2m_mean, message`), one row each,
/// then the `extra_header` columns with `extra[i]`'s values (extra empty, or one list per row), at `path`.
void write_summary_csv(const std::string& path, const std::vector<BatchRow>& rows,
                       const std::vector<std::string>& extra_header = {},
                       const std::vector<std::vector<std::string>>& extra = {});
/// One building of a CityJSONSeq: the .city.json a child wrote (one building), the id to give it, and
/// attributes: `before` come first, then the file's own (the run's figures), then `after`; keys in
/// `drop` are left out (e.g. timings, for byte-identical sequences).
struct SequenceEntry {
  std::string input;     ///< for messages
  std::string cityjson;  ///< the child's output
  std::string id;
  nlohmann::json before = nlohmann::json::object(), after = nlohmann::json::object();
  std::vector<std::string> drop;
};
/// Writes `path` as a CityJSONSeq of the entries, in order: a header with the first building's translate and
/// the finest scale any needed (`scale` or finer), `crs` ("EPSG:N" or ""), then one CityJSONFeature each.
/// An entry whose file cannot be read, or whose solid fails at the shared scale (CityJsonParams::validate,
/// eval's check), is left out with a warning. Returns the number of features written.
std::size_t write_cityjson_sequence(const std::string& path, double scale, const std::string& crs,
                                    const std::vector<SequenceEntry>& entries);

/// "" when eval's check_validity finds `mesh` valid, else its summary: the CityJsonParams::validate of the
/// CLI's CityJSON outputs and of the sequence.
std::string validity_problem(const PolygonMesh& mesh);

/// The whole batch with options.jobs children at once. Exit code: 0 all ok, 1 some input failed.
int run_batch(const BatchOptions& options);

/// Registers the `batch` subcommand, filling `options` when parsed.
CLI::App* add_batch_command(CLI::App& app, BatchOptions& options);
/// Arguments after a `--` that follows the `batch` subcommand are reconstruct's: moved into
/// options.reconstruct_args. Returns the argc to parse (argv up to the `--`).
int take_forwarded_args(int argc, char** argv, BatchOptions& options);

// JSON forms, for the Python driver.
nlohmann::json to_json(const BatchOptions& o);
BatchOptions options_from_json(const nlohmann::json& j);
nlohmann::json to_json(const BatchItem& item);
BatchItem item_from_json(const nlohmann::json& j);
nlohmann::json to_json(const BatchRow& row);
BatchRow row_from_json(const nlohmann::json& j);

}  // namespace hsr::batch
