// Visual reports: page data (JSON with base64 geometry) and the Chromium still renderer. See report.h.
#include "report/report.h"

#include "core/face_class.h"

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/log.h"
#include "eval/eval.h"
#include "partition/partition.h"

#include <algorithm>
#include <array>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <sys/wait.h>
#include <unistd.h>

// Embedded at build time (embed.cpp): three.min.js, OrbitControls.js and the page template, NUL-terminated.
extern "C" const char hsr_three_js[];
extern "C" const char hsr_orbit_controls_js[];
extern "C" const char hsr_report_template[];

namespace hsr {

namespace {

using Rgb = std::array<std::uint8_t, 3>;

// ---------------------------------------------------------------------------------------------- encoding

std::string base64(const void* data, std::size_t bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  const auto* p = static_cast<const unsigned char*>(data);
  std::string out;
  out.reserve((bytes + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes; i += 3) {
    const unsigned v = (p[i] << 16) | (p[i + 1] << 8) | p[i + 2];
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += table[(v >> 6) & 63];
    out += table[v & 63];
  }
  if (i < bytes) {
    const unsigned v = (p[i] << 16) | (i + 1 < bytes ? p[i + 1] << 8 : 0);
    out += table[v >> 18];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes ? table[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

/// Float32 positions relative to the scene centre (float precision is plenty once centred).
std::string encode_positions(const std::vector<Vec3>& pts, const Vec3& centre) {
  std::vector<float> f;
  f.reserve(pts.size() * 3);
  for (const Vec3& p : pts)
    for (int k = 0; k < 3; ++k) f.push_back(static_cast<float>(p[k] - centre[k]));
  return base64(f.data(), f.size() * sizeof(float));
}

std::string encode_colours(const std::vector<Rgb>& c) { return base64(c.data(), c.size() * 3); }

// ----------------------------------------------------------------------------------------------- colours

Rgb rgb(double r, double g, double b) {
  auto q = [](double x) { return static_cast<std::uint8_t>(std::lround(std::clamp(x, 0.0, 1.0) * 255.0)); };
  return {q(r), q(g), q(b)};
}

/// Distinct colours for ids: golden-ratio hue steps, two saturation/value bands.
Rgb palette(int i) {
  const double h = std::fmod(0.13 + 0.618033988749895 * i, 1.0) * 6.0;
  const double s = (i / 7) % 2 ? 0.55 : 0.75, v = (i / 3) % 2 ? 0.80 : 0.95;
  const int sector = static_cast<int>(h);
  const double f = h - sector, p = v * (1 - s), q = v * (1 - s * f), t = v * (1 - s * (1 - f));
  switch (sector % 6) {
    case 0: return rgb(v, t, p);
    case 1: return rgb(q, v, p);
    case 2: return rgb(p, v, t);
    case 3: return rgb(p, q, v);
    case 4: return rgb(t, p, v);
    default: return rgb(v, p, q);
  }
}

/// Blue (0) → cyan → green → yellow → red (1).
Rgb ramp(double t) {
  static const double stops[5][3] = {{0.19, 0.25, 0.85}, {0.10, 0.75, 0.90}, {0.25, 0.80, 0.30},
                                     {0.98, 0.85, 0.15}, {0.90, 0.15, 0.10}};
  if (!std::isfinite(t)) t = 1.0;
  t = std::clamp(t, 0.0, 1.0) * 4.0;
  const int k = std::min(3, static_cast<int>(t));
  const double f = t - k;
  return rgb(stops[k][0] + f * (stops[k + 1][0] - stops[k][0]), stops[k][1] + f * (stops[k + 1][1] - stops[k][1]),
             stops[k][2] + f * (stops[k + 1][2] - stops[k][2]));
}

std::string hex(const Rgb& c) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c[0], c[1], c[2]);
  return buf;
}

const Rgb kGrey = {190, 190, 190};
const Rgb kLevel1 = {60, 170, 75}, kLevel2 = {240, 150, 40}, kLevel3 = {215, 40, 40};
Rgb level_colour(int level) { return level == 1 ? kLevel1 : level == 2 ? kLevel2 : kLevel3; }

nlohmann::json colourbar(const std::string& label, double lo, double hi) {
  nlohmann::json stops = nlohmann::json::array();
  for (int k = 0; k <= 4; ++k) stops.push_back(hex(ramp(k / 4.0)));
  return {{"label", label}, {"min", lo}, {"max", hi}, {"stops", stops}};
}

nlohmann::json legend_item(const std::string& label, const Rgb& c) { return {{"label", label}, {"color", hex(c)}}; }

// -------------------------------------------------------------------------------------------- geometry

/// A triangle-soup layer: positions (3 per triangle), a colour per triangle corner, and edge segments.
struct Soup {
  std::vector<Vec3> tri;
  std::vector<Rgb> col;
  std::vector<Vec3> edges;

  void add_polygon(const std::vector<Vec3>& loop, const Rgb& c, bool with_edges = true) {
    if (loop.size() < 3) return;
    std::vector<std::array<std::uint32_t, 3>> triangles;
    triangulate_polygon(loop, triangles);  // eval's; a non-simple loop still gives its fan
    for (const auto& t : triangles)
      for (std::uint32_t k : t) {
        tri.push_back(loop[k]);
        col.push_back(c);
      }
    if (with_edges)
      for (std::size_t i = 0; i < loop.size(); ++i) {
        edges.push_back(loop[i]);
        edges.push_back(loop[(i + 1) % loop.size()]);
      }
  }
};

// --------------------------------------------------------------------------------------------- layers

nlohmann::json points_layer(const std::string& name, const std::vector<Rgb>& colours, double size) {
  return {{"type", "points"}, {"name", name}, {"shared", true}, {"col", encode_colours(colours)}, {"size", size}};
}

nlohmann::json soup_layer(const std::string& name, const Soup& s, const Vec3& centre, double opacity,
                          const Rgb& edge_colour = {40, 40, 40}) {
  return {{"type", "mesh"},
          {"name", name},
          {"pos", encode_positions(s.tri, centre)},
          {"col", encode_colours(s.col)},
          {"edges", encode_positions(s.edges, centre)},
          {"edge_color", hex(edge_colour)},
          {"opacity", opacity}};
}

nlohmann::json lines_layer(const std::string& name, const std::vector<Vec3>& segments, const Rgb& c,
                           const Vec3& centre) {
  return {{"type", "lines"}, {"name", name}, {"pos", encode_positions(segments, centre)}, {"color", hex(c)}};
}

std::vector<std::size_t> subsample(std::size_t n, std::size_t max) {
  std::vector<std::size_t> idx;
  if (max == 0 || n <= max) {
    idx.resize(n);
    for (std::size_t i = 0; i < n; ++i) idx[i] = i;
    return idx;
  }
  idx.reserve(max);
  for (std::size_t k = 0; k < max; ++k) idx.push_back(k * n / max);  // evenly strided, deterministic
  return idx;
}

/// Face colours by class (DESIGN.md §4): roofs terracotta, walls light grey, ground dark grey, closure yellow.
constexpr Rgb kRoof{200, 110, 85}, kWall{215, 218, 225}, kGround{120, 120, 125}, kClosure{230, 200, 90};
Rgb class_colour(FaceClass c, const Rgb& unknown) {
  switch (c) {
    case FaceClass::Roof: return kRoof;
    case FaceClass::Wall: return kWall;
    case FaceClass::Ground: return kGround;
    case FaceClass::Closure: return kClosure;
    case FaceClass::Unknown: break;
  }
  return unknown;
}

/// The mesh's faces, each in its class's colour when the mesh knows its classes, else in `c`.
void add_mesh(Soup& soup, const PolygonMesh& mesh, const Rgb& c) {
  std::vector<Vec3> loop;
  const bool classes = mesh.face_class.size() == mesh.faces.size();
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    loop.clear();
    for (auto v : mesh.faces[f]) loop.push_back(mesh.vertices[v]);
    soup.add_polygon(loop, classes ? class_colour(mesh.face_class[f], c) : c);
  }
}

/// A mesh layer of `mesh`; `inner`: the cutaway view may draw it from its inner side only (the mesh is
/// closed and oriented outward: eval's check, without the self-intersection test).
nlohmann::json mesh_layer(const std::string& name, const PolygonMesh& mesh, const Rgb& colour, const Vec3& centre,
                          double opacity, bool cutaway) {
  Soup soup;
  add_mesh(soup, mesh, colour);
  nlohmann::json layer = soup_layer(name, soup, centre, opacity);
  if (cutaway && !mesh.faces.empty()) {
    const Validity v = check_validity(mesh, false);
    layer["inner"] = v.closed && v.oriented && v.volume > 0;
  }
  return layer;
}

std::string fmt(double x, const char* f = "%.3g") {
  char buf[64];
  std::snprintf(buf, sizeof buf, f, x);
  return buf;
}

/// Fills the page template: the data JSON goes into a <script type="application/json"> block, where
/// "</" must not appear (it would end the script element early).
std::string fill_template(const nlohmann::json& data, const std::string& title) {
  std::string json = data.dump();
  std::string safe;
  safe.reserve(json.size());
  for (std::size_t i = 0; i < json.size(); ++i) {
    if (json[i] == '<' ) safe += "\\u003c";
    else safe += json[i];
  }
  std::string esc_title;
  for (char ch : title) {
    if (ch == '<') esc_title += "&lt;";
    else if (ch == '>') esc_title += "&gt;";
    else if (ch == '&') esc_title += "&amp;";
    else esc_title += ch;
  }
  std::string page = hsr_report_template;
  auto put = [&page](const std::string& key, const std::string& value) {
    const std::size_t at = page.find(key);
    HSR_ASSERT(at != std::string::npos, "report template lacks " + key);
    page.replace(at, key.size(), value);
  };
  put("{{TITLE}}", esc_title);
  put("/*{{THREE_JS}}*/", hsr_three_js);
  put("/*{{ORBIT_CONTROLS_JS}}*/", hsr_orbit_controls_js);
  put("{{DATA_JSON}}", safe);
  return page;
}

void require_three_js() {
  if (std::strlen(hsr_three_js) < 1000)
    throw Error(Status::NotImplemented, "report",
                "three.js was not found when hsr was built (install Debian's libjs-three and rebuild)");
}

struct Scene {
  Vec3 centre = Vec3::Zero();
  double radius = 1.0;
};

Scene scene_of(const BBox& box) {
  Scene s;
  if (box.valid()) {
    s.centre = box.center();
    s.radius = std::max(0.5 * box.diagonal(), 1e-9);
  }
  return s;
}

nlohmann::json base_data(const Scene& scene, const std::string& mode, const std::vector<Vec3>& shown_points) {
  return {{"mode", mode},
          {"radius", scene.radius},
          {"centre", {scene.centre.x(), scene.centre.y(), scene.centre.z()}},
          {"points", encode_positions(shown_points, scene.centre)},
          {"views", nlohmann::json::array()}};
}

/// The cutaway's horizontal cut (page coordinates: relative to the scene centre), when the page shows it.
void add_cutaway(nlohmann::json& data, const Scene& scene, const BBox& box, const ReportParams& params) {
  if (!cutaway_view(params) || !box.valid()) return;
  const double top = box.max.z(), height = box.max.z() - box.min.z();
  data["cutaway"] = {{"z", top - std::clamp(params.cut_depth, 0.0, 1.0) * height - scene.centre.z()}};
}

}  // namespace

ModelView parse_model_view(const std::string& name) {
  if (name == "auto") return ModelView::Auto;
  if (name == "outside") return ModelView::Outside;
  if (name == "cutaway") return ModelView::Cutaway;
  throw Error(Status::BadInput, "render", "unknown view '" + name + "' (auto, outside, cutaway)");
}

bool cutaway_view(const ReportParams& params) {
  return params.view == ModelView::Cutaway || (params.view == ModelView::Auto && params.scanned_from_inside);
}

// ------------------------------------------------------------------------------------------ the report

std::string html_report(const PipelineArtifacts& a, const PolygonMesh& mesh, const nlohmann::json& run_report,
                        const ReportParams& given) {
  require_three_js();
  ReportParams params = given;
  params.scanned_from_inside = params.scanned_from_inside || a.visibility.scanned_from_inside;
  const bool cutaway = cutaway_view(params);
  const PointCloud& cloud = a.cloud;
  const SceneStructure& st = a.structure;
  const std::size_t n = cloud.size();
  BBox box = bounding_box(cloud.points);
  for (const Vec3& v : mesh.vertices) box.extend(v);
  const Scene scene = scene_of(box);
  const std::vector<std::size_t> shown = subsample(n, params.max_points);
  std::vector<Vec3> shown_points;
  for (std::size_t i : shown) shown_points.push_back(cloud.points[i]);
  nlohmann::json data = base_data(scene, "report", shown_points);
  add_cutaway(data, scene, box, params);
  const double ps = params.point_size;
  const std::string sample_note = shown.size() < n ? " (" + std::to_string(shown.size()) + " of " +
                                                         std::to_string(n) + " points shown)" : "";
  auto per_point = [&](auto&& colour_of) {
    std::vector<Rgb> c;
    c.reserve(shown.size());
    for (std::size_t i : shown) c.push_back(colour_of(i));
    return c;
  };
  auto plane_of = [&](std::size_t i) { return i < st.point_plane.size() ? st.point_plane[i] : -1; };
  auto& views = data["views"];

  // 1. Input points, coloured by height.
  {
    const BBox cb = bounding_box(cloud.points);
    const double z0 = cb.valid() ? cb.min.z() : 0.0, z1 = cb.valid() ? cb.max.z() : 1.0;
    const double dz = z1 > z0 ? z1 - z0 : 1.0;
    nlohmann::json v = {{"id", "input"}, {"title", "1. Input points"},
                        {"caption", std::to_string(n) + " points" + sample_note + ", coloured by height"},
                        {"layers", {points_layer("points", per_point([&](std::size_t i) {
                                                   return ramp((cloud.points[i].z() - z0) / dz);
                                                 }), ps)}},
                        {"colourbar", colourbar("height (z)", z0 + cloud.origin.z(), z1 + cloud.origin.z())}};
    views.push_back(v);
  }
  // 2. Detected planes.
  {
    std::vector<Vec3> segs;
    for (const auto& p : st.planes)
      for (const auto& s : p.segments) {
        segs.push_back(s.a);
        segs.push_back(s.b);
      }
    std::size_t assigned = 0;
    for (int k : st.point_plane) assigned += k >= 0;
    nlohmann::json v = {{"id", "planes"}, {"title", "2. Detected planes"},
                        {"caption", std::to_string(st.planes.size()) + " planes, " + std::to_string(assigned) +
                                        " inliers (grey: no plane); black: boundary segments; spacing r = " +
                                        fmt(st.spacing)},
                        {"layers", {points_layer("inliers", per_point([&](std::size_t i) {
                                                   const int k = plane_of(i);
                                                   return k < 0 ? kGrey : palette(k);
                                                 }), ps),
                                    lines_layer("boundary segments", segs, {20, 20, 20}, scene.centre)}}};
    views.push_back(v);
  }
  // 3. Visibility ratio.
  {
    const auto& ratio = a.visibility.ratio;
    nlohmann::json v = {{"id", "visibility"}, {"title", "3. Visibility ratio"},
                        {"caption", "inliers coloured by their plane's fraction of visible rays (grey: no plane)"},
                        {"layers", {points_layer("inliers", per_point([&](std::size_t i) {
                                                   const int k = plane_of(i);
                                                   return k < 0 || static_cast<std::size_t>(k) >= ratio.size()
                                                              ? kGrey : ramp(ratio[static_cast<std::size_t>(k)]);
                                                 }), ps)}},
                        {"colourbar", colourbar("visibility ratio", 0.0, 1.0)}};
    views.push_back(v);
  }
  // 4. Levels and recovered planes' support.
  {
    std::vector<bool> support(n, false);
    for (const auto& r : a.recovery.recovered)
      for (int k : r.support)
        if (k >= 0 && static_cast<std::size_t>(k) < n) support[static_cast<std::size_t>(k)] = true;
    const auto& highly = a.visibility.highly;
    const auto nh = std::count(highly.begin(), highly.end(), true);
    nlohmann::json v = {
        {"id", "levels"}, {"title", "4. Levels"},
        {"caption", std::to_string(nh) + " highly / " + std::to_string(highly.size() - static_cast<std::size_t>(nh)) +
                        " barely visible planes, " + std::to_string(a.recovery.recovered.size()) +
                        " recovered planes (their supporting points in red)"},
        {"layers", {points_layer("inliers", per_point([&](std::size_t i) {
                                   if (support[i]) return kLevel3;
                                   const int k = plane_of(i);
                                   if (k < 0 || static_cast<std::size_t>(k) >= highly.size()) return kGrey;
                                   return highly[static_cast<std::size_t>(k)] ? kLevel1 : kLevel2;
                                 }), ps)}},
        {"legend", {legend_item("level 1: highly visible", kLevel1), legend_item("level 2: barely visible", kLevel2),
                    legend_item("level 3: recovered", kLevel3), legend_item("no plane", kGrey)}}};
    views.push_back(v);
  }
  // 5. The polygons handed to the partition (expanded hulls, recovered planes).
  {
    Soup soup;
    int counts[4] = {0, 0, 0, 0};
    for (const auto& p : a.polygons) {
      soup.add_polygon(p.vertices, level_colour(p.level));
      ++counts[std::clamp(p.level, 1, 3)];
    }
    nlohmann::json v = {
        {"id", "polygons"}, {"title", "5. Hulls and recovered planes"},
        {"caption", std::to_string(a.polygons.size()) + " convex polygons: " + std::to_string(counts[1]) +
                        " level 1, " + std::to_string(counts[2]) + " level 2, " + std::to_string(counts[3]) +
                        " recovered"},
        {"layers", {soup_layer("polygons", soup, scene.centre, 0.55),
                    points_layer("points", std::vector<Rgb>(shown.size(), Rgb{150, 150, 150}), 1.0)}},
        {"legend", {legend_item("level 1", kLevel1), legend_item("level 2", kLevel2),
                    legend_item("level 3 (recovered)", kLevel3)}}};
    v["layers"][1]["visible"] = false;
    views.push_back(v);
  }
  // 6. The partition, cells exploded away from the box centre: inside cells solid, outside cells as edges.
  {
    const CellComplex& cx = a.complex;
    const Vec3 c0 = cx.box.valid() ? cx.box.center() : scene.centre;
    Soup inside, outside;
    std::size_t n_inside = 0;
    std::vector<Vec3> loop;
    for (std::size_t c = 0; c < cx.cells.size(); ++c) {
      const bool in = c < a.inside.size() && a.inside[c];
      n_inside += in;
      const Vec3 shift = params.explode * (cx.cells[c].centroid - c0);
      const Rgb colour = in ? palette(static_cast<int>(c)) : Rgb{200, 200, 200};
      for (auto fi : cx.cells[c].facets) {
        loop.clear();
        for (auto vi : cx.facets[fi].vertices) loop.push_back(cx.vertices_approx[vi] + shift);
        if (in) inside.add_polygon(loop, colour);
        else
          for (std::size_t i = 0; i < loop.size(); ++i) {
            outside.edges.push_back(loop[i]);
            outside.edges.push_back(loop[(i + 1) % loop.size()]);
          }
      }
    }
    nlohmann::json v = {
        {"id", "partition"}, {"title", "6. Partition (exploded)"},
        {"caption", std::to_string(cx.cells.size()) + " cells, " + std::to_string(cx.facets.size()) + " facets; " +
                        std::to_string(n_inside) + " cells labelled inside (coloured), the others as grey edges"},
        {"layers", {soup_layer("inside cells", inside, scene.centre, 1.0),
                    lines_layer("outside cells", outside.edges, {175, 175, 175}, scene.centre)}}};
    // Exploding moves cells by up to `explode` times the half box: widen the framing accordingly.
    v["radius_scale"] = 1.0 + params.explode;
    v["cut"] = false;  // the cells are moved: a horizontal cut would not be the model's
    views.push_back(v);
  }
  // 7. Output mesh over the points coloured by their distance to it.
  {
    const std::vector<double> d = point_mesh_distances(shown_points, mesh);
    std::vector<double> sorted(d);
    std::sort(sorted.begin(), sorted.end());
    // Colour scale up to the 99th percentile, so one outlier does not wash out the rest.
    double top = sorted.empty() ? 1.0 : sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
    if (!(top > 0) || !std::isfinite(top)) top = std::max(st.spacing, 1e-12);
    std::vector<Rgb> c;
    for (double x : d) c.push_back(ramp(x / top));
    nlohmann::json v = {
        {"id", "mesh"}, {"title", "7. Output mesh"},
        {"caption", std::to_string(mesh.num_vertices()) + " vertices, " + std::to_string(mesh.num_faces()) +
                        " faces; points coloured by distance to the mesh" +
                        (run_report.contains("scene") ? "; scene: " + run_report["scene"].value("mode", std::string()) : "")},
        {"layers", {mesh_layer("mesh", mesh, {205, 210, 220}, scene.centre, 0.8, cutaway), points_layer("points", c, ps)}},
        {"colourbar", colourbar("point-to-mesh distance", 0.0, top)}};
    if (mesh.face_class.size() == mesh.faces.size())
      v["legend"] = {legend_item("roof", kRoof), legend_item("wall", kWall), legend_item("ground", kGround),
                     legend_item("closure (no data)", kClosure)};
    views.push_back(v);
  }
  data["report"] = run_report;
  std::string title = params.title;
  if (title.empty())
    title = "hsr report" + (run_report.contains("input") && run_report["input"].is_string()
                                ? ": " + std::filesystem::path(run_report["input"].get<std::string>()).filename().string()
                                : std::string());
  data["title"] = title;
  return fill_template(data, title);
}

void write_html_report(const std::string& path, const PipelineArtifacts& artifacts, const PolygonMesh& mesh,
                       const nlohmann::json& run_report, const ReportParams& params) {
  const std::string page = html_report(artifacts, mesh, run_report, params);
  AtomicFile f(path, "report");
  f.stream() << page;
  f.commit();
}

std::string html_still(const PolygonMesh* mesh, const PointCloud* points, const ReportParams& params) {
  require_three_js();
  const bool has_mesh = mesh && !mesh->faces.empty();
  const bool has_points = points && !points->empty();
  if (!has_mesh && !has_points) throw Error(Status::BadInput, "render", "nothing to render: no faces and no points");
  BBox box;
  if (has_points) box = bounding_box(points->points);
  if (has_mesh)
    for (const Vec3& v : mesh->vertices) box.extend(v);
  const Scene scene = scene_of(box);
  std::vector<Vec3> shown_points;
  if (has_points)
    for (std::size_t i : subsample(points->size(), params.max_points)) shown_points.push_back(points->points[i]);
  nlohmann::json data = base_data(scene, "still", shown_points);
  add_cutaway(data, scene, box, params);
  nlohmann::json view = {{"id", "still"}, {"title", params.title}, {"layers", nlohmann::json::array()}};
  if (has_mesh)
    view["layers"].push_back(
        mesh_layer("mesh", *mesh, {215, 218, 225}, scene.centre, has_points ? 0.85 : 1.0, cutaway_view(params)));
  if (has_points) {
    std::vector<Rgb> c;
    if (has_mesh) {
      const std::vector<double> d = point_mesh_distances(shown_points, *mesh);
      std::vector<double> sorted(d);
      std::sort(sorted.begin(), sorted.end());
      double top = sorted[std::min(sorted.size() - 1, sorted.size() * 99 / 100)];
      if (!(top > 0) || !std::isfinite(top)) top = 1e-3 * scene.radius;
      for (double x : d) c.push_back(ramp(x / top));
    } else {
      const double z0 = box.min.z(), dz = box.max.z() > box.min.z() ? box.max.z() - box.min.z() : 1.0;
      for (const Vec3& p : shown_points) c.push_back(ramp((p.z() - z0) / dz));
    }
    view["layers"].push_back(points_layer("points", c, params.point_size));
  }
  data["views"].push_back(view);
  data["title"] = params.title;
  if (params.still_width > 0 && params.still_height > 0) data["size"] = {params.still_width, params.still_height};
  return fill_template(data, params.title.empty() ? "hsr render" : params.title);
}

// ------------------------------------------------------------------------------------------ rendering

std::string find_chromium(const RenderParams& params) {
  namespace fs = std::filesystem;
  auto executable = [](const std::string& p) { return !p.empty() && ::access(p.c_str(), X_OK) == 0 && !fs::is_directory(p); };
  if (!params.chromium.empty()) return executable(params.chromium) ? params.chromium : "";
  if (const char* env = std::getenv("HSR_CHROMIUM"); env && *env) return executable(env) ? env : "";
  const char* path = std::getenv("PATH");
  std::stringstream dirs(path ? path : "/usr/bin:/bin");
  std::string dir;
  while (std::getline(dirs, dir, ':'))
    for (const char* name : {"chromium", "chromium-browser"}) {
      const std::string p = (fs::path(dir.empty() ? "." : dir) / name).string();
      if (executable(p)) return p;
    }
  return "";
}

void render_png(const std::string& html_path, const std::string& png_path, const RenderParams& params) {
  namespace fs = std::filesystem;
  const std::string chromium = find_chromium(params);
  if (chromium.empty())
    throw Error(Status::NotImplemented, "render",
                "Chromium not found (install Debian's chromium package, or set HSR_CHROMIUM to the browser)");
  if (!fs::exists(html_path)) throw Error(Status::FileNotFound, "render", "page not found: " + html_path);
  // A fresh profile per run: no shared state, nothing left in the user's home.
  std::string tmpl = (fs::temp_directory_path() / "hsr-render-XXXXXX").string();
  if (!::mkdtemp(tmpl.data())) throw Error(Status::Internal, "render", "cannot create a temporary folder");
  const fs::path tmp(tmpl);
  const fs::path shot = tmp / "shot.png";
  const std::string url = "file://" + fs::absolute(html_path).string();
  std::vector<std::string> args = {
      chromium, "--headless", "--no-sandbox", "--disable-gpu", "--use-angle=swiftshader",
      "--enable-unsafe-swiftshader", "--disable-quic", "--no-first-run", "--disable-background-networking",
      "--disable-component-update", "--disable-sync", "--hide-scrollbars", "--force-device-scale-factor=1",
      "--user-data-dir=" + (tmp / "profile").string(),
      "--window-size=" + std::to_string(params.width) + "," + std::to_string(params.height),
      "--virtual-time-budget=" + std::to_string(params.virtual_time_ms), "--screenshot=" + shot.string()};
  if (params.allow_file_access) args.push_back("--allow-file-access-from-files");
  args.push_back(url);
  const fs::path log_path = tmp / "chromium.log";
  const pid_t pid = ::fork();
  if (pid < 0) throw Error(Status::Internal, "render", "fork failed");
  if (pid == 0) {
    std::FILE* log = std::fopen(log_path.c_str(), "w");
    if (log) {
      ::dup2(fileno(log), 1);
      ::dup2(fileno(log), 2);
    }
    ::alarm(static_cast<unsigned>(params.timeout_seconds));  // SIGALRM survives exec: the browser is killed
    std::vector<char*> argv;
    for (auto& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    ::execv(chromium.c_str(), argv.data());
    std::_Exit(127);
  }
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  const bool ok = fs::exists(shot) && fs::file_size(shot) > 0;
  if (!ok) {
    std::string tail;
    {
      std::ifstream in(log_path);
      std::string line;
      while (std::getline(in, line))
        if (line.find("ERROR") != std::string::npos && line.find("dbus") == std::string::npos) tail = line;
    }
    std::error_code ec;
    fs::remove_all(tmp, ec);
    throw Error(Status::Internal, "render",
                "Chromium wrote no screenshot of " + html_path +
                    (WIFSIGNALED(status) ? " (killed after " + std::to_string(params.timeout_seconds) + " s)" : "") +
                    (tail.empty() ? "" : ": " + tail.substr(0, 200)));
  }
  // Move into place atomically (copy to a temp name beside the target, then rename).
  const fs::path target = fs::absolute(png_path);
  const fs::path part = target.string() + ".part";
  std::error_code ec;
  fs::copy_file(shot, part, fs::copy_options::overwrite_existing, ec);
  if (!ec) fs::rename(part, target, ec);
  fs::remove_all(tmp);
  if (ec) throw Error(Status::FileNotFound, "render", "cannot write " + png_path + ": " + ec.message());
  log::verbose("render: " + png_path + " (" + std::to_string(params.width) + "x" + std::to_string(params.height) + ")");
}

}  // namespace hsr
