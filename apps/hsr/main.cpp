// hsr — command-line entry point. Subcommands: reconstruct, batch (driver/batch_run.h), city
// (driver/city_run.h), synth, eval, info, render, tiles (tiles3d/tiles3d.h).
// Every failure prints one line "hsr: <stage>: <problem>" on stderr and exits non-zero (exit code per
// hsr::Status, see core/error.h); no partial output file is ever left behind.

#include "core/atomic_file.h"
#include "core/budget.h"
#include "core/error.h"
#include "core/log.h"
#include "core/spacing.h"
#include "city/footprints.h"
#include "driver/batch_run.h"
#include "driver/city_run.h"
#include "driver/launcher.h"
#include "eval/eval.h"
#include "io/cityjson.h"
#include "io/io.h"
#include "io/raster.h"
#include "pipeline/pipeline.h"
#include "report/report.h"
#include "synth/city_synth.h"
#include "tiles3d/tiles3d.h"
#include "synth/synth.h"

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

namespace {

using namespace hsr;

std::string format_vec(const Vec3& v) {
  char buf[128];
  std::snprintf(buf, sizeof buf, "%.6g %.6g %.6g", v.x(), v.y(), v.z());
  return buf;
}

/// "x,y,z;x,y,z" → positions.
std::vector<Vec3> parse_positions(const std::string& text) {
  std::vector<Vec3> out;
  std::stringstream all(text);
  std::string item;
  while (std::getline(all, item, ';')) {
    if (item.empty()) continue;
    std::stringstream one(item);
    std::string c;
    std::vector<double> xyz;
    while (std::getline(one, c, ',')) xyz.push_back(std::stod(c));
    if (xyz.size() != 3)
      throw Error(Status::BadInput, "cli", "scanner position '" + item + "' is not x,y,z");
    out.emplace_back(xyz[0], xyz[1], xyz[2]);
  }
  return out;
}

PlaneDetector parse_detector(const std::string& name) {
  if (name == "region-growing") return PlaneDetector::RegionGrowing;
  if (name == "ransac") return PlaneDetector::Ransac;
  throw Error(Status::BadInput, "cli", "unknown plane detector '" + name + "' (region-growing | ransac)");
}

void write_json_atomic(const std::string& path, const nlohmann::json& j) {
  AtomicFile f(path, "report");
  f.stream() << j.dump(2) << '\n';
  f.commit();
}

/// --config: a run report's parameters (parameters.<stage>) as the defaults of this run, its --sample, its
/// scanner positions (local in the report, back in file coordinates here). Its ground_z stays local (the
/// caller does not shift it again, unless --ground-z is given beside it): adding and subtracting the origin
/// need not give the same double back.
void load_run_config(const std::string& path, PipelineParams& pp, std::string& partition, std::string& detector,
                     std::string& scene, std::size_t& sample, std::string& scanners) {
  std::ifstream in(path);
  if (!in) throw Error(Status::BadInput, "config", "cannot read " + path);
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, /*allow_exceptions=*/false);
  if (report.is_discarded() || !report.is_object() || !report.contains("parameters"))
    throw Error(Status::BadInput, "config", path + " is not a run report (no \"parameters\")");
  stage_params_from_json(report["parameters"], pp);
  partition = partitioner_name(pp.partition.method);
  detector = pp.structure.detector == PlaneDetector::Ransac ? "ransac" : "region-growing";
  scene = scene_mode_name(pp.scene.mode);
  if (report.contains("sample") && report["sample"].is_number_unsigned()) sample = report["sample"].get<std::size_t>();
  Vec3 origin = Vec3::Zero();
  if (report.contains("origin") && report["origin"].is_array() && report["origin"].size() == 3)
    origin = Vec3(report["origin"][0].get<double>(), report["origin"][1].get<double>(), report["origin"][2].get<double>());
  scanners.clear();
  char buf[96];
  for (const Vec3& s : pp.structure.scanners) {
    const Vec3 g = s + origin;
    std::snprintf(buf, sizeof buf, "%.17g,%.17g,%.17g;", g.x(), g.y(), g.z());
    scanners += buf;
  }
}

/// "k: n, k: n, ..." for the values of `v` that occur, in increasing order.
template <class T>
std::string histogram(const std::vector<T>& v) {
  std::map<unsigned, std::size_t> count;
  for (const T x : v) ++count[x];
  std::string out;
  for (const auto& [value, n] : count) out += (out.empty() ? "" : ", ") + std::to_string(value) + ": " + std::to_string(n);
  return out;
}

/// The CRS in one line: "EPSG:N" as is, a WKT by its name (the first quoted string) and length.
std::string crs_line(const std::string& crs) {
  if (crs.empty()) return "none given";
  const std::size_t open = crs.find('"'), close = open == std::string::npos ? open : crs.find('"', open + 1);
  if (crs.rfind("EPSG:", 0) == 0 || close == std::string::npos) return crs.substr(0, 120);
  return crs.substr(open + 1, close - open - 1) + "  (OGC WKT, " + std::to_string(crs.size()) + " characters)";
}

/// The per-point attributes of a survey file (LAS/LAZ/COPC) and its CRS.
void print_attributes(const PointCloud& cloud) {
  const PointAttributes& a = cloud.attributes;
  if (a.empty() && cloud.crs.empty()) return;
  std::string kept;
  const auto add = [&](bool has, const char* name) {
    if (has) kept += (kept.empty() ? "" : ", ") + std::string(name);
  };
  add(!a.classification.empty(), "classification");
  add(!a.return_number.empty(), "return number and count");
  add(!a.intensity.empty(), "intensity");
  add(!a.gps_time.empty(), "GPS time");
  add(!a.rgb.empty(), "RGB");
  std::printf("attributes %s\n", kept.empty() ? "none" : kept.c_str());
  if (!a.classification.empty()) std::printf("classes   %s\n", histogram(a.classification).c_str());
  if (!a.return_number.empty()) std::printf("returns   %s  (points by return number)\n", histogram(a.return_number).c_str());
  if (!a.gps_time.empty()) {
    const auto [lo, hi] = std::minmax_element(a.gps_time.begin(), a.gps_time.end());
    std::printf("gps time  %.17g .. %.17g\n", *lo, *hi);
  }
  std::printf("crs       %s\n", crs_line(cloud.crs).c_str());
}

int cmd_info(const std::string& path, std::size_t sample) {
  ReadParams rp;
  rp.sample_count = sample;
  const PointCloud cloud = read_points(path, rp);
  const BBox box = bounding_box(cloud.points);
  std::printf("file      %s\n", path.c_str());
  std::printf("points    %zu\n", cloud.size());
  std::printf("normals   %s\n", cloud.has_normals() ? "yes" : "no");
  std::printf("bbox min  %s\n", format_vec(box.min + cloud.origin).c_str());
  std::printf("bbox max  %s\n", format_vec(box.max + cloud.origin).c_str());
  std::printf("size      %s  (diagonal %.6g)\n", format_vec(box.size()).c_str(), box.diagonal());
  if (cloud.origin != Vec3::Zero())
    std::printf("origin    %s  (shifted to a local origin; writers shift back)\n", format_vec(cloud.origin).c_str());
  std::printf("spacing   %.6g  (mean distance to the 6 nearest neighbours)\n", average_spacing(cloud.points));
  print_attributes(cloud);
  return 0;
}

int cmd_synth(const std::string& model, const std::string& out_dir, const SynthParams& params) {
  const SynthScan scan = run_synth(model, params);
  write_synth(scan, out_dir);
  log::info("synth: " + model + ": " + std::to_string(scan.cloud.size()) + " points, " +
            std::to_string(scan.planes.size()) + " planes, " + std::to_string(scan.scanners.size()) +
            " scanner positions → " + out_dir + "/{points.ply,truth.obj,planes.json}");
  return 0;
}

/// `hsr tiles`: CityJSON sequences to 3D Tiles and a viewer (tiles3d/tiles3d.h); --png: its screenshot.
int cmd_tiles(const std::vector<std::string>& inputs, const std::string& out, const Tiles3dParams& params, const std::string& png) {
  const Tiles3dSummary s = write_3d_tiles(inputs, out, params);
  log::info("tiles: " + std::to_string(s.buildings) + " buildings, " + std::to_string(s.triangles) + " triangles in " +
            std::to_string(s.contents) + " glTF contents -> " + out + "/tileset.json (" +
            (s.earth_fixed ? "placed on the earth from " + s.crs : std::string("in the sequences' own frame")) +
            "); view: python3 -m http.server -d " + out + ", then http://localhost:8000/");
  if (!png.empty()) {
    RenderParams rp;
    rp.allow_file_access = true;
    render_png((std::filesystem::path(out) / "index.html").string(), png, rp);
    log::info("tiles: " + png);
  }
  return 0;
}

/// `hsr synth city`: a survey tile (synth/city_synth.h).
int cmd_synth_city(const std::string& out_dir, const SynthCityParams& params) {
  if (params.survey_size > 0) {  // a survey: written tile by tile, never held whole
    SynthSurvey survey = plan_synth_survey(params);
    const std::size_t points = write_synth_survey(survey, out_dir);
    log::info("synth: city: " + std::to_string(survey.buildings.size()) + " buildings, " + std::to_string(points) + " points in " +
              std::to_string(survey.tiles_per_side * survey.tiles_per_side) + " tiles -> " + out_dir +
              "/{tiles/,footprints.geojson,truth.json,truth/}");
    return 0;
  }
  const SynthCity city = run_synth_city(params);
  write_synth_city(city, out_dir);
  log::info("synth: city: " + std::to_string(city.buildings.size()) + " buildings, " + std::to_string(city.cloud.size()) +
            " points -> " + out_dir + "/{tile.las,tile_unclassified.las,footprints.geojson,truth.json,truth/}");
  return 0;
}

/// --footprint FILE: every polygon of every feature, in the cloud's local frame.
Footprint read_footprint_option(const std::string& path, const PointCloud& cloud) {
  FootprintReadParams rp;
  rp.points_crs = cloud.crs;
  const FootprintSet set = read_footprints(path, rp);
  Footprint out;
  for (const FootprintFeature& f : set.features)
    for (FootprintPolygon p : f.footprint) {
      for (Vec2& q : p.outer) q -= cloud.origin.head<2>();
      for (auto& h : p.holes)
        for (Vec2& q : h) q -= cloud.origin.head<2>();
      out.push_back(std::move(p));
    }
  if (out.empty()) throw Error(Status::BadInput, "city", "--footprint " + path + " holds no polygon");
  check_footprint(out);
  return out;
}

int cmd_eval(const std::string& points_path, const std::string& mesh_path, const std::string& truth_path,
             bool as_json, const EvalParams& params) {
  const PointCloud cloud = read_points(points_path);
  PolygonMesh mesh = read_mesh(mesh_path);
  // Meshes are read in their file's coordinates; bring them into the cloud's local frame.
  for (auto& v : mesh.vertices) v += mesh.origin - cloud.origin;
  mesh.origin = cloud.origin;
  PolygonMesh truth;
  if (!truth_path.empty()) {
    truth = read_mesh(truth_path);
    for (auto& v : truth.vertices) v += truth.origin - cloud.origin;
    truth.origin = cloud.origin;
  }
  const EvalResult r = run_eval(cloud, mesh, truth_path.empty() ? nullptr : &truth, params);
  if (as_json)
    std::cout << to_json(r).dump(2) << '\n';
  else
    std::cout << summary(r) << '\n';
  return 0;
}

/// Every building of a CityJSON file or sequence as one mesh (their face classes kept), in the first one's frame.
PolygonMesh merged_buildings(const std::string& path) {
  CityModel model = read_cityjson(path);
  if (model.buildings.empty()) throw Error(Status::BadInput, "render", path + " holds no building");
  PolygonMesh all;
  all.origin = model.buildings.front().mesh.origin;
  for (const CityBuilding& b : model.buildings) {
    const auto base = static_cast<std::uint32_t>(all.vertices.size());
    for (const Vec3& v : b.mesh.vertices) all.vertices.push_back(v + b.mesh.origin - all.origin);
    for (auto face : b.mesh.faces) {
      for (auto& v : face) v += base;
      all.faces.push_back(std::move(face));
    }
    all.face_class.insert(all.face_class.end(), b.mesh.face_class.begin(), b.mesh.face_class.end());
  }
  return all;
}

/// `hsr render FILE... -o out.png`: each file is a mesh (drawn with its edges) or points (coloured by their
/// distance to the mesh, or by height); the still page is written to `html_path` (or a temp file) and
/// screenshot by headless Chromium.
int cmd_render(const std::vector<std::string>& files, const std::string& png, const std::string& html_path,
               const RenderParams& rp, std::size_t max_points, ModelView view) {
  const std::string chromium = find_chromium(rp);
  if (chromium.empty() && !png.empty()) render_png("", png, rp);  // throws the "install chromium" error
  PolygonMesh mesh;
  PointCloud cloud;
  bool have_mesh = false, have_cloud = false;
  for (const auto& f : files) {
    const std::string ext = file_extension(f);
    PolygonMesh m;
    if (is_cityjson_path(f) || is_cityjsonseq_path(f)) m = merged_buildings(f);  // every building, with its classes
    else if (ext == "obj" || ext == "off") m = read_mesh(f);
    if (ext == "ply") {  // a PLY holds a mesh or points: a mesh when it has faces
      try {
        m = read_mesh(f);
      } catch (const Error&) {
        m.faces.clear();
      }
    }
    if (!m.faces.empty()) {
      if (have_mesh) throw Error(Status::BadInput, "render", "more than one mesh given: " + f);
      mesh = std::move(m);
      have_mesh = true;
    } else {
      if (have_cloud) throw Error(Status::BadInput, "render", "more than one point file given: " + f);
      cloud = read_points(f);
      have_cloud = true;
    }
  }
  // One frame: the mesh's coordinates are global; bring them to the cloud's local frame (or keep their own).
  if (have_cloud && have_mesh) {
    for (auto& v : mesh.vertices) v += mesh.origin - cloud.origin;
    mesh.origin = cloud.origin;
  }
  ReportParams params;
  params.max_points = max_points;
  params.still_width = rp.width;
  params.still_height = rp.height;
  params.view = view;
  params.scanned_from_inside = have_cloud && normals_face_inward(cloud);  // auto: the cutaway for a room
  const std::string page = html_still(have_mesh ? &mesh : nullptr, have_cloud ? &cloud : nullptr, params);
  namespace fs = std::filesystem;
  const std::string html = html_path.empty() ? (fs::path(png).string() + ".html") : html_path;
  {
    AtomicFile f(html, "render");
    f.stream() << page;
    f.commit();
  }
  if (!png.empty()) render_png(html, png, rp);
  if (html_path.empty()) fs::remove(html);
  log::info("render: wrote " + (png.empty() ? html : png));
  return 0;
}

int cmd_reconstruct(const std::string& input, const std::string& output, std::size_t sample,
                    const std::string& report_path, const std::string& truth_path, const std::string& ground_path,
                    PipelineParams params,
                    const std::string& html_path, const std::string& png_path, CityJsonParams cityjson,
                    bool ground_z_is_local = false, ModelView view = ModelView::Auto,
                    const std::string& footprint_path = "", const std::string& turn_path = "") {
  // hsr city's turn (driver.h Turn, DECISIONS #235): waited for before the budget's clock starts, given up when
  // the building's first run and step 0 are done (or with the run)
  driver::Turn turn(turn_path);
  params.turn_over = [&turn] { turn.give_up(); };
  if (!cityjson.crs.empty()) crs_url(cityjson.crs);  // a bad --crs fails before the run
  // The budget covers reading and every stage; it ends before anything is written, so a run stopped by it
  // (cooperatively or by the watchdog) never leaves an output file.
  std::optional<BudgetScope> budget_scope(std::in_place, params.budget);
  ReadParams rp;
  rp.sample_count = sample;
  std::vector<Vec3> file_scanners;  // E57: one per scan (its pose translation), file coordinates
  const PointCloud cloud = read_points(input, rp, file_scanners);
  check_budget("io");
  // The scanner positions the file records orient the normals and drive visibility, as --scanner would;
  // positions given on the command line win.
  if (params.structure.scanners.empty() && !file_scanners.empty()) {
    params.structure.scanners = file_scanners;
    log::info("reconstruct: " + std::to_string(file_scanners.size()) + " scanner position(s) from the file's scan poses");
  }
  if (!footprint_path.empty()) params.footprint = read_footprint_option(footprint_path, cloud);
  params_to_local(params, cloud.origin, ground_z_is_local);
  PolygonMesh truth;
  if (!truth_path.empty()) {
    truth = read_mesh(truth_path);
    for (auto& v : truth.vertices) v += truth.origin - cloud.origin;
    truth.origin = cloud.origin;
    params.truth = &truth;
  }
  if (!params.dump_dir.empty()) std::filesystem::create_directories(params.dump_dir);
  // Fail before the run, not after it, when a picture is asked for and no browser can take it.
  if (!png_path.empty() && find_chromium().empty()) render_png("", png_path);
  Raster ground_raster;
  if (!ground_path.empty()) {
    ground_raster = read_raster(ground_path);
    params.ground_raster = &ground_raster;
  }
  PipelineArtifacts artifacts;
  if (!html_path.empty()) params.artifacts = &artifacts;
  PipelineResult result = run_pipeline(cloud, params);
  result.report["input"] = input;
  result.report["output"] = output;
  result.report["sample"] = sample;
  budget_scope.reset();
  if (is_cityjson_path(output)) {  // one Building named after the output file, the run's figures as attributes
    cityjson.id = std::filesystem::path(output).filename().string();
    cityjson.id.resize(cityjson.id.size() - std::string(".city.json").size());
    cityjson.attributes = cityjson_attributes(result.report);
    cityjson.require_valid = !params.force;
    cityjson.validate = driver::validity_problem;
    write_cityjson(output, result.mesh, cityjson);
  } else {
    write_mesh(output, result.mesh);
  }
  if (!report_path.empty()) write_json_atomic(report_path, result.report);
  ReportParams view_params;  // the cutaway for a model scanned from inside (auto), or as --view says
  view_params.view = view;
  view_params.scanned_from_inside = result.report.contains("visibility") &&
                                    result.report["visibility"].value("scanned_from_inside", false);
  if (!html_path.empty()) {
    write_html_report(html_path, artifacts, result.mesh, result.report, view_params);
    log::info("reconstruct: wrote the visual report " + html_path);
  }
  if (!png_path.empty()) {  // the output mesh over the input points
    const std::string page = png_path + ".html";
    {
      AtomicFile f(page, "render");
      ReportParams still = view_params;
      still.still_width = RenderParams{}.width;
      still.still_height = RenderParams{}.height;
      f.stream() << html_still(&result.mesh, &cloud, still);
      f.commit();
    }
    render_png(page, png_path);
    std::filesystem::remove(page);
    log::info("reconstruct: wrote " + png_path);
  }
  log::info("reconstruct: wrote " + output + " (" + std::to_string(result.mesh.num_vertices()) +
            " vertices, " + std::to_string(result.mesh.num_faces()) + " faces)");
  std::cout << summary(result.eval) << '\n';
  return 0;
}

/// One command, as main() runs it: parses `argv` and runs the subcommand; returns the exit code.
int run_command(int argc, char** argv) {
  CLI::App app{"hsr — Hierarchical Space Partition for Surface Reconstruction.\n"
               "Turns a point cloud of a man-made scene into a compact, watertight polygon mesh."};
  app.set_version_flag("--version", std::string("hsr ") + HSR_VERSION);
  app.require_subcommand(1);
  app.fallthrough();  // global flags (-q, -v) also accepted after the subcommand
  bool quiet = false, verbose = false;
  app.add_flag("-q,--quiet", quiet, "Print only results and errors");
  app.add_flag("-v,--verbose", verbose, "Print resolved parameters and per-stage details");

  // info
  auto* info = app.add_subcommand("info", "Print what a point file holds: count, bbox, spacing, normals; for LAS/LAZ/COPC the attributes (classes, returns, GPS time) and the CRS");
  std::string info_path;
  std::size_t info_sample = 0;
  info->add_option("FILE", info_path, "Point or mesh file (.ply .xyz .xyzn .pwn .off .obj; LAS/LAZ/COPC by content)")->required();
  info->add_option("--sample", info_sample, "For mesh files: sample N points on the faces instead of using vertices");

  // synth
  auto* synth = app.add_subcommand("synth", "Simulate a LiDAR scan of a procedural model, with ground truth");
  std::string synth_model, synth_out, synth_scanners;
  bool synth_list = false;
  SynthParams synth_params;
  synth->add_option("MODEL", synth_model, "Model name (see --list)");
  synth->add_flag("--list", synth_list, "Print the model names, one per line");
  synth->add_option("-o,--output", synth_out, "Output folder (points.ply, truth.obj, planes.json)");
  synth->add_option("--seed", synth_params.seed, "Random seed")->capture_default_str();
  synth->add_option("--noise", synth_params.noise, "Range noise, fraction of the model's bbox diagonal")
      ->capture_default_str();
  synth->add_option("--points", synth_params.target_points, "Approximate number of points")->capture_default_str();
  synth->add_option("--scanners", synth_scanners, "Scanner positions 'x,y,z;x,y,z' (default: the model's own)");
  double synth_density = 0.0;
  synth->add_option("--density", synth_density,
                    "Points per m²: aerial_* models on roofs (default 10); hall / meeting_room / office on the "
                    "model's surface (default 60 / 400 / 80; replaces --points); other models: replaces --points");
  synth->add_option("--blocks", synth_params.blocks,
                    "hall: furniture blocks (default 120); meeting_room: chairs (default 16)");
  synth->add_option("--planes", synth_params.planes,
                    "hall: add blocks until the truth has about this many planes (replaces --blocks)");
  synth->add_option("--rooms", synth_params.office.rooms, "office: rooms (1-6)")->capture_default_str();
  synth->add_option("--partition", synth_params.office.partition, "office: thickness of the partitions, metres")
      ->capture_default_str();
  synth->add_option("--turned-share", synth_params.office.turned_share,
                    "office: share of the furniture turned by a random angle (the rest along x or y)")
      ->capture_default_str();
  synth->add_option("--angle", synth_params.office.angle_deg,
                    "office: turn every piece but the pillars by this angle, degrees (default: at random)");
  for (auto [flag, count, what] : {std::tuple{"--tables", &synth_params.office.tables, "tables on four legs"},
                                   std::tuple{"--chairs", &synth_params.office.chairs, "chairs on one post"},
                                   std::tuple{"--desks", &synth_params.office.desks, "L-shaped desks"},
                                   std::tuple{"--cabinets", &synth_params.office.cabinets, "cabinets"},
                                   std::tuple{"--shelves", &synth_params.office.shelves, "open shelves"},
                                   std::tuple{"--pillars", &synth_params.office.pillars, "round pillars"}})
    synth->add_option(flag, *count, std::string("office: ") + what + " per room")->capture_default_str();
  synth->add_option("--range-noise", synth_params.aerial_range_noise,
                    "aerial_* models: range noise (standard deviation along the ray), metres")
      ->capture_default_str();
  synth->add_option("--ground", synth_params.aerial_ground,
                    "aerial_* models: ground points around the building: 1 yes, 0 no, -1 by the seed (odd: yes)")
      ->capture_default_str();
  synth->add_option("--trees", synth_params.aerial_trees,
                    "aerial_* models: tree crowns beside the building; -1: 0-2 drawn by the seed (city: one per building)")
      ->capture_default_str();
  SynthCityParams city_params;
  synth->add_option("--buildings", city_params.buildings, "city: buildings on the tile")->capture_default_str();
  synth->add_option("--terraced", city_params.terraced, "city: of them, attached to a neighbour (sharing a wall)")
      ->capture_default_str();
  synth->add_option("--slope", city_params.slope, "city: gradient of the ground (rise over run)")->capture_default_str();
  synth->add_option("--tiles", city_params.tiles, "city: also cut the survey into N x N tiles (DIR/tiles/rRcC.las)")
      ->check(CLI::Range(1, 100))
      ->capture_default_str();
  double survey_km = 0;
  synth->add_option("--size", survey_km,
                    "city: a survey of KM x KM km instead of one tile: plots fill it (replaces --buildings), written tile by "
                    "tile (DIR/tiles/rRcC.las) with one footprint file, never held whole");
  synth->add_option("--tile-size", city_params.tile_size, "city --size: side of its tiles, m")->capture_default_str();
  synth->add_flag("--unclassified", city_params.unclassified_tiles,
                  "city --size: also write each tile without classes (DIR/tiles_unclassified/)");

  // eval
  auto* eval = app.add_subcommand("eval", "Accuracy and validity of a mesh against points (and a true mesh)");
  std::string eval_points, eval_mesh, eval_truth;
  bool eval_json = false;
  EvalParams eval_params;
  eval_params.samples_per_point = 0;  // `hsr eval` is the full evaluation: --samples on every mesh
  eval->add_option("POINTS", eval_points, "Input point file")->required();
  eval->add_option("MESH", eval_mesh, "Mesh to evaluate (.obj .ply .off)")->required();
  eval->add_option("--truth", eval_truth, "True surface mesh: adds symmetric Chamfer and Hausdorff distances");
  eval->add_flag("--json", eval_json, "Print JSON instead of text");
  eval->add_option("--samples", eval_params.mesh_samples, "Samples taken on each mesh")->capture_default_str();

  // reconstruct
  auto* rec = app.add_subcommand("reconstruct", "Reconstruct a watertight polygon mesh from a point cloud");
  std::string rec_input, rec_output, rec_report, rec_truth, rec_partition = "hierarchical", rec_detector = "region-growing";
  std::size_t rec_sample = 0;
  PipelineParams pp;
  rec->add_option("INPUT", rec_input, "Input point file (.ply .xyz .xyzn .pwn .off .las; meshes with --sample)")
      ->required();
  rec->add_option("-o,--output", rec_output, "Output mesh (.obj .ply .off .city.json)")->required();
  std::string rec_scene = "auto";
  rec->add_option("--scene", rec_scene,
                  "Scene prior: building (aerial scan: up is +z, ground, walls recovered down to it) | object | "
                  "auto (building when the data looks like an aerial building scan; the choice is printed)")
      ->capture_default_str();
  rec->add_option("--ground-z", pp.scene.building.ground_z,
                  "building: the ground height (file coordinates); wins over every other source of the ground");
  std::string rec_ground;
  rec->add_option("--ground", rec_ground,
                  "building: a terrain raster (GeoTIFF or any raster GDAL reads, file coordinates): the ground is "
                  "its median height under the building");
  rec->add_flag("--trust-ground-z", pp.scene.building.given_ground_wins,
                "building: --ground-z is the ground and no plane at the bottom of the points is taken for ground "
                "(hsr city sets it: its buildings' points hold no ground)");
  rec->add_option("--wall-weight", pp.extraction.wall_area_weight,
                  "building: weight of the area term on wall faces (walls are often not scanned)")
      ->capture_default_str();
  rec->add_option("--partition", rec_partition, "Space partition: exhaustive | bsp | kinetic | hierarchical")
      ->capture_default_str();
  rec->add_option("--k", pp.partition.kinetic_k, "kinetic: a polygon stops at its k-th collision")->capture_default_str();
  rec->add_option("--max-per-domain", pp.partition.max_polygons_per_domain,
                  "kinetic/hierarchical: a domain with more polygons is split into sub-domains")
      ->capture_default_str();
  rec->add_option("--max-crossings", pp.partition.max_crossings,
                  "hierarchical: safety budget, distinct same-level planes a polygon may cross")
      ->capture_default_str();
  rec->add_option("--bbox-margin", pp.partition.bbox_margin,
                  "Partition box = points' bbox enlarged by this fraction of its diagonal on each side")
      ->capture_default_str();
  std::string rec_detail = detail_name(Detail::Medium);
  rec->add_option("--support-points", pp.extraction.support_points,
                  "Clean-up: never remove a part whose removal moves at least N points more than 2 r (0: off)")
      ->capture_default_str();
  rec->add_option("--detail", rec_detail,
                  "Detail / size trade-off: full (the min-cut's faces) | high | medium | low (fewest faces); "
                  "sets --face-price and --lambda (README \"Detail and face count\"); a scene scanned from inside "
                  "(a room) gets full unless this, --face-price or --lambda is given")
      ->check(CLI::IsMember({"full", "high", "medium", "low"}))
      ->capture_default_str();
  double rec_lambda = -1.0, rec_face_price = -1.0;
  rec->add_option("--lambda", rec_lambda, "Weight of the area term in the min-cut energy (default: by --detail)");
  rec->add_option("--face-price", rec_face_price,
                  "Label clean-up: largest mean surface displacement (fraction of the bbox diagonal) paid to "
                  "remove one face; 0: none (default: by --detail)")
      ->check(CLI::NonNegativeNumber);
  rec->add_option("--smoothness", pp.visibility.smoothness, "w: visibility MRF smoothness weight (paper §3.2)")
      ->capture_default_str();
  rec->add_option("--recovery-angle", pp.recovery.angle_deg, "r_a: missing-plane recovery angle, degrees (§3.3)")
      ->capture_default_str();
  rec->add_option("--recovery-distance", pp.recovery.distance, "r_d: missing-plane recovery distance, in r (§3.3)")
      ->capture_default_str();
  rec->add_option("--alpha-radius", pp.structure.alpha_radius,
                  "Alpha-shape radius of plane boundaries (and of visibility's occluders), in r")
      ->capture_default_str();
  rec->add_option("--detector", rec_detector, "Plane detector: region-growing | ransac")->capture_default_str();
  rec->add_option("--max-distance", pp.structure.max_distance, "Plane inlier distance, in average spacings r")
      ->capture_default_str();
  rec->add_option("--max-angle", pp.structure.max_angle_deg, "Plane inlier normal deviation, degrees")
      ->capture_default_str();
  rec->add_option("--min-plane-points", pp.structure.min_region_points,
                  "Smallest plane, in points (also at least min_region_fraction, 0.3 %, of the points); a room: "
                  "region_k + 1 = 13 points unless given")
      ->capture_default_str();
  rec->add_option("--min-plane-width", pp.structure.min_region_width,
                  "Smallest plane's width across its narrow direction, in average spacings r; 0: no width test")
      ->capture_default_str();
  rec->add_option("--min-plane-share", pp.structure.min_region_fraction,
                  "Smallest plane, as a share of all points (0: none); a scene scanned from inside (a room) is "
                  "detected again with none unless this is given")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  rec->add_flag("--distinct-points", pp.structure.min_region_distinct,
                "The smallest plane counts its inliers at distinct positions (duplicated points once)");
  rec->add_flag("!--keep-coincident-planes", pp.structure.share_coincident_planes,
                "Keep each plane's own fit where fits coincide up to rounding (by default they share one exact "
                "equation: CAD clouds)");
  rec->add_flag("--regularize", pp.structure.regularize, "Snap near-parallel planes and merge near-coplanar ones");
  std::string rec_scanners;
  rec->add_option("--scanner", rec_scanners,
                  "Scanner position(s) 'x,y,z;...' (file coordinates): orients estimated normals towards them");
  rec->add_option("--report", rec_report, "Write a JSON run report (parameters, timings, counts, accuracy)");
  std::string rec_config;
  rec->add_option("--config", rec_config,
                  "Replay a run: every parameter from its --report file; flags given beside it override")
      ->check(CLI::ExistingFile);
  rec->add_option("--dump", pp.dump_dir, "Write per-stage files for inspection into this folder");
  rec->add_option("--truth", rec_truth, "True mesh, to add the distance to the truth to the report");
  rec->add_option("--sample", rec_sample, "For mesh inputs: sample N points with face normals");
  rec->add_option("--seed", pp.structure.seed, "Random seed for every randomised step")->capture_default_str();
  rec->add_option("--threads", pp.threads,
                  "Threads of the run; 0: the environment variable HSR_THREADS if set, else every core (the output "
                  "does not depend on it; hsr city gives each building cores / --jobs)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  rec->add_flag_callback("--no-recovery", [&pp] { pp.hulls.recovered_planes = false; },
                         "Do not add recovered (missing) planes to the partition (the paper's ablation)");
  rec->add_flag("--force", pp.force, "Write the mesh even if it fails the validity checks (flagged)");
  rec->add_option("--max-seconds", pp.budget.max_seconds,
                  "Stop (exit code of BudgetExceeded, no output) after this many seconds; 0: no limit")
      ->check(CLI::NonNegativeNumber);
  pp.budget.max_memory_mb = default_memory_budget_mb();
  rec->add_option("--max-memory", pp.budget.max_memory_mb,
                  "Stop (exit code of BudgetExceeded, no output) above this resident memory, MB; 0: no limit. "
                  "Default: 75 % of the physical memory")
      ->check(CLI::NonNegativeNumber);
  pp.budget.hard_stop = true;  // a watchdog ends the run if a long step does not reach a budget check in time
  CityJsonParams rec_cityjson;
  rec->add_option("--cityjson-scale", rec_cityjson.scale, ".city.json: size of one integer coordinate step (1 mm)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  rec->add_option("--crs", rec_cityjson.crs, ".city.json: reference system EPSG:NNNN (metadata.referenceSystem)");
  std::string rec_footprint;
  rec->add_option("--footprint", rec_footprint,
                  "building: footprint file (any GDAL vector format; all its polygons): the solid stays inside its prism")
      ->check(CLI::ExistingFile);
  rec->add_flag("--footprint-prism", pp.footprint_prism,
                "building, with --footprint of one polygon: no plane detection, the model is the footprint extruded from "
                "the ground to the 0.7 quantile of the points' heights (hsr city: a footprint with too few points)")
      ->needs("--footprint");
  std::string rec_turn;
  rec->add_option("--turn", rec_turn,
                  "hsr city's own: a lock file held from the start until the building's first run is done, so that "
                  "its later runs go beside the next building's first (DECISIONS #235, #249)")
      ->group("");
  std::string rec_html, rec_png;
  rec->add_option("--html", rec_html, "Write a self-contained HTML page with a 3D view of every stage");
  rec->add_option("--png", rec_png, "Render the output mesh over the points to a PNG (headless Chromium)");
  std::string rec_view = "auto";
  rec->add_option("--view", rec_view,
                  "--html/--png: auto (cutaway for a scene scanned from inside) | outside | cutaway (from above, "
                  "the top cut away, the mesh's inner side)")
      ->check(CLI::IsMember({"auto", "outside", "cutaway"}))
      ->capture_default_str();

  // render
  auto* render = app.add_subcommand("render", "Render a mesh and/or points to a PNG with headless Chromium");
  std::vector<std::string> render_files;
  std::string render_png_path, render_html;
  std::size_t render_max_points = 200000;
  RenderParams render_params;
  render->add_option("FILES", render_files,
                     "A mesh (.obj .ply .off; .city.json or .city.jsonl: all its buildings) and/or a point file, drawn together")
      ->required();
  render->add_option("-o,--output", render_png_path, "Output PNG");
  render->add_option("--html", render_html, "Also keep the page that was rendered (self-contained HTML)");
  render->add_option("--width", render_params.width, "Image width, pixels")->capture_default_str();
  render->add_option("--height", render_params.height, "Image height, pixels")->capture_default_str();
  render->add_option("--max-points", render_max_points, "Points drawn at most (evenly subsampled)")
      ->capture_default_str();
  std::string render_view = "auto";
  render->add_option("--view", render_view,
                     "auto (cutaway when the points' normals show a scan from inside) | outside | cutaway (from "
                     "above, the top cut away, the mesh's inner side)")
      ->check(CLI::IsMember({"auto", "outside", "cutaway"}))
      ->capture_default_str();

  // tiles
  auto* tiles = app.add_subcommand("tiles", "A city for the browser: CityJSONSeq (hsr city's output) to 3D Tiles 1.1 and a viewer page");
  std::vector<std::string> tiles_inputs;
  std::string tiles_out, tiles_png;
  Tiles3dParams tiles_params;
  bool tiles_local = false;
  tiles->add_option("SEQUENCES", tiles_inputs, "CityJSON sequences (.city.jsonl) or files (.city.json)")->required();
  tiles->add_option("-o,--output", tiles_out, "Output folder: tileset.json, NAME.glb per sequence, index.html")->required();
  tiles->add_option("--crs", tiles_params.crs, "EPSG:N of the sequences when they name none (or to override)");
  tiles->add_flag("--local", tiles_local, "Keep the sequences' own frame (no placement on the earth)");
  tiles->add_option("--png", tiles_png, "Also a screenshot of the viewer (headless Chromium)");

  batch::BatchOptions batch_options;
  auto* batch_cmd = batch::add_batch_command(app, batch_options);
  city::CityOptions city_options;
  auto* city_cmd = city::add_city_command(app, city_options);

  try {
    app.parse(std::min(driver::take_forwarded_args(argc, argv, "batch", batch_options.reconstruct_args),
                       driver::take_forwarded_args(argc, argv, "city", city_options.reconstruct_args)),
              argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  log::set_level(quiet ? log::Level::Quiet : verbose ? log::Level::Verbose : log::Level::Info);

  try {
    if (*info) return cmd_info(info_path, info_sample);
    if (*synth) {
      if (synth_list) {
        for (const auto& name : synth_model_names()) std::cout << name << '\n';
        for (const auto& name : synth_aerial_model_names()) std::cout << name << '\n';
        for (const auto& name : synth_indoor_model_names()) std::cout << name << '\n';
        std::cout << "city\n";
        return 0;
      }
      if (synth->count("--density")) {
        const auto aerial = synth_aerial_model_names();
        const bool aerial_like = synth_model == "city" ||
                                 std::find(aerial.begin(), aerial.end(), synth_model) != aerial.end();
        (aerial_like ? synth_params.aerial_density : synth_params.density) = synth_density;
      }
      if (synth_model == "city") {
        if (synth_out.empty()) throw Error(Status::BadInput, "synth", "need -o DIR");
        city_params.seed = synth_params.seed;
        city_params.density = synth_params.aerial_density;
        city_params.range_noise = synth_params.aerial_range_noise;
        city_params.trees = synth_params.aerial_trees;
        if (synth->count("--size")) {
          if (synth->count("--buildings") || synth->count("--tiles"))
            throw Error(Status::BadInput, "synth", "city: --size makes a survey whose plots give the buildings and --tile-size its tiles: "
                                                   "drop --buildings and --tiles");
          if (!(survey_km > 0)) throw Error(Status::BadInput, "synth", "city: --size must be a side in km above 0");
          city_params.survey_size = 1000.0 * survey_km;
        } else if (synth->count("--tile-size") || synth->count("--unclassified")) {
          throw Error(Status::BadInput, "synth", "city: --tile-size and --unclassified go with --size (a survey)");
        }
        return cmd_synth_city(synth_out, city_params);
      }
      if (synth_model.empty() || synth_out.empty())
        throw Error(Status::BadInput, "synth", "need MODEL and -o DIR (see hsr synth --list)");
      synth_params.scanners = parse_positions(synth_scanners);
      return cmd_synth(synth_model, synth_out, synth_params);
    }
    if (*eval) return cmd_eval(eval_points, eval_mesh, eval_truth, eval_json, eval_params);
    if (*rec) {
      // --detail sets face_price and λ; a report's parameters (--config) replace them; the flags given
      // beside --config win again (CLI11 re-parses them), --detail only when given.
      apply_detail(parse_detail(rec_detail), pp.extraction);
      if (!rec_config.empty()) {
        load_run_config(rec_config, pp, rec_partition, rec_detector, rec_scene, rec_sample, rec_scanners);
        app.parse(argc, argv);
        if (rec->count("--detail")) apply_detail(parse_detail(rec_detail), pp.extraction);
      }
      if (rec_lambda >= 0) pp.extraction.lambda = rec_lambda;
      if (rec_face_price >= 0) pp.extraction.face_price = rec_face_price;
      // What the user chose: a scene kind's defaults never override it (scene/plan.h). A --config's own
      // choices (parameters.user_choices) stay chosen.
      pp.user.detail = pp.user.detail || rec->count("--detail") || rec_lambda >= 0 || rec_face_price >= 0;
      pp.user.min_plane_share = pp.user.min_plane_share || rec->count("--min-plane-share");
      pp.user.min_plane_points = pp.user.min_plane_points || rec->count("--min-plane-points");
      pp.partition.method = parse_partitioner(rec_partition);
      pp.scene.mode = parse_scene_mode(rec_scene);
      pp.structure.scanners = parse_positions(rec_scanners);  // file coordinates; made local after loading
      pp.structure.detector = parse_detector(rec_detector);
      const bool ground_z_is_local = !rec_config.empty() && rec->count("--ground-z") == 0;  // from the report
      return cmd_reconstruct(rec_input, rec_output, rec_sample, rec_report, rec_truth, rec_ground, pp, rec_html, rec_png,
                             rec_cityjson, ground_z_is_local, parse_model_view(rec_view), rec_footprint,
                             rec_turn);
    }
    if (*batch_cmd) return batch::run_batch(batch_options);
    if (*city_cmd) {
      city_options.tiles = city::expand_tile_folders(city_options.tiles);
      return city::run_city(city_options);
    }
    if (*tiles) {
      tiles_params.earth_fixed = !tiles_local;
      return cmd_tiles(tiles_inputs, tiles_out, tiles_params, tiles_png);
    }
    if (*render) {
      if (render_png_path.empty() && render_html.empty())
        throw Error(Status::BadInput, "render", "need -o OUT.png (or --html PAGE.html)");
      return cmd_render(render_files, render_png_path, render_html, render_params, render_max_points,
                        parse_model_view(render_view));
    }
  } catch (const Error& e) {
    std::cerr << "hsr: " << e.one_line() << '\n';
    return exit_code(e.status());
  } catch (const std::bad_alloc&) {
    std::cerr << "hsr: out of memory (see --max-memory)\n";
    return exit_code(Status::BudgetExceeded);
  } catch (const std::exception& e) {
    std::cerr << "hsr: internal error: " << e.what() << '\n';
    return exit_code(Status::Internal);
  }
  return 0;
}

/// run_command with `args` as its argv.
int run_args(std::vector<std::string> args) {
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  return run_command(static_cast<int>(args.size()), argv.data());
}

}  // namespace

int main(int argc, char** argv) {
  // `hsr batch` and `hsr city` fork their launcher now, before anything runs (driver/launcher.h); a child run
  // it starts returns here, loaded and fresh, with its own arguments, and a worker runs its runs through
  // run_args in turn.
  std::vector<std::string> child_args;
  if (driver::start_launcher(argc, argv, child_args, run_args)) return run_args(child_args);
  return run_command(argc, argv);
}
