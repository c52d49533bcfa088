// `hsr batch INPUT... -o DIR`: many independent reconstructions (README "City scale"; DESIGN.md §4).
//
// Each input runs as a child process (driver.h): `hsr reconstruct INPUT -o DIR/NAME.FMT --report
// DIR/NAME.report.json ...`, its log in DIR/NAME.log. At the end DIR/summary.csv has one row per input in
// input order (whatever the number of jobs), and with --format city.json DIR/buildings.city.jsonl holds every
// building that succeeded as a CityJSONSeq. A failed input is recorded and skipped; an option that
// `reconstruct` rejects (a usage error, which every input would hit) stops the batch.
//
// The same steps serve the Dask driver (python/hsr/batch.py): plan_batch(), driver::done_row() for --resume,
// driver::run_item() per input in a worker, finish_batch() for the summary and the sequence, so both drivers
// give the same files.
#pragma once

#include "driver/driver.h"

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace hsr::batch {

/// driver::RunOptions (jobs, resume, cityjson_scale, crs, reconstruct_args, hsr_cli) and the batch's own.
struct BatchOptions : driver::RunOptions {
  std::vector<std::string> inputs;  ///< point files, in the order of the summary
  std::string out_dir;              ///< created if missing
  std::string format = "obj";       ///< output format: obj | ply | off | city.json
};

/// Names (file stem; prefixed by its folders when stems collide), paths and command lines; creates out_dir.
/// Throws Error(BadInput, "batch") for no input, an input given twice, an unknown format or an empty out_dir.
std::vector<driver::Item> plan_batch(const BatchOptions& options);
/// Writes DIR/summary.csv and, for city.json, DIR/buildings.city.jsonl. Returns the number of failed rows.
std::size_t finish_batch(const BatchOptions& options, const std::vector<driver::Item>& items, const std::vector<driver::Row>& rows);

/// The whole batch with options.jobs children at once. Exit code: 0 all ok, 1 some input failed.
int run_batch(const BatchOptions& options);

/// Registers the `batch` subcommand, filling `options` when parsed.
CLI::App* add_batch_command(CLI::App& app, BatchOptions& options);

// JSON forms, for the Python driver.
nlohmann::json to_json(const BatchOptions& o);
BatchOptions options_from_json(const nlohmann::json& j);

}  // namespace hsr::batch
