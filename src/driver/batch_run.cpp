// `hsr batch` (see batch_run.h): plan, one child process per input (driver.h), summary and CityJSONSeq.
#include "driver/batch_run.h"

#include "core/error.h"
#include "core/log.h"
#include "io/cityjson.h"

#include <CLI/CLI.hpp>

#include <algorithm>
#include <filesystem>
#include <set>

namespace hsr::batch {

namespace fs = std::filesystem;

namespace {

[[noreturn]] void bad(const std::string& what) { throw Error(Status::BadInput, "batch", what); }

/// Every successful building's .city.json as one CityJSONFeature of DIR/buildings.city.jsonl (its NAME as id).
void write_sequence(const BatchOptions& options, const std::vector<driver::Item>& items, const std::vector<driver::Row>& rows) {
  std::vector<driver::SequenceEntry> entries;
  for (std::size_t i = 0; i < items.size(); ++i)
    if (rows[i].ok()) entries.push_back({items[i].input, items[i].output, items[i].name, {}, {}, {}});
  driver::write_cityjson_sequence((fs::path(options.out_dir) / "buildings.city.jsonl").string(), options.cityjson_scale,
                                  options.crs, entries);
}

}  // namespace

std::vector<driver::Item> plan_batch(const BatchOptions& options) {
  if (options.inputs.empty()) bad("no input given");
  if (options.out_dir.empty()) bad("no output folder given (-o DIR)");
  static const std::set<std::string> formats{"obj", "ply", "off", "city.json"};
  if (!formats.count(options.format)) bad("unknown format '" + options.format + "' (obj, ply, off, city.json)");
  driver::require_distinct(options.inputs, "batch", "input");
  if (!options.crs.empty()) crs_url(options.crs);  // fail here, not once per input
  fs::create_directories(options.out_dir);
  const std::vector<std::string> names = driver::unique_names(options.inputs);
  const std::string cli = driver::cli_path(options, "batch");
  std::vector<driver::Item> items;
  for (std::size_t i = 0; i < options.inputs.size(); ++i) {
    driver::Item it;
    it.input = options.inputs[i];
    it.name = names[i];
    const fs::path base = fs::path(options.out_dir) / names[i];
    it.output = base.string() + "." + options.format;
    it.report = base.string() + ".report.json";
    it.log = base.string() + ".log";
    it.argv = {cli, "reconstruct", it.input, "-o", it.output, "--report", it.report};
    if (options.format == "city.json") {
      it.argv.insert(it.argv.end(), {"--cityjson-scale", driver::format_number(options.cityjson_scale)});
      if (!options.crs.empty()) it.argv.insert(it.argv.end(), {"--crs", options.crs});
    }
    it.argv.insert(it.argv.end(), options.reconstruct_args.begin(), options.reconstruct_args.end());
    items.push_back(std::move(it));
  }
  return items;
}

std::size_t finish_batch(const BatchOptions& options, const std::vector<driver::Item>& items, const std::vector<driver::Row>& rows) {
  if (rows.size() != items.size()) bad("finish: " + std::to_string(rows.size()) + " rows for " + std::to_string(items.size()) + " inputs");
  driver::write_summary_csv((fs::path(options.out_dir) / "summary.csv").string(), rows);
  if (options.format == "city.json") write_sequence(options, items, rows);
  return static_cast<std::size_t>(std::count_if(rows.begin(), rows.end(), [](const driver::Row& r) { return !r.ok(); }));
}

int run_batch(const BatchOptions& options) {
  const std::vector<driver::Item> items = plan_batch(options);
  std::vector<driver::Row> rows(items.size());
  std::vector<std::size_t> todo;
  for (std::size_t i = 0; i < items.size(); ++i) {
    std::optional<driver::Row> done = options.resume ? driver::done_row(items[i]) : std::nullopt;
    if (done) rows[i] = *done;
    else todo.push_back(i);
  }
  const std::size_t resumed = items.size() - todo.size();
  if (resumed) log::info("batch: " + std::to_string(resumed) + " of " + std::to_string(items.size()) + " inputs already done (--resume)");
  driver::run_items(items, todo, options.jobs, options.fresh_processes, rows, resumed, "batch");
  const std::size_t failures = finish_batch(options, items, rows);
  log::info("batch: " + std::to_string(items.size() - failures) + " of " + std::to_string(items.size()) +
            " inputs ok; summary in " + (fs::path(options.out_dir) / "summary.csv").string());
  return failures ? 1 : 0;
}

CLI::App* add_batch_command(CLI::App& app, BatchOptions& o) {
  auto* b = app.add_subcommand("batch", "Reconstruct many inputs, one child process each, with a summary");
  b->add_option("INPUTS", o.inputs, "Input point files (one building or object each)")->required();
  b->add_option("-o,--output", o.out_dir, "Output folder: NAME.FMT, NAME.report.json, NAME.log per input; summary.csv")
      ->required();
  b->add_option("--format", o.format, "Output format: obj | ply | off | city.json (adds buildings.city.jsonl)")
      ->check(CLI::IsMember({"obj", "ply", "off", "city.json"}))
      ->capture_default_str();
  b->add_option("-j,--jobs", o.jobs, "Inputs reconstructed at once; 0: one per hardware thread")->capture_default_str();
  b->add_flag("--resume", o.resume, "Skip inputs whose output and report already exist");
  b->add_flag("--fresh-processes", o.fresh_processes,
                 "Each input in a process of its own, not one worker per job running its inputs in turn "
                 "(the same files; slower)");
  b->add_option("--cityjson-scale", o.cityjson_scale, "city.json: size of one integer coordinate step (1 mm)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  b->add_option("--crs", o.crs, "city.json: reference system EPSG:NNNN (metadata.referenceSystem)");
  b->add_option("--hsr", o.hsr_cli, "Program run as `PROGRAM reconstruct ...` for each input (default: this hsr)");
  driver::add_forwarded_options(*b, "batch", o.reconstruct_args);
  b->footer("Any other reconstruct option goes after --, e.g.\n  hsr batch scans/*.ply -o out --format city.json -- --scene building");
  return b;
}

nlohmann::json to_json(const BatchOptions& o) {
  nlohmann::json j = driver::to_json(static_cast<const driver::RunOptions&>(o));
  j["inputs"] = o.inputs;
  j["out_dir"] = o.out_dir;
  j["format"] = o.format;
  return j;
}

BatchOptions options_from_json(const nlohmann::json& j) {
  BatchOptions o;
  driver::read_run_options(j, o);
  o.inputs = j.value("inputs", o.inputs);
  o.out_dir = j.value("out_dir", o.out_dir);
  o.format = j.value("format", o.format);
  return o;
}

}  // namespace hsr::batch
