// The steps of `hsr batch` (src/driver/batch_run.h) and `hsr city` (src/driver/city_run.h) for the Dask
// drivers python/hsr/batch.py and python/hsr/city.py: plans, rows and options cross as plain dicts (through
// JSON), so a Dask task ships a dict and gets a dict back.
#include "core/error.h"
#include "driver/batch_run.h"
#include "driver/city_run.h"
#include "driver/driver.h"

#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

namespace py = pybind11;
using namespace hsr;

namespace {

nlohmann::json from_py(const py::handle& obj) {
  return nlohmann::json::parse(py::module_::import("json").attr("dumps")(obj).cast<std::string>());
}

py::object to_py(const nlohmann::json& j) { return py::module_::import("json").attr("loads")(j.dump()); }

std::vector<driver::Row> rows_from_py(const py::list& rows) {
  std::vector<driver::Row> out;
  for (const auto& r : rows) out.push_back(driver::row_from_json(from_py(r)));
  return out;
}

}  // namespace

void bind_driver(py::module_& m) {
  m.def("_cli_path", [] { return std::string(HSR_CLI_PATH); }, "The hsr program of this build (run per input).");
  m.def("_exit_code", [](const std::string& status) {
    for (int s = 0; s <= static_cast<int>(Status::Internal); ++s)
      if (status == status_name(static_cast<Status>(s))) return exit_code(static_cast<Status>(s));
    return exit_code(Status::Internal);
  }, py::arg("status"), "The CLI's exit code for a status name ('bad-input' ...).");
  m.def("_forwarded_options", [](const std::string& driver) {
    py::list out;
    for (const auto& o : driver::forwarded_options(driver)) out.append(py::make_tuple(o.name, o.help));
    return out;
  }, py::arg("driver"), "(name, help) of each reconstruct option the driver ('batch' or 'city') passes on, in "
                        "command-line order (src/driver/driver.h forwarded_options).");
  m.def("_done_row", [](const py::dict& item) -> py::object {
    const auto row = driver::done_row(driver::item_from_json(from_py(item)));
    return row ? to_py(driver::to_json(*row)) : py::none();
  }, py::arg("item"), "--resume: the summary row of an item already done, or None.");
  m.def("_run_item", [](const py::dict& item) {
    const driver::Item it = driver::item_from_json(from_py(item));
    driver::Row row;
    {
      py::gil_scoped_release release;  // the child runs; other worker threads go on
      row = driver::run_item(it);
    }
    return to_py(driver::to_json(row));
  }, py::arg("item"), "Runs one item's child process and returns its summary row.");
  m.def("_progress_line", &driver::progress_line, py::arg("label"), py::arg("done"), py::arg("total"),
        py::arg("failed"), py::arg("ran"), py::arg("elapsed"), "The progress line of hsr batch and hsr city.");
  m.def("_batch_plan", [](const py::dict& options) {
    py::list items;
    for (const auto& it : batch::plan_batch(batch::options_from_json(from_py(options)))) items.append(to_py(driver::to_json(it)));
    return items;
  }, py::arg("options"), "Names, files and command lines of every input (batch_run.h plan_batch); creates the folder.");
  m.def("_batch_finish", [](const py::dict& options, const py::list& items, const py::list& rows) {
    std::vector<driver::Item> its;
    for (const auto& it : items) its.push_back(driver::item_from_json(from_py(it)));
    return batch::finish_batch(batch::options_from_json(from_py(options)), its, rows_from_py(rows));
  }, py::arg("options"), py::arg("items"), py::arg("rows"),
  "Writes summary.csv (and buildings.city.jsonl for city.json); returns the number of failed inputs.");
  m.def("_city_tiles", [](const py::dict& options) {
    py::list out;
    for (const auto& f : city::tile_files(city::options_from_json(from_py(options)))) out.append(to_py(city::to_json(f)));
    return out;
  }, py::arg("options"), "Each tile's files: sequence, summary, work folder (city_run.h tile_files).");
  m.def("_city_plan", [](const py::dict& options, const py::dict& files) {
    const city::CityOptions o = city::options_from_json(from_py(options));
    const city::TileFiles f = city::files_from_json(from_py(files));
    city::TilePlan plan;
    {
      py::gil_scoped_release release;  // reading and splitting the tile
      plan = city::plan_tile(o, f);
    }
    return to_py(city::to_json(plan));
  }, py::arg("options"), py::arg("files"), "Plans one tile (city_run.h plan_tile): its buildings and their children.");
  m.def("_city_require_footprints", [](const py::dict& options, const py::list& plans) {
    std::vector<city::TilePlan> ps;
    for (const auto& p : plans) ps.push_back(city::plan_from_json(from_py(p)));
    city::require_footprints_on_tiles(city::options_from_json(from_py(options)), ps);
  }, py::arg("options"), py::arg("plans"),
  "Raises hsr.Error (naming --crs) when footprints were given and none lies on any tile (city_run.h).");
  m.def("_city_initial_rows", [](const py::dict& options, const py::dict& plan) {
    std::vector<std::size_t> todo;
    const auto rows = city::initial_rows(city::options_from_json(from_py(options)), city::plan_from_json(from_py(plan)), todo);
    py::list rs;
    for (const auto& r : rows) rs.append(to_py(driver::to_json(r)));
    return py::make_tuple(rs, todo);
  }, py::arg("options"), py::arg("plan"), "(rows, indices to run): failed buildings' rows, and --resume's done ones.");
  m.def("_city_finish", [](const py::dict& options, const py::dict& plan, const py::list& rows) {
    return city::finish_tile(city::options_from_json(from_py(options)), city::plan_from_json(from_py(plan)), rows_from_py(rows));
  }, py::arg("options"), py::arg("plan"), py::arg("rows"),
  "Writes the tile's summary and CityJSONSeq; returns the number of buildings that failed.");
}
