// CityJSON 2.0 / CityJSONSeq writer and reader (see cityjson.h). The rounding to integers, its repair and
// the combinatorial checks are here; the geometric verdict (eval's check_validity) comes in through
// CityJsonParams::validate, so stage io needs no CGAL.
#include "io/cityjson.h"

#include "core/atomic_file.h"
#include "core/face_class.h"
#include "core/log.h"
#include "io/io_internal.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <map>
#include <sstream>

namespace hsr {

using io_detail::fail;
using Int3 = std::array<std::int64_t, 3>;
using Ring = std::vector<std::uint32_t>;

namespace {

constexpr double kMaxInteger = 9007199254740992.0;  // 2^53: integers beyond it are not exact in JSON readers

bool ends_with_ci(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (std::size_t i = 0; i < suffix.size(); ++i)
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i]) return false;
  return true;
}

// ------------------------------------------------------------------------------------------ rounding

/// One axis of a vertex on the integer grid: the shift origin - translate is added as a whole number of
/// steps when it is one (the usual case: integer origins, decimal scales), so a re-quantised decoded solid
/// lands exactly on its own integers.
std::int64_t to_grid(double local, double shift, double scale) {
  const double steps = shift / scale;
  const double whole = std::nearbyint(steps);
  const double q = std::abs(steps - whole) <= 1e-9 * std::max(1.0, std::abs(steps))
                       ? std::nearbyint(local / scale) + whole
                       : std::nearbyint((local + shift) / scale);
  if (!(std::abs(q) < kMaxInteger))
    throw Error(Status::BadInput, "io", "CityJSON: a coordinate does not fit the integer grid of scale " +
                                            std::to_string(scale) + " (|x / scale| >= 2^53)");
  return static_cast<std::int64_t>(q);
}

/// Exact Newell vector (twice the area, normal direction) of a ring of integer points.
std::array<__int128, 3> exact_newell(const std::vector<Int3>& v, const Ring& ring) {
  std::array<__int128, 3> n{0, 0, 0};
  const Int3& o = v[ring[0]];
  for (std::size_t i = 1; i + 1 < ring.size(); ++i) {
    __int128 a[3], b[3];
    for (int k = 0; k < 3; ++k) {
      a[k] = v[ring[i]][k] - o[k];
      b[k] = v[ring[i + 1]][k] - o[k];
    }
    n[0] += a[1] * b[2] - a[2] * b[1];
    n[1] += a[2] * b[0] - a[0] * b[2];
    n[2] += a[0] * b[1] - a[1] * b[0];
  }
  return n;
}

bool has_area(const std::vector<Int3>& v, const Ring& ring) {
  const auto n = exact_newell(v, ring);
  return n[0] != 0 || n[1] != 0 || n[2] != 0;
}

/// True when integer point p lies strictly inside the segment a-b (exact).
bool strictly_inside(const Int3& a, const Int3& b, const Int3& p) {
  __int128 d[3], e[3];
  for (int k = 0; k < 3; ++k) {
    d[k] = b[k] - a[k];
    e[k] = p[k] - a[k];
  }
  if (d[1] * e[2] - d[2] * e[1] != 0 || d[2] * e[0] - d[0] * e[2] != 0 || d[0] * e[1] - d[1] * e[0] != 0) return false;
  const __int128 t = d[0] * e[0] + d[1] * e[1] + d[2] * e[2];
  const __int128 len2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
  return t > 0 && t < len2;
}

/// A face flattened to a segment by rounding leaves its neighbours' edges along that segment unmatched
/// (one neighbour has a-c where the others have a-b, b-c): inserts the flattened faces' vertices into every
/// edge they lie strictly inside, in order along the edge. Returns the number of insertions.
std::size_t insert_on_edges(std::vector<Ring>& faces, const std::vector<Int3>& v, const std::vector<std::uint32_t>& points) {
  std::size_t inserted = 0;
  for (Ring& f : faces) {
    Ring out;
    for (std::size_t i = 0; i < f.size(); ++i) {
      const std::uint32_t a = f[i], b = f[(i + 1) % f.size()];
      out.push_back(a);
      std::vector<std::pair<__int128, std::uint32_t>> on;
      for (std::uint32_t p : points)
        if (p != a && p != b && strictly_inside(v[a], v[b], v[p])) {
          __int128 t = 0;
          for (int k = 0; k < 3; ++k) t += static_cast<__int128>(v[b][k] - v[a][k]) * (v[p][k] - v[a][k]);
          on.emplace_back(t, p);
        }
      std::sort(on.begin(), on.end());
      for (const auto& [t, p] : on) out.push_back(p);
      inserted += on.size();
    }
    f = std::move(out);
  }
  return inserted;
}

/// Removes repeated consecutive vertices, the last-first pair included.
void drop_consecutive_repeats(Ring& ring) {
  ring.erase(std::unique(ring.begin(), ring.end()), ring.end());
  while (ring.size() > 1 && ring.back() == ring.front()) ring.pop_back();
}

/// Splits a ring that visits a vertex twice into rings that do not (both keep the orientation). Appends
/// the pieces to `out`; returns the number of splits made.
std::size_t split_at_repeats(const Ring& ring, std::vector<Ring>& out) {
  for (std::size_t i = 0; i < ring.size(); ++i)
    for (std::size_t j = i + 1; j < ring.size(); ++j)
      if (ring[i] == ring[j]) {
        Ring a(ring.begin() + static_cast<std::ptrdiff_t>(i), ring.begin() + static_cast<std::ptrdiff_t>(j));
        Ring b(ring.begin() + static_cast<std::ptrdiff_t>(j), ring.end());
        b.insert(b.end(), ring.begin(), ring.begin() + static_cast<std::ptrdiff_t>(i));
        drop_consecutive_repeats(a);
        drop_consecutive_repeats(b);
        return 1 + split_at_repeats(a, out) + split_at_repeats(b, out);
      }
  out.push_back(ring);
  return 0;
}

void check_mesh_indices(const PolygonMesh& mesh) {
  if (!mesh.origin.allFinite()) throw Error(Status::BadInput, "io", "CityJSON: non-finite mesh origin");
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    if (!mesh.vertices[i].allFinite())
      throw Error(Status::BadInput, "io", "CityJSON: non-finite coordinates at vertex " + std::to_string(i));
  for (std::size_t f = 0; f < mesh.faces.size(); ++f)
    for (std::uint32_t v : mesh.faces[f])
      if (v >= mesh.vertices.size())
        throw Error(Status::BadInput, "io", "CityJSON: face " + std::to_string(f) + " has vertex index " +
                                                std::to_string(v) + " >= " + std::to_string(mesh.vertices.size()));
}

/// Integer points of the vertices, deduplicated in first-appearance order; `remap` maps old to new indices.
std::vector<Int3> round_vertices(const PolygonMesh& mesh, double scale, const Vec3& translate,
                                 std::vector<std::uint32_t>& remap, std::size_t& merged) {
  std::vector<Int3> out;
  std::map<Int3, std::uint32_t> index;
  remap.resize(mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i) {
    Int3 q;
    for (int k = 0; k < 3; ++k) q[k] = to_grid(mesh.vertices[i][k], mesh.origin[k] - translate[k], scale);
    const auto [it, inserted] = index.emplace(q, static_cast<std::uint32_t>(out.size()));
    if (inserted) out.push_back(q);
    else ++merged;
    remap[i] = it->second;
  }
  return out;
}

/// Drops the vertices no face uses, keeping the order of the others.
void drop_unused_vertices(CityJsonSolid& s) {
  std::vector<std::uint32_t> remap(s.vertices.size(), UINT32_MAX);
  for (const Ring& f : s.faces)
    for (std::uint32_t v : f) remap[v] = 0;
  std::vector<Int3> kept;
  for (std::size_t i = 0; i < s.vertices.size(); ++i)
    if (remap[i] == 0) {
      remap[i] = static_cast<std::uint32_t>(kept.size());
      kept.push_back(s.vertices[i]);
    }
  for (Ring& f : s.faces)
    for (std::uint32_t& v : f) v = remap[v];
  s.vertices = std::move(kept);
}

/// The rules every written ring obeys (CityJSON boundaries index `vertices`; val3dity 101/102: at least 3
/// distinct points, no repeated point), checked on the result rather than trusted from the construction.
void verify_rings(const CityJsonSolid& s) {
  if (s.faces.empty()) throw Error(Status::InvalidOutput, "io", "CityJSON: no face is left after rounding");
  for (std::size_t f = 0; f < s.faces.size(); ++f) {
    Ring sorted = s.faces[f];
    std::sort(sorted.begin(), sorted.end());
    const bool ok = sorted.size() >= 3 && sorted.back() < s.vertices.size() &&
                    std::adjacent_find(sorted.begin(), sorted.end()) == sorted.end() && has_area(s.vertices, s.faces[f]);
    HSR_ASSERT(ok, "CityJSON ring " + std::to_string(f) + " breaks the ring rules after repair");
  }
}

std::string scale_text(double scale) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", scale);
  return buf;
}

[[noreturn]] void refuse(double scale, const CityJsonSolid& s, const std::string& problem) {
  throw Error(Status::InvalidOutput, "io",
              "CityJSON: rounded to the grid of scale " + scale_text(scale) + " the solid is " + problem + " (" +
                  std::to_string(s.merged_vertices) + " vertices merged, " + std::to_string(s.dropped_faces) +
                  " faces dropped, " + std::to_string(s.split_faces) + " split)");
}

/// Closed, oriented and 2-manifold at its edges: every directed edge once, and its reverse once.
bool edges_pair_up(const CityJsonSolid& s) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, int> count;
  for (const Ring& f : s.faces)
    for (std::size_t i = 0; i < f.size(); ++i)
      if (++count[{f[i], f[(i + 1) % f.size()]}] > 1) return false;
  for (const auto& [edge, n] : count)
    if (!count.count({edge.second, edge.first})) return false;
  return true;
}

// ------------------------------------------------------------------------------------------ JSON pieces

const char* semantic_type(FaceClass c) {
  switch (c) {
    case FaceClass::Roof: return "RoofSurface";
    case FaceClass::Wall: return "WallSurface";
    case FaceClass::Ground: return "GroundSurface";
    case FaceClass::Closure: return "ClosureSurface";
    case FaceClass::Unknown: break;
  }
  return nullptr;
}

FaceClass class_of_semantic(const std::string& type) {
  for (FaceClass c : {FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    if (type == semantic_type(c)) return c;
  return FaceClass::Unknown;
}

/// `semantics` of a one-shell solid: one Semantic Object per class present (roof, wall, ground, closure
/// order), values[0][f] indexing it, null for an unknown face. A face whose `own` entry is an object gets a
/// Semantic Object of its own after those ({"type": its class, ...own}). Null json when no face has a class.
nlohmann::json semantics_json(const std::vector<FaceClass>& classes, const std::vector<nlohmann::json>& own = {}) {
  const auto has_own = [&](std::size_t f) { return f < own.size() && own[f].is_object() && classes[f] != FaceClass::Unknown; };
  std::array<int, 5> slot{-1, -1, -1, -1, -1};
  nlohmann::json surfaces = nlohmann::json::array();
  for (FaceClass c : {FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    for (std::size_t f = 0; f < classes.size(); ++f)
      if (classes[f] == c && !has_own(f)) {
        slot[static_cast<int>(c)] = static_cast<int>(surfaces.size());
        surfaces.push_back({{"type", semantic_type(c)}});
        break;
      }
  nlohmann::json values = nlohmann::json::array();
  for (std::size_t f = 0; f < classes.size(); ++f) {
    const int c = static_cast<int>(classes[f]);
    if (has_own(f)) {
      nlohmann::json o = {{"type", semantic_type(classes[f])}};
      for (const auto& [key, value] : own[f].items()) o[key] = value;
      values.push_back(surfaces.size());
      surfaces.push_back(std::move(o));
    } else {
      values.push_back(slot[c] < 0 ? nlohmann::json(nullptr) : nlohmann::json(slot[c]));
    }
  }
  if (surfaces.empty()) return nullptr;
  return {{"surfaces", surfaces}, {"values", nlohmann::json::array({values})}};
}

/// The Solid of `s` at `lod`, its rings indexing the vertices from `first_vertex`; each face's own semantic
/// attributes from params.surface_attributes.
nlohmann::json solid_json(const CityJsonSolid& s, std::uint32_t first_vertex, const std::string& lod = "2.2",
                          const CityJsonParams* params = nullptr) {
  nlohmann::json shell = nlohmann::json::array();
  for (const Ring& f : s.faces) {
    nlohmann::json ring = nlohmann::json::array();
    for (std::uint32_t v : f) ring.push_back(first_vertex + v);
    shell.push_back(nlohmann::json::array({ring}));
  }
  nlohmann::json g = {{"type", "Solid"}, {"lod", lod}, {"boundaries", nlohmann::json::array({shell})}};
  std::vector<nlohmann::json> own;
  if (params && params->surface_attributes) {
    const PolygonMesh decoded = decode_solid(s);
    for (std::size_t f = 0; f < s.faces.size(); ++f) own.push_back(params->surface_attributes(lod, decoded, f));
  }
  nlohmann::json sem = semantics_json(s.classes, own);
  if (!sem.is_null()) g["semantics"] = std::move(sem);
  return g;
}

/// [minx, miny, minz, maxx, maxy, maxz] of the decoded coordinates.
std::vector<double> extent_of(const CityJsonSolid& s) {
  std::vector<double> e{INFINITY, INFINITY, INFINITY, -INFINITY, -INFINITY, -INFINITY};
  for (const Int3& q : s.vertices)
    for (int k = 0; k < 3; ++k) {
      const double x = static_cast<double>(q[k]) * s.scale + s.translate[k];
      e[k] = std::min(e[k], x);
      e[k + 3] = std::max(e[k + 3], x);
    }
  return e;
}

nlohmann::json building_json(const CityJsonSolid& s, const CityJsonParams& params) {
  nlohmann::json b = {{"type", "Building"}, {"geographicalExtent", extent_of(s)}};
  if (!params.attributes.is_null() && !params.attributes.empty()) b["attributes"] = params.attributes;
  b["geometry"] = nlohmann::json::array({solid_json(s, 0)});
  return b;
}

nlohmann::json vertices_json(const CityJsonSolid& s) {
  nlohmann::json v = nlohmann::json::array();
  for (const Int3& q : s.vertices) v.push_back({q[0], q[1], q[2]});
  return v;
}

nlohmann::json transform_json(double scale, const Vec3& translate) {
  return {{"scale", {scale, scale, scale}}, {"translate", {translate.x(), translate.y(), translate.z()}}};
}

nlohmann::json metadata_json(const CityJsonParams& params, const std::vector<double>& extent) {
  nlohmann::json m = nlohmann::json::object();
  if (!params.crs.empty()) m["referenceSystem"] = crs_url(params.crs);
  if (extent.size() == 6) m["geographicalExtent"] = extent;
  return m;
}

std::string building_id(const CityJsonParams& params) { return params.id.empty() ? "building" : params.id; }

void write_lines(const std::string& path, const std::vector<const nlohmann::json*>& objects) {
  AtomicFile file(path, "io");
  for (const nlohmann::json* j : objects) file.stream() << j->dump() << '\n';
  file.commit();
}

}  // namespace

bool is_cityjson_path(const std::string& path) { return ends_with_ci(path, ".city.json"); }
bool is_cityjsonseq_path(const std::string& path) { return ends_with_ci(path, ".city.jsonl"); }

std::string crs_url(const std::string& crs) {
  const bool epsg = crs.size() > 5 && ends_with_ci(crs.substr(0, 5), "epsg:") &&
                    std::all_of(crs.begin() + 5, crs.end(), [](unsigned char c) { return std::isdigit(c); });
  if (!epsg) throw Error(Status::BadInput, "io", "CityJSON: reference system '" + crs + "' is not EPSG:NNNN");
  return "https://www.opengis.net/def/crs/EPSG/0/" + crs.substr(5);
}

nlohmann::json cityjson_attributes(const nlohmann::json& report) {
  nlohmann::json a = nlohmann::json::object();
  const auto get = [&report](const char* section, const char* key) -> const nlohmann::json* {
    if (!report.contains(section) || !report[section].is_object() || !report[section].contains(key)) return nullptr;
    return &report[section][key];
  };
  if (const auto* v = get("validity", "valid")) {
    a["hsr_valid"] = *v;
    std::string failed;
    for (const char* check : {"closed", "manifold", "oriented", "self_intersection_free", "bounds_volume"})
      if (const auto* c = get("validity", check); c && c->is_boolean() && !c->get<bool>())
        failed += (failed.empty() ? "invalid: not " : ", not ") + std::string(check);
    a["hsr_validity"] = failed.empty() ? std::string("valid") : failed;
  }
  if (const auto* v = get("accuracy", "p2m_mean")) a["hsr_p2m_mean"] = *v;
  if (const auto* v = get("accuracy", "p2m_rms")) a["hsr_p2m_rms"] = *v;
  if (const auto* v = get("counts", "output_faces")) a["hsr_facets"] = *v;
  // Issue 42: the run's quality, so a city's doubtful buildings are found without looking at each.
  static const std::pair<const char*, const char*> quality[] = {
      {"points_unexplained_share", "hsr_points_unexplained_share"}, {"scene", "hsr_scene"},
      {"scene_choice", "hsr_scene_choice"}, {"scene_margin", "hsr_scene_margin"},
      {"ground_source", "hsr_ground_source"}, {"removed_points", "hsr_removed_points"}, {"fallback", "hsr_fallback"}};
  for (const auto& [key, attribute] : quality)
    if (const auto* v = get("quality", key)) a[attribute] = *v;
  if (const auto* v = get("seconds", "total")) a["hsr_seconds"] = *v;
  if (report.contains("version")) a["hsr_version"] = report["version"];
  return a;
}

CityJsonSolid quantize_solid(const PolygonMesh& mesh, double scale, const Vec3& translate, bool require_valid,
                             const std::function<std::string(const PolygonMesh&)>& validate) {
  if (!(scale > 0) || !std::isfinite(scale))
    throw Error(Status::BadInput, "io", "CityJSON: scale must be a positive number, got " + std::to_string(scale));
  if (!translate.allFinite()) throw Error(Status::BadInput, "io", "CityJSON: non-finite translate");
  check_mesh_indices(mesh);
  if (mesh.faces.empty()) throw Error(Status::BadInput, "io", "CityJSON: the mesh has no faces");
  CityJsonSolid s;
  s.scale = scale;
  s.translate = translate;
  std::vector<std::uint32_t> remap;
  s.vertices = round_vertices(mesh, scale, translate, remap, s.merged_vertices);
  // Classes from the unrounded faces: rounding must not turn a wall into a roof.
  const std::vector<FaceClass> classes = face_classes_or_by_normal(mesh);
  std::vector<std::uint32_t> flattened;  // vertices of faces rounded to a segment
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    Ring ring;
    for (std::uint32_t v : mesh.faces[f]) ring.push_back(remap[v]);
    drop_consecutive_repeats(ring);
    std::vector<Ring> pieces;
    if (split_at_repeats(ring, pieces) > 0) ++s.split_faces;
    for (Ring& piece : pieces) {
      if (piece.size() < 3 || !has_area(s.vertices, piece)) {
        ++s.dropped_faces;
        if (piece.size() >= 3) flattened.insert(flattened.end(), piece.begin(), piece.end());
        continue;
      }
      s.faces.push_back(std::move(piece));
      s.classes.push_back(classes[f]);
    }
  }
  std::sort(flattened.begin(), flattened.end());
  flattened.erase(std::unique(flattened.begin(), flattened.end()), flattened.end());
  s.inserted_vertices = insert_on_edges(s.faces, s.vertices, flattened);
  drop_unused_vertices(s);
  verify_rings(s);
  if (require_valid) {
    if (!edges_pair_up(s)) refuse(scale, s, "not a closed, oriented 2-manifold (an edge is not used once each way)");
    if (validate)
      if (const std::string problem = validate(decode_solid(s)); !problem.empty()) refuse(scale, s, problem);
  }
  return s;
}

PolygonMesh decode_solid(const CityJsonSolid& s) {
  PolygonMesh m;
  m.origin = s.translate;
  m.vertices.reserve(s.vertices.size());
  for (const Int3& q : s.vertices)
    m.vertices.emplace_back(static_cast<double>(q[0]) * s.scale, static_cast<double>(q[1]) * s.scale,
                            static_cast<double>(q[2]) * s.scale);
  m.faces = s.faces;
  m.face_class = s.classes;
  return m;
}

namespace {

/// quantize_solid at params.scale or, when the rounded solid fails a check, at the first of
/// params.finer_steps steps ten times finer that passes (a warning says which).
CityJsonSolid quantize_finest_needed(const PolygonMesh& mesh, const CityJsonParams& params, const Vec3& translate) {
  double scale = params.scale;
  std::string first_problem;
  for (int step = 0;; ++step, scale /= 10) {
    try {
      CityJsonSolid s = quantize_solid(mesh, scale, translate, params.require_valid, params.validate);
      if (step > 0) log::warn(building_id(params) + ": " + first_problem + "; written at scale " + scale_text(scale));
      return s;
    } catch (const Error& e) {
      if (e.status() != Status::InvalidOutput) throw;
      if (step == 0) first_problem = e.what();
      if (step >= params.finer_steps)
        throw Error(Status::InvalidOutput, "io",
                    first_problem + (params.finer_steps > 0 ? "; and so at every finer step down to " + scale_text(scale)
                                                            : std::string("; use a finer --cityjson-scale")));
    }
  }
}

}  // namespace

nlohmann::json cityjson_document(const PolygonMesh& mesh, const CityJsonParams& params) {
  const CityJsonSolid s = quantize_finest_needed(mesh, params, mesh.origin);
  const std::vector<double> extent = extent_of(s);
  nlohmann::json doc = {{"type", "CityJSON"}, {"version", "2.0"}, {"transform", transform_json(s.scale, s.translate)}};
  doc["metadata"] = metadata_json(params, extent);
  doc["CityObjects"] = {{building_id(params), building_json(s, params)}};
  doc["vertices"] = vertices_json(s);
  return doc;
}

void write_cityjson(const std::string& path, const PolygonMesh& mesh, const CityJsonParams& params) {
  const nlohmann::json doc = cityjson_document(mesh, params);  // everything is checked before the file opens
  write_lines(path, {&doc});
}

nlohmann::json cityjson_seq_header(const CityJsonParams& params, const Vec3& translate, const std::vector<double>& extent) {
  if (!(params.scale > 0) || !std::isfinite(params.scale))
    throw Error(Status::BadInput, "io", "CityJSON: scale must be a positive number");
  nlohmann::json h = {{"type", "CityJSON"}, {"version", "2.0"}, {"transform", transform_json(params.scale, translate)}};
  h["metadata"] = metadata_json(params, extent);
  h["CityObjects"] = nlohmann::json::object();
  h["vertices"] = nlohmann::json::array();
  return h;
}

nlohmann::json cityjson_feature(const PolygonMesh& mesh, const CityJsonParams& params, const Vec3& translate) {
  const CityJsonSolid s = quantize_solid(mesh, params.scale, translate, params.require_valid, params.validate);  // the header's scale
  const std::string id = building_id(params);
  return {{"type", "CityJSONFeature"},
          {"id", id},
          {"CityObjects", {{id, building_json(s, params)}}},
          {"vertices", vertices_json(s)}};
}

nlohmann::json cityjson_feature(const std::vector<CityJsonGeometry>& solids, const CityJsonParams& params, const Vec3& translate) {
  if (solids.empty()) throw Error(Status::BadInput, "io", "CityJSON: a feature without a solid");
  const std::string id = building_id(params);
  nlohmann::json geometry = nlohmann::json::array(), vertices = nlohmann::json::array();
  std::vector<double> extent;
  for (const CityJsonGeometry& g : solids) {
    const CityJsonSolid s = quantize_solid(g.mesh, params.scale, translate, params.require_valid, params.validate);
    geometry.push_back(solid_json(s, static_cast<std::uint32_t>(vertices.size()), g.lod, &params));
    for (auto& v : vertices_json(s)) vertices.push_back(std::move(v));
    const std::vector<double> e = extent_of(s);
    if (extent.empty()) extent = e;
    for (int k = 0; k < 3; ++k) {
      extent[k] = std::min(extent[k], e[k]);
      extent[k + 3] = std::max(extent[k + 3], e[k + 3]);
    }
  }
  nlohmann::json b = {{"type", "Building"}, {"geographicalExtent", extent}};
  if (!params.attributes.is_null() && !params.attributes.empty()) b["attributes"] = params.attributes;
  b["geometry"] = std::move(geometry);
  return {{"type", "CityJSONFeature"}, {"id", id}, {"CityObjects", {{id, std::move(b)}}}, {"vertices", std::move(vertices)}};
}

void write_cityjsonseq(const std::string& path, const nlohmann::json& header, const std::vector<nlohmann::json>& features) {
  std::vector<const nlohmann::json*> lines{&header};
  for (const auto& f : features) lines.push_back(&f);
  write_lines(path, lines);
}

// ------------------------------------------------------------------------------------------ reader

namespace {

struct Reader {
  std::string path;

  [[noreturn]] void bad(const std::string& what) const { fail(Status::BadFormat, path, "CityJSON: " + what); }

  const nlohmann::json& member(const nlohmann::json& obj, const char* key, const std::string& where) const {
    if (!obj.is_object() || !obj.contains(key)) bad(where + " has no \"" + key + "\" member");
    return obj[key];
  }

  void read_transform(const nlohmann::json& doc, CityModel& model) const {
    const auto& t = member(doc, "transform", "the CityJSON object");
    const auto& sc = member(t, "scale", "transform");
    const auto& tr = member(t, "translate", "transform");
    if (!sc.is_array() || sc.size() != 3 || !tr.is_array() || tr.size() != 3) bad("transform scale/translate are not 3 numbers");
    for (int k = 0; k < 3; ++k)
      if (!sc[k].is_number() || !tr[k].is_number()) bad("transform scale/translate are not 3 numbers");
    if (sc[0] != sc[1] || sc[0] != sc[2]) bad("transform scales differ per axis (hsr writes one scale)");
    model.scale = sc[0].get<double>();
    if (!(model.scale > 0)) bad("transform scale is not positive");
    model.translate = Vec3(tr[0].get<double>(), tr[1].get<double>(), tr[2].get<double>());
    if (doc.contains("metadata") && doc["metadata"].contains("referenceSystem"))
      model.reference_system = doc["metadata"]["referenceSystem"].get<std::string>();
  }

  std::vector<Int3> read_vertices(const nlohmann::json& obj) const {
    const auto& vs = member(obj, "vertices", "the object");
    if (!vs.is_array()) bad("\"vertices\" is not an array");
    std::vector<Int3> out;
    out.reserve(vs.size());
    for (std::size_t i = 0; i < vs.size(); ++i) {
      const auto& v = vs[i];
      if (!v.is_array() || v.size() != 3 || !v[0].is_number_integer() || !v[1].is_number_integer() || !v[2].is_number_integer())
        bad("vertex " + std::to_string(i) + " is not an array of 3 integers");
      out.push_back({v[0].get<std::int64_t>(), v[1].get<std::int64_t>(), v[2].get<std::int64_t>()});
    }
    return out;
  }

  /// Semantic class of each surface of shell 0 (Unknown for null); empty semantics -> all Unknown.
  std::vector<FaceClass> read_semantics(const nlohmann::json& g, std::size_t surfaces, const std::string& id) const {
    std::vector<FaceClass> out(surfaces, FaceClass::Unknown);
    if (!g.contains("semantics")) return out;
    const auto& sem = g["semantics"];
    const auto& types = member(sem, "surfaces", id + " semantics");
    const auto& values = member(sem, "values", id + " semantics");
    if (!types.is_array() || !values.is_array() || values.size() != g["boundaries"].size() || !values[0].is_array() ||
        values[0].size() != surfaces)
      bad(id + ": semantics values are not one per surface of each shell");
    for (std::size_t f = 0; f < surfaces; ++f) {
      const auto& v = values[0][f];
      if (v.is_null()) continue;
      if (!v.is_number_integer() || v.get<std::int64_t>() < 0 || v.get<std::size_t>() >= types.size())
        bad(id + ": semantics value of surface " + std::to_string(f) + " does not index \"surfaces\"");
      out[f] = class_of_semantic(member(types[v.get<std::size_t>()], "type", id + " semantic surface").get<std::string>());
    }
    return out;
  }

  /// The Building's Solids in file order; the one of the highest LoD (the first of them) first in `best`.
  std::vector<const nlohmann::json*> solids_of(const nlohmann::json& obj, const std::string& id, std::size_t& best) const {
    const auto& geoms = member(obj, "geometry", "Building " + id);
    std::vector<const nlohmann::json*> out;
    best = 0;
    for (const auto& g : geoms)
      if (g.is_object() && g.value("type", "") == "Solid") {
        const auto lod_of = [](const nlohmann::json& j) { return j.contains("lod") && j["lod"].is_string() ? j["lod"].get<std::string>() : std::string(); };
        if (!out.empty() && lod_of(g) > lod_of(*out[best])) best = out.size();
        out.push_back(&g);
      }
    if (out.empty()) bad("Building " + id + " has no Solid geometry");
    return out;
  }

  /// One Solid's mesh: its used vertices (in index order) decoded, its shell's rings as faces.
  PolygonMesh read_solid(const nlohmann::json& g, const std::string& id, const std::vector<Int3>& vertices, const CityModel& model) const {
    const auto& shells = member(g, "boundaries", id + " Solid");
    if (!shells.is_array() || shells.empty() || !shells[0].is_array()) bad(id + ": Solid boundaries are not an array of shells");
    if (shells.size() > 1) bad(id + ": Solid has interior shells (hsr writes one shell)");
    PolygonMesh mesh;
    std::map<std::uint32_t, std::uint32_t> local;
    for (const auto& surface : shells[0]) {
      if (!surface.is_array() || surface.empty()) bad(id + ": a surface is not an array of rings");
      if (surface.size() > 1) bad(id + ": a surface has inner rings (hsr writes none)");
      Ring ring;
      for (const auto& idx : surface[0]) {
        if (!idx.is_number_integer() || idx.get<std::int64_t>() < 0 || idx.get<std::size_t>() >= vertices.size())
          bad(id + ": a ring refers to a vertex out of range");
        ring.push_back(local.emplace(idx.get<std::uint32_t>(), 0).first->first);
      }
      Ring sorted = ring;
      std::sort(sorted.begin(), sorted.end());
      if (ring.size() < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
        bad(id + ": a ring has fewer than 3 distinct vertices or repeats one");
      mesh.faces.push_back(std::move(ring));
    }
    std::uint32_t next = 0;
    for (auto& [global, mine] : local) {
      mine = next++;
      const Int3& q = vertices[global];
      mesh.vertices.emplace_back(static_cast<double>(q[0]) * model.scale, static_cast<double>(q[1]) * model.scale,
                                 static_cast<double>(q[2]) * model.scale);
    }
    for (Ring& f : mesh.faces)
      for (std::uint32_t& v : f) v = local[v];
    mesh.origin = model.translate;
    mesh.face_class = read_semantics(g, mesh.faces.size(), id);
    return mesh;
  }

  CityBuilding read_building(const std::string& id, const nlohmann::json& obj, const std::vector<Int3>& vertices,
                             const CityModel& model) const {
    std::size_t best = 0;
    const std::vector<const nlohmann::json*> solids = solids_of(obj, id, best);
    CityBuilding b;
    b.id = id;
    for (const nlohmann::json* g : solids)
      b.lods.push_back({g->contains("lod") && (*g)["lod"].is_string() ? (*g)["lod"].get<std::string>() : std::string(),
                        read_solid(*g, id, vertices, model)});
    b.mesh = b.lods[best].mesh;
    if (obj.contains("attributes")) b.attributes = obj["attributes"];
    if (obj.contains("geographicalExtent")) b.extent = obj["geographicalExtent"].get<std::vector<double>>();
    return b;
  }

  void read_buildings(const nlohmann::json& obj, CityModel& model) const {
    const std::vector<Int3> vertices = read_vertices(obj);
    const auto& objects = member(obj, "CityObjects", "the object");
    if (!objects.is_object()) bad("\"CityObjects\" is not an object");
    for (const auto& [id, co] : objects.items())
      if (co.is_object() && co.value("type", "") == "Building") model.buildings.push_back(read_building(id, co, vertices, model));
  }

  void check_header(const nlohmann::json& doc) const {
    if (!doc.is_object() || doc.value("type", "") != "CityJSON") bad("the first object is not of type \"CityJSON\"");
    if (doc.value("version", "") != "2.0") bad("version is not \"2.0\"");
  }

  nlohmann::json parse(const std::string& text) const {
    try {
      return nlohmann::json::parse(text);
    } catch (const nlohmann::json::exception& e) {
      bad(std::string("not valid JSON (") + e.what() + ")");
    }
  }

  CityModel read_document(const std::string& text) const {
    const nlohmann::json doc = parse(text);
    check_header(doc);
    CityModel model;
    read_transform(doc, model);
    read_buildings(doc, model);
    return model;
  }

  CityModel read_sequence(const std::string& text) const {
    std::istringstream in(text);
    std::string line;
    CityModel model;
    bool header = true;
    while (std::getline(in, line)) {
      if (!line.empty() && line.back() == '\r') line.pop_back();
      if (line.empty()) continue;
      const nlohmann::json obj = parse(line);
      if (header) {
        check_header(obj);
        read_transform(obj, model);
        header = false;
        continue;
      }
      if (!obj.is_object() || obj.value("type", "") != "CityJSONFeature") bad("a line after the first is not a CityJSONFeature");
      read_buildings(obj, model);
    }
    if (header) bad("empty sequence (no CityJSON header line)");
    return model;
  }
};

}  // namespace

CityModel read_cityjson(const std::string& path) {
  const std::string text = io_detail::read_whole_file(path);
  Reader r{path};
  return is_cityjsonseq_path(path) ? r.read_sequence(text) : r.read_document(text);
}

}  // namespace hsr
