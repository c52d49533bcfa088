// `hsr city` (city_run.h): plan each tile, run its buildings as `hsr batch` runs its inputs, write its sequence.
#include "driver/city_run.h"

#include "driver/city_survey.h"
#include "core/error.h"
#include "core/log.h"
#include "core/threads.h"
#include "core/memory.h"
#include "io/cityjson.h"
#include "io/io.h"

#include <CLI/CLI.hpp>

#include <sys/stat.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <thread>

namespace hsr::city {

namespace fs = std::filesystem;

namespace {

constexpr const char* kStage = "city";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

[[noreturn]] void bad(const std::string& what) { throw Error(Status::BadInput, kStage, what); }

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

/// What a file is, for --resume: its absolute path, size and modification time.
nlohmann::json file_key(const std::string& path) {
  if (path.empty()) return nullptr;
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return {{"path", path}};
  return {{"path", fs::absolute(path).lexically_normal().string()}, {"size", static_cast<std::int64_t>(st.st_size)},
          {"mtime_ns", static_cast<std::int64_t>(st.st_mtim.tv_sec) * 1000000000 + st.st_mtim.tv_nsec}};
}

/// Everything a plan depends on: the tile, the footprints and the options that shape the buildings and the
/// children's command lines (not --jobs, --resume or the output names).
nlohmann::json plan_key(const CityOptions& o, const TileFiles& files) {
  nlohmann::json params;
  to_json(params, o.params);
  nlohmann::json survey = nlohmann::json::array();  // several tiles: each is planned with its neighbours' points
  if (o.tiles.size() > 1)
    for (const std::string& t : o.tiles) survey.push_back(file_key(t));
  return {{"tile", file_key(files.tile)}, {"survey", survey}, {"footprints", file_key(o.footprints)}, {"layer", o.footprint_layer},
          {"id_field", o.id_field}, {"crs", o.crs}, {"cityjson_scale", o.cityjson_scale},
          {"reconstruct_args", o.reconstruct_args}, {"hsr_cli", driver::cli_path(o, kStage)}, {"params", params}};
}

/// The threads each building's run gets: the cores shared by the jobs (cores / jobs, at least 1; --jobs 0 is one
/// job per core), so that jobs x threads do not oversubscribe the machine; 0 (the run's default: every core, or
/// HSR_THREADS) when the cores are unknown or HSR_THREADS is set. Why: with two jobs on two cores each run's
/// threads only took turns with the other job's, and step 5's runs, which run at once when a run has threads
/// to spare (DECISIONS #157), are then better one after the other, each stopped early where it can be.
int building_threads(unsigned jobs, unsigned cores) {
  if (cores == 0 || resolve_thread_count(0) > 0) return 0;  // HSR_THREADS decides (core/threads.h)
  const unsigned j = jobs == 0 ? cores : jobs;
  return static_cast<int>(std::max(1u, cores / j));
}

/// The turns' lock files of a tile (driver::run_items' `turns`), or "" where its buildings run one at a time: where
/// asked (--one-at-a-time), and where a building's run has one thread (as many jobs as cores): then the jobs keep
/// the cores busy and a job's two children at once were no faster (1.03 x with two surfaces, 1.04 x with the
/// defaults, -j 2 on the AHN3 tile, DECISIONS #235).
std::string turns_of(const CityOptions& o, const TileFiles& files, unsigned cores) {
  if (o.one_at_a_time || building_threads(o.jobs, cores) < 2) return "";
  return (fs::path(files.work) / ".turn").string();
}

/// The child's command line for one building.
std::vector<std::string> child_argv(const CityOptions& o, const PlannedBuilding& b, const std::string& footprint_file) {
  std::vector<std::string> argv = {driver::cli_path(o, kStage), "reconstruct", b.item.input, "-o", b.item.output, "--report", b.item.report,
                                   "--scene", "building", "--cityjson-scale", driver::format_number(o.cityjson_scale)};
  if (!std::isnan(b.ground_z)) argv.insert(argv.end(), {"--ground-z", driver::format_number(b.ground_z), "--trust-ground-z"});
  if (!footprint_file.empty()) argv.insert(argv.end(), {"--footprint", footprint_file});
  if (!footprint_file.empty() && b.footprint_prism) argv.push_back("--footprint-prism");
  argv.insert(argv.end(), o.reconstruct_args.begin(), o.reconstruct_args.end());
  const bool given = std::find(o.reconstruct_args.begin(), o.reconstruct_args.end(), "--threads") != o.reconstruct_args.end();
  if (const int threads = building_threads(o.jobs, std::thread::hardware_concurrency()); threads > 0 && !given)
    argv.insert(argv.end(), {"--threads", std::to_string(threads)});
  return argv;
}

/// Unique file names for the ids (safe characters; a number appended where two ids give the same name).
std::vector<std::string> building_names(const std::vector<std::string>& ids) {
  std::vector<std::string> names;
  std::map<std::string, int> used;
  for (const std::string& id : ids) {
    std::string name = driver::safe_file_name(id.empty() ? "building" : id);
    if (used[name]++) name += "_" + std::to_string(used[name]);
    names.push_back(name);
  }
  return names;
}

/// The sequence's reference system: --crs, else the tile's when it names an EPSG CRS.
std::string sequence_crs(const CityOptions& o, const PointCloud& tile) {
  if (!o.crs.empty()) return o.crs;
  if (tile.crs.empty()) {
    log::warn("city: " + tile.source + " names no CRS: the sequence has no referenceSystem (give --crs EPSG:N)");
    return "";
  }
  const std::string code = crs_epsg_code(tile.crs);
  if (code.empty()) log::warn("city: the CRS of " + tile.source + " has no EPSG code: no referenceSystem (give --crs EPSG:N)");
  return code;
}

/// The tile stage's parameters in the tile's units (its CRS in feet: the metres converted).
CityParams tile_params(const CityOptions& o, const std::string& tile_crs, const std::string& source) {
  const std::string crs = o.crs.empty() ? tile_crs : o.crs;
  bool projected = false;
  std::string unit;
  const double metres = crs_metres_per_unit(crs, &projected, &unit);
  if (!crs.empty() && !projected)
    log::warn("city: the CRS of " + source + " is not projected: its lengths are taken as metres");
  if (metres == 1.0) return o.params;
  log::info("city: " + source + " is in " + unit + " (" + driver::format_number(metres) + " m): lengths converted");
  return in_tile_units(o.params, metres, unit == "US survey foot" ? "US ft" : unit == "foot" ? "ft" : unit);
}

/// The line of require_footprints_on_tiles: what was compared and what to do.
std::string no_footprint_line(const CityOptions& o, const TilePlan& plan, std::size_t tiles) {
  const std::string where = tiles == 1 ? "the tile " + plan.files.tile : "any of the " + std::to_string(tiles) + " tiles";
  return "none of the " + std::to_string(plan.footprints_off_tile) + " footprints of " + o.footprints + " lies on " + where +
         " (" + plan.crs_note + "): " +
         (plan.crs_compared ? "footprints of another place, or a wrong --crs for the points"
                            : "give the points' CRS with --crs EPSG:N, so that the footprints are brought into it");
}

/// The reader of the tile's points (city_survey.h), its own points counted.
RegionReader region_reader(const CityOptions& o, const TileFiles& files, SurveyIndex* index) {
  const bool group_cells = o.footprints.empty();  // only groups read them
  if (o.tiles.size() < 2) {
    RegionReader reader({files.tile}, 0, group_cells);
    reader.set_every_part(o.every_part);
    return reader;
  }
  const auto at = std::find(o.tiles.begin(), o.tiles.end(), files.tile);
  if (at == o.tiles.end()) bad("plan: " + files.tile + " is not one of the run's tiles");
  RegionReader reader(o.tiles, static_cast<int>(at - o.tiles.begin()), group_cells, index);
  reader.set_every_part(o.every_part);
  return reader;
}

/// The tile's plan (run_city_tile) on the points it reads (city_survey.h): a region whose file classes give
/// its ground and building points keeps those near a building, within the first ground ring (or the
/// footprints' buffer) and a slack; a building whose ring had to widen past that is planned again with its
/// surroundings to the widest ring read too. Else every point is kept. `tile` receives the cloud.
CityTile plan_on_kept_points(const RegionReader& reader, const std::vector<FootprintFeature>* footprints, const CityParams& params,
                             PointCloud& tile, SurveyRegion& region, std::vector<std::uint32_t>* own_building = nullptr) {
  if (!reader.classified(params.classes)) {
    tile = reader.read(nullptr, region);
    return run_city_tile(tile, footprints, params, region);
  }
  const double slack = RegionReader::kSlack;
  const double complete = std::max(params.ring_outer, params.buffer);  // rings up to this read every ground point
  const double cells = footprints ? 0.0 : 2 * params.component_cell;  // a group's cell lies within this of its points
  KeepMask keep = first_keep_mask(reader, footprints, params);
  const std::size_t parts_read = reader.parts_read(), parts_total = reader.parts_total();
  tile = reader.read(&keep, region, own_building);
  const std::string parts = std::to_string(reader.parts_read() - parts_read) + " of " + std::to_string(reader.parts_total() - parts_total) +
                            " parts of the files decoded";
  CityTile split = run_city_tile(tile, footprints, params, region);
  std::size_t wider = 0;
  for (const TileBuilding& b : split.buildings) {
    if (b.ring_outer <= complete) continue;
    BBox box;
    for (const FootprintPolygon& poly : b.footprint)
      for (const Vec2& q : poly.outer) box.extend(Vec3(q.x(), q.y(), 0));
    for (std::size_t i : b.points) box.extend(tile.points[i] + tile.origin);
    if (!box.valid()) continue;
    const double reach = params.ring_max_outer + cells + slack;
    keep.mark(box.min.x() - reach, box.min.y() - reach, box.max.x() + reach, box.max.y() + reach);
    ++wider;
  }
  const std::size_t all = tile.size() + region.left_out.ground + region.left_out.building + region.left_out.other;
  log::info("city: " + reader.source() + ": " + std::to_string(tile.size()) + " of " + std::to_string(all) +
            " points kept (building points and the ground near them; " + parts + ")" +
            (wider ? "; " + std::to_string(wider) + " ground rings widened: read again" : ""));
  if (!wider) return split;
  split = CityTile{};  // its flags and point lists go before the region is read again
  tile = PointCloud{};
  tile = reader.read(&keep, region, own_building);
  return run_city_tile(tile, footprints, params, region);
}

/// The plan's entry for one building of the tile, its files written (NAME.ply: its points of `tile`; its footprint).
PlannedBuilding planned_building(const CityOptions& o, const TileFiles& files, const TileBuilding& tb, const std::string& name,
                                 const PointCloud& tile, double metres) {
  PlannedBuilding b;
  b.id = tb.id;
  b.name = name;
  b.points = tb.points.size();
  b.area = tb.area * metres * metres;  // m², whatever the tile's unit
  b.ground_z = tb.ground_z;
  b.ground_points = tb.ground_points;
  b.ground_source = tb.ground_source;
  b.attributes = tb.attributes;
  b.failure = tb.failure;
  b.not_building = tb.not_building;
  b.footprint_prism = tb.footprint_prism;
  b.no_points = tb.no_points;
  const fs::path base = fs::path(files.work) / b.name;
  b.item.input = base.string() + ".ply";
  b.item.name = b.name;
  b.item.output = base.string() + ".city.json";
  b.item.report = base.string() + ".report.json";
  b.item.log = base.string() + ".log";
  std::string footprint_file;
  if (b.failure.empty() && b.not_building.empty() && b.no_points.empty()) {
    PointCloud points = select_points(tile, tb.points);
    points.normals.clear();  // as the tile's points always went to the child: it estimates its own normals
    write_points(b.item.input, points, FileEncoding::Binary);
    if (!tb.footprint.empty()) {
      footprint_file = base.string() + ".footprint.geojson";
      driver::write_json(footprint_file, footprint_geojson({tb.id, tb.footprint, tb.attributes}), kStage);
    }
  }
  b.item.argv = child_argv(o, b, footprint_file);
  return b;
}

/// The log lines and counts of a plan (make_plan, make_plan_in_blocks) once its buildings are known.
void describe_plan(const CityOptions& o, const TileFiles& files, const FootprintGrid* grid, const CityTile& split, std::size_t off_tile,
                   bool any_building, TilePlan& plan) {
  if (split.small_groups)
    log::info("city: " + files.tile + ": " + std::to_string(split.small_groups) + " groups too small to be buildings left out");
  if (grid && off_tile && any_building) log::info("city: " + files.tile + ": " + std::to_string(off_tile) + " footprints lie off this tile");
  if (split.groups_elsewhere)
    log::info("city: " + files.tile + ": " + std::to_string(split.groups_elsewhere) + " groups across its edges are planned by a neighbour");
  if (split.vegetation_groups)
    log::info("city: " + files.tile + ": " + std::to_string(split.vegetation_groups) +
              " groups are vegetation, not buildings (listed as " + kNotABuilding + ")");
  plan.classes = split.classes;
  plan.buildings_from = split.buildings_from;
  plan.unused_building_points = split.unused_building_points;
  if (grid) {
    const FootprintSet& footprints = grid->set();
    plan.crs_note = footprints.crs_note;
    plan.crs_compared = footprints.crs_compared;
    plan.footprints_off_tile = off_tile;
    if (o.tiles.size() == 1) require_footprints_on_tiles(o, {plan});  // before anything is written or warned
    if (!plan.crs_compared && !footprints.crs.empty())
      log::warn("city: " + files.tile + ": " + plan.crs_note + ": give the points' CRS with --crs EPSG:N");
  }
}

/// How far around a footprint's plan box its plan reads points (file units): its building points within the
/// buffer, their box grown by the widest ground ring (plan_on_kept_points' second read), and a unit of slack.
double block_window_reach(const CityParams& p) { return p.buffer + p.ring_max_outer + RegionReader::kSlack + 1.0; }

/// One large tile planned block by block (issue 40 item 2; DECISIONS #124; CityOptions::block): the footprints
/// the whole tile plans, each given to the block owning its centre (TileBlocks::of); per block, the points within
/// block_window_reach of its footprints' boxes read (one decode of the tile per block), planned and its
/// buildings' files written, then dropped; the buildings merged in footprint order. The same plan to the byte as
/// the whole tile's: a building's plan reads only points within that reach of its box, kept in the same file
/// order, in the same local frame (the tile's origin), and the classes line counts every point either way.
/// The building points no building took are counted by their rank among the tile's (one bit each).
std::optional<TilePlan> make_plan_in_blocks(const CityOptions& o, const TileFiles& files, RegionReader& reader, const CityParams& params,
                                            const FootprintGrid* grid) {
  const double metres = crs_metres_per_unit(o.crs.empty() ? reader.crs() : o.crs);
  const TileBlocks blocks = TileBlocks::over(reader.own_box(), o.block / metres);
  if (!grid || blocks.count() < 2 || !reader.classified(params.classes) || reader.own_building_points() >= RegionReader::kNotOwnBuilding)
    return std::nullopt;
  const std::vector<FootprintFeature>& features = grid->set().features;
  std::vector<std::size_t> planned;  // feature indices the tile plans, ascending
  std::vector<std::vector<std::size_t>> of_block(static_cast<std::size_t>(blocks.count()));
  for (std::size_t i : grid->meeting(reader.footprint_reach()))
    if (reader.plans(features[i].footprint)) {
      of_block[static_cast<std::size_t>(blocks.of(footprint_plan_centre(features[i].footprint, reader.origin())))].push_back(planned.size());
      planned.push_back(i);
    }
  if (planned.empty()) return std::nullopt;
  std::vector<std::string> ids;
  for (std::size_t i : planned) ids.push_back(features[i].id);
  const std::vector<std::string> names = building_names(ids);
  fs::create_directories(files.work);
  std::vector<PlannedBuilding> buildings(planned.size());
  std::vector<std::uint64_t> used((reader.own_building_points() + 63) / 64, 0);  // per own building point: taken
  std::optional<CityTile> first;  // the first block's counts (the classes line is every block's)
  std::string crs;
  const double reach = block_window_reach(params);
  for (int k = 0; k < blocks.count(); ++k) {
    const std::vector<std::size_t>& mine = of_block[static_cast<std::size_t>(k)];
    if (mine.empty()) continue;
    BBox window;
    for (std::size_t m : mine)
      for (const FootprintPolygon& poly : features[planned[m]].footprint)
        for (const Vec2& q : poly.outer) window.extend(Vec3(q.x(), q.y(), 0));
    window.min -= Vec3(reach, reach, 0);
    window.max += Vec3(reach, reach, 0);
    reader.set_block(blocks, k, window);
    std::vector<FootprintFeature> near;
    for (std::size_t i : grid->meeting(reader.footprint_reach())) near.push_back(features[i]);
    SurveyRegion region;
    PointCloud tile;
    std::vector<std::uint32_t> rank;
    CityTile split = plan_on_kept_points(reader, &near, params, tile, region, &rank);
    if (split.buildings.size() != mine.size())
      throw Error(Status::Internal, kStage, "block " + std::to_string(k) + " planned " + std::to_string(split.buildings.size()) +
                                                " buildings, not its " + std::to_string(mine.size()));
    log::info("city: " + files.tile + ": block " + std::to_string(k + 1) + " of " + std::to_string(blocks.count()) + ": " +
              std::to_string(mine.size()) + " buildings");
    for (std::size_t n = 0; n < mine.size(); ++n) {
      const TileBuilding& tb = split.buildings[n];
      for (std::size_t i : tb.points)
        if (rank[i] != RegionReader::kNotOwnBuilding) used[rank[i] / 64] |= std::uint64_t(1) << (rank[i] % 64);
      buildings[mine[n]] = planned_building(o, files, tb, names[mine[n]], tile, metres);
    }
    if (!first) {
      crs = sequence_crs(o, tile);
      split.buildings.clear();
      first = std::move(split);
    } else if (split.classes != first->classes) {
      throw Error(Status::Internal, kStage, "block " + std::to_string(k) + " counts the classes otherwise: " + split.classes);
    }
    tile = PointCloud{};
    release_free_memory();  // the block's points go before the next block's
  }
  reader.set_block(blocks, -1, BBox{});
  std::size_t taken = 0;
  for (std::uint64_t w : used) taken += static_cast<std::size_t>(__builtin_popcountll(w));
  TilePlan plan;
  plan.files = files;
  first->unused_building_points = reader.own_building_points() - taken;
  plan.footprints_on_tile = planned.size();
  describe_plan(o, files, grid, *first, features.size() - planned.size(), true, plan);
  plan.crs = crs;
  plan.buildings = std::move(buildings);
  return plan;
}

TilePlan make_plan(const CityOptions& o, const TileFiles& files, RunFootprints* run_footprints, SurveyIndex* index) {
  RegionReader reader = region_reader(o, files, index);
  // The footprints before the tile's units: the child process that reads them answers the CRS questions
  // too, one child and one load of GDAL, not two (footprints.cpp, DECISIONS #245).
  const std::string points_crs = o.crs.empty() ? reader.crs() : o.crs;
  std::unique_ptr<FootprintGrid> read_here;  // no run's footprints (one tile planned alone, a Dask task): read now
  const FootprintGrid* grid = nullptr;
  if (run_footprints) {
    grid = run_footprints->get(points_crs);
  } else if (std::unique_ptr<FootprintSet> set = load_footprints(o, points_crs)) {
    read_here = std::make_unique<FootprintGrid>(std::move(*set));
    grid = read_here.get();
  }
  const CityParams params = tile_params(o, reader.crs(), reader.source());
  reader.add_neighbours(params.tile_margin);
  if (o.tiles.size() > 1)
    log::info("city: " + reader.source() + ": its census decoded " + std::to_string(reader.census_parts_read()) + " of " +
              std::to_string(reader.census_parts_total()) + " parts of the region's files, " +
              std::to_string(reader.census_points_decoded()) + " points");
  if (std::optional<TilePlan> blocks = make_plan_in_blocks(o, files, reader, params, grid)) return std::move(*blocks);
  // Only the footprints near the region: the others are off the tile and hold none of its points.
  std::vector<FootprintFeature> near;
  if (grid)
    for (std::size_t i : grid->meeting(reader.footprint_reach())) near.push_back(grid->set().features[i]);
  const std::size_t far = grid ? grid->set().features.size() - near.size() : 0;
  TilePlan plan;
  plan.files = files;
  SurveyRegion region;
  PointCloud tile;
  const CityTile split = plan_on_kept_points(reader, grid ? &near : nullptr, params, tile, region);
  near.clear();
  near.shrink_to_fit();
  const double metres = crs_metres_per_unit(o.crs.empty() ? tile.crs : o.crs);
  if (grid) plan.footprints_on_tile = split.buildings.size();
  describe_plan(o, files, grid, split, split.footprints_elsewhere + far, !split.buildings.empty(), plan);
  plan.crs = sequence_crs(o, tile);
  fs::create_directories(files.work);
  std::vector<std::string> ids;
  for (const TileBuilding& b : split.buildings) ids.push_back(b.id);
  const std::vector<std::string> names = building_names(ids);
  for (std::size_t k = 0; k < split.buildings.size(); ++k)
    plan.buildings.push_back(planned_building(o, files, split.buildings[k], names[k], tile, metres));
  return plan;
}

/// The building's footprint (NAME.footprint.geojson beside its points NAME.ply, written by planned_building) with
/// `origin` taken off, or none (a group, or a footprint-less run): the density and no-data share are over it.
Footprint footprint_in_mesh_frame(const std::string& points_file, const Vec3& origin) {
  fs::path path(points_file);
  path.replace_extension(".footprint.geojson");
  if (!fs::exists(path)) return {};
  FootprintSet set = read_footprints(path.string());
  if (set.features.size() != 1) return {};
  Footprint fp = std::move(set.features[0].footprint);
  const Vec2 o(origin.x(), origin.y());
  for (FootprintPolygon& poly : fp) {
    for (Vec2& q : poly.outer) q -= o;
    for (auto& h : poly.holes)
      for (Vec2& q : h) q -= o;
  }
  return fp;
}

/// The feature's LoD 1.2 and 1.3 and their attributes (src/city/lods.h), from its LoD 2.2 and its points
/// (the child's input, NAME.ply); the LoD 2.2 roof surfaces' slope, azimuth and area.
void add_lods(driver::SequenceEntry& e, const LodParams& lods) {
  const std::string points_file = e.input;
  e.lods = [points_file, lods](const CityBuilding& b, const nlohmann::json& attributes, double scale) {
    LodParams p = lods;
    p.grid = scale;
    const PointCloud cloud = read_points(points_file);
    std::vector<Vec3> points;
    points.reserve(cloud.points.size());
    for (const Vec3& v : cloud.points) points.push_back(v + (cloud.origin - b.mesh.origin));
    BuildingLods made = building_lods(b.mesh, points, attributes, p, footprint_in_mesh_frame(points_file, b.mesh.origin));
    driver::FeatureLods out;
    out.keep_read = p.lod22;
    out.solids = std::move(made.solids);
    out.attributes = std::move(made.attributes);
    return out;
  };
  e.surface_attributes = [](const std::string& lod, const PolygonMesh& mesh, std::size_t face) {
    return lod == "2.2" ? roof_surface_attributes(mesh, face) : nlohmann::json(nullptr);
  };
}

/// "city: tile 3 of 16 done (r0c2.las): 978 buildings in 2.4 min, 407 buildings/min, ETA 31 min (13 tiles)" (under a
/// minute: "in 40 s"):
/// after each tile of a survey, the buildings run so far over the run's wall time (planning included) and the
/// time left at the mean time per tile so far. Why tiles and not buildings: the survey's buildings are known only
/// once every tile is planned.
std::string survey_progress_line(std::size_t tiles_done, std::size_t tiles, const std::string& tile, std::size_t buildings,
                                 double elapsed) {
  const double minutes = elapsed / 60.0;
  const double left = tiles_done ? elapsed / static_cast<double>(tiles_done) * static_cast<double>(tiles - tiles_done) : 0.0;
  std::string eta = tiles_done == tiles ? "done"
                    : left < 60     ? "ETA " + std::to_string(static_cast<int>(std::ceil(left))) + " s"
                                    : "ETA " + std::to_string(static_cast<int>(std::ceil(left / 60))) + " min";
  if (tiles_done < tiles) eta += " (" + std::to_string(tiles - tiles_done) + (tiles - tiles_done == 1 ? " tile)" : " tiles)");
  char buf[96];
  std::snprintf(buf, sizeof buf, elapsed < 60 ? " in %.0f s, %.0f buildings/min, " : " in %.1f min, %.0f buildings/min, ",
                elapsed < 60 ? elapsed : minutes, minutes > 0 ? static_cast<double>(buildings) / minutes : 0.0);
  return "city: tile " + std::to_string(tiles_done) + " of " + std::to_string(tiles) + " done (" +
         fs::path(tile).filename().string() + "): " + std::to_string(buildings) + " buildings" + buf + eta;
}

/// A written tile's plan as the rest of the run needs it (require_footprints_on_tiles: its footprint counts and
/// CRS note): its buildings dropped. Why: a survey's plans, kept whole to the end, grew with the survey.
TilePlan without_buildings(TilePlan plan) {
  plan.buildings.clear();
  plan.buildings.shrink_to_fit();
  return plan;
}

std::string fixed(double v, int digits) {
  if (std::isnan(v)) return "";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", digits, v);
  return buf;
}

}  // namespace

std::vector<std::string> expand_tile_folders(const std::vector<std::string>& args) {
  std::vector<std::string> out;
  for (const std::string& a : args) {
    std::error_code ec;
    if (!fs::is_directory(a, ec)) {
      out.push_back(a);
      continue;
    }
    std::vector<std::string> files;
    for (const auto& e : fs::directory_iterator(a)) {
      const std::string ext = file_extension(e.path().string());
      if (e.is_regular_file() && (ext == "las" || ext == "laz")) files.push_back(e.path().string());
    }
    if (files.empty()) bad("the folder " + a + " holds no LAS/LAZ file");
    std::sort(files.begin(), files.end());
    out.insert(out.end(), files.begin(), files.end());
  }
  return out;
}

std::vector<TileFiles> tile_files(const CityOptions& o) {
  if (o.tiles.empty()) bad("no tile given");
  LodParams lods;
  parse_lod_list(o.lod, lods);  // a bad --lod fails before any work
  if (o.output.empty()) bad("no output given (-o OUT.city.jsonl, or -o DIR for several tiles)");
  driver::require_distinct(o.tiles, kStage, "tile");
  std::vector<TileFiles> out;
  if (ends_with(o.output, ".city.jsonl")) {
    if (o.tiles.size() != 1) bad("-o " + o.output + " names one sequence: give one tile, or -o DIR for several");
    const std::string stem = o.output.substr(0, o.output.size() - std::string(".city.jsonl").size());
    out.push_back({o.tiles.front(), o.output, stem + ".summary.csv", stem + ".work"});
    return out;
  }
  const std::vector<std::string> names = driver::unique_names(o.tiles);
  for (std::size_t i = 0; i < o.tiles.size(); ++i) {
    const std::string base = (fs::path(o.output) / names[i]).string();
    out.push_back({o.tiles[i], base + ".city.jsonl", base + ".summary.csv", base + ".work"});
  }
  return out;
}

std::unique_ptr<FootprintSet> load_footprints(const CityOptions& o, const std::string& points_crs) {
  if (o.footprints.empty()) return nullptr;
  FootprintReadParams rp;
  rp.layer = o.footprint_layer;
  rp.id_field = o.id_field;
  rp.points_crs = points_crs;
  auto set = std::make_unique<FootprintSet>(read_footprints(o.footprints, rp));
  log::info("city: " + std::to_string(set->features.size()) + " footprints in " + o.footprints + " (" + set->crs_note + ")" +
            (set->skipped ? "; " + std::to_string(set->skipped) + " features without a polygon skipped" : ""));
  return set;
}

const FootprintGrid* RunFootprints::get(const std::string& points_crs) {
  if (options_.footprints.empty()) return nullptr;
  if (!grid_ || points_crs != crs_) {
    grid_.reset();  // the footprints in another CRS go first
    grid_ = std::make_unique<FootprintGrid>(std::move(*load_footprints(options_, points_crs)));
    crs_ = points_crs;
    ++reads_;
  }
  return grid_.get();
}

TilePlan plan_tile(const CityOptions& o, const TileFiles& files, RunFootprints* footprints, SurveyIndex* index) {
  const std::string plan_path = (fs::path(files.work) / "plan.json").string();
  const nlohmann::json key = plan_key(o, files);
  if (o.resume && fs::exists(plan_path)) {
    const nlohmann::json j = driver::read_json(plan_path);
    if (j.is_object() && j.value("key", nlohmann::json()) == key) {
      TilePlan plan = plan_from_json(j);
      plan.files = files;
      log::info("city: " + files.tile + ": plan of " + std::to_string(plan.buildings.size()) + " buildings reused (--resume)");
      return plan;
    }
  }
  TilePlan plan = make_plan(o, files, footprints, index);
  release_free_memory();  // the tile's points are gone: the next tile's plan starts from what the run holds
  nlohmann::json j = to_json(plan);
  j["key"] = key;
  driver::write_json(plan_path, j, kStage);
  std::size_t failed = 0;
  for (const auto& b : plan.buildings) failed += !b.failure.empty();
  log::info("city: " + files.tile + ": " + plan.classes);
  log::info("city: " + files.tile + ": " + std::to_string(plan.buildings.size()) + " buildings from " + plan.buildings_from +
            (failed ? " (" + std::to_string(failed) + " not run: see the summary)" : "") +
            (plan.unused_building_points ? "; " + std::to_string(plan.unused_building_points) + " building points in none" : ""));
  return plan;
}

void require_footprints_on_tiles(const CityOptions& o, const std::vector<TilePlan>& plans) {
  if (o.footprints.empty() || plans.empty()) return;
  for (const TilePlan& p : plans)
    if (p.footprints_on_tile) return;
  bad(no_footprint_line(o, plans.front(), plans.size()));
}

std::vector<driver::Row> initial_rows(const CityOptions& o, const TilePlan& plan, std::vector<std::size_t>& todo) {
  std::vector<driver::Row> rows(plan.buildings.size());
  todo.clear();
  for (std::size_t i = 0; i < plan.buildings.size(); ++i) {
    const PlannedBuilding& b = plan.buildings[i];
    rows[i].input = b.item.input;
    if (!b.failure.empty()) {
      rows[i].status = status_name(Status::DegenerateInput);
      rows[i].message = b.failure;
      continue;
    }
    if (!b.not_building.empty()) {
      rows[i].status = kNotABuilding;
      rows[i].message = b.not_building;
      continue;
    }
    if (!b.no_points.empty()) {
      rows[i].status = kNoPoints;
      rows[i].message = b.no_points;
      continue;
    }
    std::optional<driver::Row> done = o.resume ? driver::done_row(b.item) : std::nullopt;
    if (done) rows[i] = *done;
    else todo.push_back(i);
  }
  return rows;
}

namespace {

/// The LoDs asked for (--lod) in the plan's CRS units.
LodParams tile_lods(const CityOptions& o, const TilePlan& plan) {
  LodParams lods;
  parse_lod_list(o.lod, lods);
  lods.metres_per_unit = crs_metres_per_unit(plan.crs);
  return lods;
}

/// Building b's feature in the tile's sequence (written only when its run succeeded).
driver::SequenceEntry sequence_entry(const PlannedBuilding& b, const LodParams& lods) {
  driver::SequenceEntry e;
  e.input = b.item.input;
  e.cityjson = b.item.output;
  e.id = b.id;
  e.before = b.attributes;
  e.after = {{"hsr_points", b.points}, {"hsr_ground_source", b.ground_source}};
  if (!std::isnan(b.ground_z)) e.after["hsr_ground_z"] = b.ground_z;
  e.drop = {"hsr_seconds"};  // the run's time: the sequence stays the same bytes from run to run
  add_lods(e, lods);
  return e;
}

/// finish_tile with the features of some buildings made already (`entries` and `prepared`: one per planned
/// building, as run_city's FeatureMaker made them).
std::size_t finish_tile_prepared(const CityOptions& o, const TilePlan& plan, const std::vector<driver::Row>& rows,
                                 std::vector<driver::SequenceEntry> all,
                                 std::vector<std::optional<driver::PreparedFeature>> prepared) {
  if (rows.size() != plan.buildings.size() || all.size() != rows.size() || prepared.size() != rows.size())
    bad("finish: " + std::to_string(rows.size()) + " rows for " + std::to_string(plan.buildings.size()) + " buildings");
  std::vector<std::vector<std::string>> extra;
  std::vector<driver::SequenceEntry> entries;
  std::vector<std::optional<driver::PreparedFeature>> made;
  std::size_t failed = 0;
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const PlannedBuilding& b = plan.buildings[i];
    extra.push_back({b.id, std::to_string(b.points), fixed(b.area, 1), fixed(b.ground_z, 3), std::to_string(b.ground_points), b.ground_source});
    if (!rows[i].ok()) {
      failed += rows[i].status != kNotABuilding && rows[i].status != kNoPoints;
      continue;
    }
    entries.push_back(std::move(all[i]));
    made.push_back(std::move(prepared[i]));
  }
  driver::write_summary_csv(plan.files.summary, rows, {"building", "points", "area_m2", "ground_z", "ground_points", "ground_source"}, extra);
  const std::size_t written = driver::write_cityjson_sequence(plan.files.sequence, o.cityjson_scale, plan.crs, entries, std::move(made));
  log::info("city: " + plan.files.tile + ": " + std::to_string(written) + " of " + std::to_string(rows.size()) +
            " buildings in " + plan.files.sequence + "; summary in " + plan.files.summary);
  return failed + (entries.size() - written);
}

}  // namespace

std::size_t finish_tile(const CityOptions& o, const TilePlan& plan, const std::vector<driver::Row>& rows) {
  const LodParams lods = tile_lods(o, plan);
  std::vector<driver::SequenceEntry> entries;
  for (const PlannedBuilding& b : plan.buildings) entries.push_back(sequence_entry(b, lods));
  return finish_tile_prepared(o, plan, rows, std::move(entries),
                              std::vector<std::optional<driver::PreparedFeature>>(plan.buildings.size()));
}

int run_city(const CityOptions& o, CityRunStats* stats) {
  const std::vector<TileFiles> tiles = tile_files(o);
  if (!ends_with(o.output, ".city.jsonl")) fs::create_directories(o.output);
  if (!o.crs.empty()) crs_url(o.crs);  // a bad --crs fails before any work
  std::size_t failures = 0, buildings = 0;
  RunFootprints footprints(o);  // read once, by the first tile that needs them
  SurveyIndex index;            // the files decoded whole, so that a neighbour's margin is read in its parts (#142)
  std::vector<TilePlan> done;   // each tile's plan once its tile is written: its counts, no building
  std::size_t held = 0;         // the buildings of the plans the run holds
  const double t0 = log::now_seconds();
  for (const TileFiles& files : tiles) {
    TilePlan plan = plan_tile(o, files, &footprints, tiles.size() > 1 ? &index : nullptr);
    index.forget_after(static_cast<int>(done.size()));  // the files no tile still to plan reads
    if (stats) stats->most_index_files = std::max(stats->most_index_files, index.files());
    held += plan.buildings.size();
    if (stats) stats->most_buildings_held = std::max(stats->most_buildings_held, held);
    // A survey's per-building lines name the tile, and each tile ends with the survey's progress.
    const std::string label = tiles.size() == 1 ? std::string(kStage)
                                                : "city: tile " + std::to_string(done.size() + 1) + " of " + std::to_string(tiles.size());
    std::vector<std::size_t> todo;
    std::vector<driver::Row> rows = initial_rows(o, plan, todo);
    std::vector<driver::Item> items;
    for (const PlannedBuilding& b : plan.buildings) items.push_back(b.item);
    const std::size_t ran = rows.size() - todo.size();
    if (o.resume && ran) log::info("city: " + std::to_string(ran) + " of " + std::to_string(rows.size()) + " buildings already done or not to run");
    // Each building's feature (its LoDs) is made as soon as its run is done (driver::FeatureMaker).
    const LodParams lods = tile_lods(o, plan);
    std::vector<driver::SequenceEntry> entries;
    for (const PlannedBuilding& b : plan.buildings) entries.push_back(sequence_entry(b, lods));
    std::vector<std::optional<driver::PreparedFeature>> prepared;
    {
      driver::FeatureMaker maker(entries);
      const std::string turns = turns_of(o, plan.files, std::thread::hardware_concurrency());
      driver::run_items(
          items, todo, o.jobs, o.fresh_processes, rows, ran, kStage, label,
          [&](std::size_t i) {
            if (rows[i].ok()) maker.add(i);
          },
          turns);
      prepared = maker.take();
    }
    failures += finish_tile_prepared(o, plan, rows, std::move(entries), std::move(prepared));
    buildings += todo.size();
    held -= plan.buildings.size();
    done.push_back(without_buildings(std::move(plan)));
    release_free_memory();  // the sequence's threads' leftovers go before the next tile's plan
    if (tiles.size() > 1) log::info(survey_progress_line(done.size(), tiles.size(), files.tile, buildings, log::now_seconds() - t0));
  }
  if (stats) stats->footprint_reads = footprints.reads();
  require_footprints_on_tiles(o, done);
  return failures ? 1 : 0;
}

CLI::App* add_city_command(CLI::App& app, CityOptions& o) {
  auto* c = app.add_subcommand("city", "A survey tile in, a city out: one building-mode model per building, as CityJSONSeq");
  c->add_option("TILES", o.tiles, "Tiles: LAS/LAZ (or any point file), classified or not")->required();
  c->add_option("-o,--output", o.output, "OUT.city.jsonl (one tile) or a folder (TILE.city.jsonl each); "
                                          "beside them .summary.csv and the .work folder")
      ->required();
  c->add_option("--footprints", o.footprints, "Building footprints (GeoPackage, Shapefile, GeoJSON, ... through GDAL); "
                                              "default: connected groups of building points");
  c->add_option("--footprint-layer", o.footprint_layer, "Layer of the footprint file (default: the first)");
  c->add_option("--id-field", o.id_field, "Field of the footprints holding the building ids (default: the FID)");
  c->add_option_function<std::string>("--classes", [&o](const std::string& v) { o.params.classes = parse_class_source(v); },
                                      "auto (ground = class 2, buildings = class 6 where the tile has such points, else "
                                      "SMRF / the building rule) | file (the same; an error without class 2 or 6) | filter "
                                      "(SMRF and the rule whatever the file says)")
      ->check(CLI::IsMember({"auto", "file", "filter"}));
  c->add_option("--crs", o.crs, "EPSG:N of the points (and of the sequence) when the tile does not say, or to override it");
  c->add_option("-j,--jobs", o.jobs, "Buildings reconstructed at once; 0: one per hardware thread")->capture_default_str();
  c->add_flag("--resume", o.resume, "Reuse the plan of an earlier run and skip buildings already done");
  c->add_flag("--fresh-processes", o.fresh_processes,
                 "Each building in a process of its own, not one worker per job running its buildings in turn "
                 "(the same files; slower)");
  c->add_flag("--one-at-a-time", o.one_at_a_time,
              "Each job's buildings one after another, not the next's first runs beside the last's step 7 and writing "
              "(the same files; slower)");
  c->add_option("--lod", o.lod, "LoDs of each feature: 1.2 (the plan extruded to the roof's 70th percentile), 1.3 "
                                "(each roof part to its own), 2.2 (the building-mode model), comma-separated")
      ->capture_default_str();
  c->add_option("--cityjson-scale", o.cityjson_scale, "Size of one integer coordinate step (1 mm)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  c->add_option("--buffer", o.params.buffer, "Footprints: points this close outside a footprint belong to it, m")->capture_default_str();
  c->add_option("--ring-inner", o.params.ring_inner, "Ground ring: from this distance around the footprint, m")->capture_default_str();
  c->add_option("--ring-outer", o.params.ring_outer, "Ground ring: to this distance (doubled while too few ground points), m")
      ->capture_default_str();
  c->add_option("--min-points", o.params.min_building_points,
                "A footprint with fewer building points is its footprint prism; a smaller group is no building")
      ->capture_default_str();
  c->add_option("--min-prism-points", o.params.min_prism_points,
                "A footprint with fewer building points gets no model (listed as no-points, not a failure)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  c->add_option("--tile-margin", o.params.tile_margin,
                "Several tiles: each is planned with its neighbours' points this far around it (buildings across edges), m")
      ->capture_default_str();
  c->add_option("--block", o.block,
                "A larger tile with footprints and classes is planned in blocks of about this side (the same plan in "
                "less memory), m; 0: whole")
      ->capture_default_str();
  c->add_option("--min-area", o.params.min_building_area, "No footprints: smaller groups are not buildings, m²")->capture_default_str();
  c->add_option("--component-cell", o.params.component_cell, "No footprints: cell of the plan grid of building points, m")
      ->capture_default_str();
  c->add_option("--min-height", o.params.min_height_above_ground, "No classes: building points rise this far above the ground, m")
      ->capture_default_str();
  c->add_option("--max-group-variation", o.params.max_group_variation,
                "No classes, no footprints: a group whose points' median surface variation is above this is vegetation "
                "(listed as not-a-building)")
      ->capture_default_str();
  c->add_option("--smrf-cell", o.params.smrf.cell, "No classes: SMRF cell, m")->capture_default_str();
  c->add_option("--smrf-slope", o.params.smrf.slope, "No classes: SMRF slope threshold (rise over run)")->capture_default_str();
  c->add_option("--smrf-window", o.params.smrf.max_window, "No classes: SMRF largest window radius, m")->capture_default_str();
  c->add_option("--smrf-threshold", o.params.smrf.elevation_threshold, "No classes: SMRF elevation threshold, m")
      ->capture_default_str();
  c->add_option("--hsr", o.hsr_cli, "Program run as `PROGRAM reconstruct ...` per building (default: this hsr)");
  driver::add_forwarded_options(*c, kStage, o.reconstruct_args);
  c->footer("Any other reconstruct option goes after --, e.g.\n  hsr city tile.las -o tile.city.jsonl -- --wall-weight 0.5");
  return c;
}

// ------------------------------------------------------------------------------------------ JSON forms

nlohmann::json to_json(const CityOptions& o) {
  nlohmann::json j = driver::to_json(static_cast<const driver::RunOptions&>(o));
  j["tiles"] = o.tiles;
  j["output"] = o.output;
  j["footprints"] = o.footprints;
  j["footprint_layer"] = o.footprint_layer;
  j["id_field"] = o.id_field;
  j["lod"] = o.lod;
  j["block"] = o.block;
  to_json(j["params"], o.params);
  return j;
}

CityOptions options_from_json(const nlohmann::json& j) {
  CityOptions o;
  driver::read_run_options(j, o);
  o.tiles = expand_tile_folders(j.value("tiles", o.tiles));
  o.output = j.value("output", o.output);
  o.footprints = j.value("footprints", o.footprints);
  o.footprint_layer = j.value("footprint_layer", o.footprint_layer);
  o.id_field = j.value("id_field", o.id_field);
  o.lod = j.value("lod", o.lod);
  o.block = j.value("block", o.block);
  if (j.contains("params")) from_json(j["params"], o.params);
  return o;
}

nlohmann::json to_json(const TileFiles& f) {
  return {{"tile", f.tile}, {"sequence", f.sequence}, {"summary", f.summary}, {"work", f.work}};
}

TileFiles files_from_json(const nlohmann::json& j) {
  return {j.at("tile").get<std::string>(), j.at("sequence").get<std::string>(), j.at("summary").get<std::string>(),
          j.at("work").get<std::string>()};
}

nlohmann::json to_json(const TilePlan& p) {
  nlohmann::json buildings = nlohmann::json::array();
  for (const PlannedBuilding& b : p.buildings)
    buildings.push_back({{"id", b.id}, {"name", b.name}, {"points", b.points}, {"area", b.area},
                         {"ground_z", std::isnan(b.ground_z) ? nlohmann::json(nullptr) : nlohmann::json(b.ground_z)},
                         {"ground_points", b.ground_points}, {"ground_source", b.ground_source}, {"attributes", b.attributes},
                         {"failure", b.failure}, {"not_building", b.not_building}, {"footprint_prism", b.footprint_prism},
                         {"no_points", b.no_points}, {"item", driver::to_json(b.item)}});
  return {{"files", to_json(p.files)}, {"crs", p.crs}, {"classes", p.classes}, {"buildings_from", p.buildings_from},
          {"crs_note", p.crs_note}, {"crs_compared", p.crs_compared}, {"unused_building_points", p.unused_building_points},
          {"footprints_on_tile", p.footprints_on_tile}, {"footprints_off_tile", p.footprints_off_tile}, {"buildings", buildings}};
}

TilePlan plan_from_json(const nlohmann::json& j) {
  TilePlan p;
  p.files = files_from_json(j.at("files"));
  p.crs = j.value("crs", "");
  p.classes = j.value("classes", "");
  p.buildings_from = j.value("buildings_from", "");
  p.crs_note = j.value("crs_note", "");
  p.unused_building_points = j.value("unused_building_points", std::size_t(0));
  p.crs_compared = j.value("crs_compared", false);
  p.footprints_on_tile = j.value("footprints_on_tile", std::size_t(0));
  p.footprints_off_tile = j.value("footprints_off_tile", std::size_t(0));
  for (const auto& b : j.at("buildings")) {
    PlannedBuilding pb;
    pb.id = b.at("id").get<std::string>();
    pb.name = b.at("name").get<std::string>();
    pb.points = b.value("points", std::size_t(0));
    pb.area = b.value("area", 0.0);
    pb.ground_z = b.contains("ground_z") && b["ground_z"].is_number() ? b["ground_z"].get<double>() : kNaN;
    pb.ground_points = b.value("ground_points", std::size_t(0));
    pb.ground_source = b.value("ground_source", "");
    pb.attributes = b.value("attributes", nlohmann::json::object());
    pb.failure = b.value("failure", "");
    pb.not_building = b.value("not_building", "");
    pb.footprint_prism = b.value("footprint_prism", false);
    pb.no_points = b.value("no_points", "");
    pb.item = driver::item_from_json(b.at("item"));
    p.buildings.push_back(std::move(pb));
  }
  return p;
}

}  // namespace hsr::city
