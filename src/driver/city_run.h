// `hsr city TILE... -o OUT.city.jsonl`: a survey tile in, a city out (issue 27; README "City scale";
// DESIGN.md §4 "From a tile to a city").
//
// Per tile: plan_tile() reads it (with several tiles, also its neighbours' points within the tile margin:
// city_survey.h), splits its points and finds its buildings (src/city/city.h: classes or
// SMRF, footprints or groups in plan, the ground ring), and writes into the tile's work folder, per building,
// NAME.ply (its points, file coordinates) and NAME.footprint.geojson, and plan.json (the buildings and each
// child's command line). Each building then runs as a child process of the same binary, as `hsr batch` runs
// its inputs (driver.h: run_item, so a crash ends that building only): `hsr reconstruct NAME.ply -o
// NAME.city.json --report NAME.report.json --scene building --ground-z Z --trust-ground-z --footprint
// NAME.footprint.geojson --cityjson-scale S ...`. finish_tile() writes the tile's CityJSONSeq (driver.h write_cityjson_sequence: a
// feature per building that succeeded, in building order, ids from the footprints or stable within the
// tile, the footprint's fields and the ground as attributes, CRS from the tile or --crs) and its summary CSV
// (every building, the failed ones with their reason; driver.h write_summary_csv with the city's columns).
// A building that fails never stops the tile. The sequence's bytes do not depend on the number of jobs,
// on the driver (this one or python/hsr/city.py) or on the run (timings are left out of it).
//
// Outputs: with one tile, -o OUT.city.jsonl gives OUT.city.jsonl, OUT.summary.csv and the folder OUT.work/;
// otherwise -o DIR gives DIR/NAME.city.jsonl, DIR/NAME.summary.csv, DIR/NAME.work/ per tile (NAME: the tile's
// file stem, with folders prepended where stems collide). --resume reuses a tile's plan.json when it was made
// from the same tile, footprints and options, and skips the buildings whose output and report exist.
#pragma once

#include "city/city.h"
#include "city/lods.h"
#include "driver/driver.h"

#include <nlohmann/json.hpp>

#include <memory>
#include <string>
#include <vector>

namespace CLI {
class App;
}

namespace hsr::city {

class SurveyIndex;  // city_survey.h

/// driver::RunOptions (jobs: buildings at once; crs: "EPSG:N", the points' CRS and the sequence's, "": the
/// tile's own; cityjson_scale, reconstruct_args: after the city's own child options; resume; hsr_cli) and
/// the city's own.
struct CityOptions : driver::RunOptions {
  std::vector<std::string> tiles;  ///< LAS/LAZ (or any point file read_points reads), in summary order
  std::string output;              ///< OUT.city.jsonl (one tile only) or a folder
  std::string footprints;          ///< footprint file (footprints.h); "": groups in plan
  std::string footprint_layer;     ///< its layer; "": the first
  std::string id_field;            ///< the field holding the ids; "": the FIDs
  CityParams params;               ///< the tile stage's (src/city/city.h)
  /// The LoDs of each feature (`--lod`, src/city/lods.h parse_lod_list): "1.2,1.3,2.2" or a subset.
  std::string lod = "1.2,1.3,2.2";
  /// A tile larger than this is planned block by block (`--block`; DECISIONS #124): blocks of about this side,
  /// metres (a side of a tile gets round(length / block) blocks, at least 1, so a tile up to 1.5 blocks a side
  /// is planned whole). Only with footprints on a tile whose file gives its ground and building classes (a
  /// plan that keeps only the points near its buildings); the plan is the same to the byte whatever the blocks,
  /// so it is not part of what --resume compares. 1 km: a block's kept points are those of a 1 km² tile of a
  /// survey (DECISIONS #103); 0 or less: never.
  double block = 1000.0;
  /// Decode every part of every file (io.h point_parts), not only those holding a point the plan keeps
  /// (DECISIONS #133). The plan is the same to the byte either way; for tests and the bench, no flag.
  bool every_part = false;
  /// Each job's buildings one after another (`--one-at-a-time`), not two at a time in turns, the next's first
  /// runs beside the last's step 7, self-check and writing (driver.h Turn, DECISIONS #235). The same files.
  bool one_at_a_time = false;
};

/// One tile's files.
struct TileFiles {
  std::string tile, sequence, summary, work;
};

/// One building of a tile's plan.
struct PlannedBuilding {
  std::string id, name;    ///< the building's id, its files' name
  std::size_t points = 0;
  double area = 0;        ///< plan area, m²
  double ground_z = 0;     ///< file coordinates; NaN: none (ground_source says why)
  std::size_t ground_points = 0;
  std::string ground_source;
  nlohmann::json attributes = nlohmann::json::object();  ///< the footprint's fields
  std::string failure;     ///< non-empty: not run, and why
  std::string not_building;  ///< non-empty: a group that is not a building (city.h step 5), and why; not run
  bool footprint_prism = false;  ///< too few points for a run: the child makes the footprint prism (city.h step 4)
  std::string no_points;   ///< non-empty: a footprint with (almost) no points (city.h step 4), and why; not run
  driver::Item item;   ///< its child (input = NAME.ply)
};

struct TilePlan {
  TileFiles files;
  std::string crs;              ///< the sequence's "EPSG:N", or ""
  std::string classes, buildings_from, crs_note;
  std::size_t unused_building_points = 0;  ///< building points in no building (off every footprint, small groups)
  std::size_t footprints_on_tile = 0;      ///< footprints whose centre lies on the tile (0 without footprints)
  std::size_t footprints_off_tile = 0;     ///< the others
  bool crs_compared = false;               ///< the footprints' CRS and the points' were both known
  std::vector<PlannedBuilding> buildings;
};

/// The summary's status of a group that is not a building (PlannedBuilding::not_building): not a failure.
constexpr const char* kNotABuilding = "not-a-building";
/// The summary's status of a footprint with fewer than CityParams::min_prism_points points
/// (PlannedBuilding::no_points): no model, not a failure (DECISIONS #165).
constexpr const char* kNoPoints = "no-points";

/// The tiles of a run as given on the command line: each argument that is a folder becomes the LAS/LAZ files in
/// it (extensions las, laz, COPC's copc.laz; not its subfolders), sorted by name; any other argument stays as
/// given (globs are the shell's). Why: issue 40 item 1, a survey is published as a folder of tiles. Throws
/// Error(BadInput, "city") for a folder without such a file.
std::vector<std::string> expand_tile_folders(const std::vector<std::string>& args);

/// The files of every tile; throws Error(BadInput, "city") for no tile, a tile given twice, an
/// OUT.city.jsonl with several tiles, or a bad --lod.
std::vector<TileFiles> tile_files(const CityOptions& options);

/// Reads the footprints (null when none are given), their CRS checked against `points_crs`.
std::unique_ptr<FootprintSet> load_footprints(const CityOptions& options, const std::string& points_crs);

/// The footprints of a run over several tiles (issue 40 item 2; DECISIONS #103): read once, by the first tile
/// that needs them, in that tile's points' CRS (again only for a tile in another CRS), and indexed by their
/// boxes (survey.h FootprintGrid), so that each tile takes the footprints near it. Before, each tile read the
/// whole file and planned with every footprint of the survey.
class RunFootprints {
 public:
  explicit RunFootprints(const CityOptions& options) : options_(options) {}
  /// The footprints in `points_crs` (load_footprints); null without --footprints.
  const FootprintGrid* get(const std::string& points_crs);
  std::size_t reads() const { return reads_; }  ///< times the footprint file was read

 private:
  const CityOptions& options_;
  std::unique_ptr<FootprintGrid> grid_;
  std::string crs_;
  std::size_t reads_ = 0;
};

/// Plans one tile (see the header comment); with --resume, the tile's plan.json when it still fits.
/// Throws hsr::Error for a tile that cannot be read (the tile then has no plan), and Error(BadInput) when the
/// run has this one tile, footprints, and none of them lies on it (require_footprints_on_tiles).
/// `footprints`: the run's (run_city); null: the tile reads the footprint file itself (a tile planned alone, the
/// Dask driver's plan task).
/// `index`: the run's (run_city, a survey): the files decoded whole, so that a neighbour's census decodes only the
/// parts meeting the margin (city_survey.h SurveyIndex, DECISIONS #142); null: every file decoded whole.
TilePlan plan_tile(const CityOptions& options, const TileFiles& files, RunFootprints* footprints = nullptr,
                   SurveyIndex* index = nullptr);

/// Footprints were given but none lies on any tile of `plans` (every tile's plan): throws Error(BadInput,
/// "city") with one line naming --crs (the footprints are in another CRS than the points, or of another
/// place). Without footprints, or with one on some tile, nothing.
void require_footprints_on_tiles(const CityOptions& options, const std::vector<TilePlan>& plans);

/// The rows of a plan: failed buildings get theirs now (status degenerate-input, the reason), groups that are
/// not buildings theirs (status kNotABuilding, why), footprints without points theirs (kNoPoints); the others are to run, or with --resume done already
/// (driver::done_row). `todo` receives the indices to run.
std::vector<driver::Row> initial_rows(const CityOptions& options, const TilePlan& plan, std::vector<std::size_t>& todo);

/// Writes the tile's summary and CityJSONSeq; returns the number of buildings that failed (the groups that
/// are not buildings and the footprints without points are listed, not counted).
std::size_t finish_tile(const CityOptions& options, const TilePlan& plan, const std::vector<driver::Row>& rows);

/// What a run held, for tests of its memory (DECISIONS #103).
struct CityRunStats {
  std::size_t footprint_reads = 0;      ///< times the footprint file was read (1 with footprints, whatever the tiles)
  std::size_t most_buildings_held = 0;  ///< the most planned buildings held at once (one tile's: plans go with their tile)
  std::size_t most_index_files = 0;     ///< the most files the SurveyIndex held at once (DECISIONS #142), after a tile
};

/// Every tile, options.jobs children at once, one tile after the other: a tile's plan is dropped once its
/// tile is written (its counts kept). Exit code: 0 when every building was modelled (groups that are
/// not buildings and footprints without points do not count), 1 when one failed; a bad input (require_footprints_on_tiles, a tile that
/// cannot be read, ...) throws hsr::Error, the CLI's one line and its exit code. `stats`: filled when given.
int run_city(const CityOptions& options, CityRunStats* stats = nullptr);

/// Registers the `city` subcommand.
CLI::App* add_city_command(CLI::App& app, CityOptions& options);

// JSON forms, for plan.json and the Python driver.
nlohmann::json to_json(const CityOptions& o);
CityOptions options_from_json(const nlohmann::json& j);
nlohmann::json to_json(const TilePlan& plan);
TilePlan plan_from_json(const nlohmann::json& j);
nlohmann::json to_json(const TileFiles& f);
TileFiles files_from_json(const nlohmann::json& j);

}  // namespace hsr::city
