// Stage 0 dispatch: format by extension, text formats (XYZ family, OFF, OBJ), validation, local origin,
// mesh sampling, and the writers. PLY lives in ply.cpp, LAS in las.cpp.
#include "io/io.h"

#include "core/atomic_file.h"
#include "core/log.h"
#include "io/cityjson.h"
#include "io/io_internal.h"
#include "io/las_internal.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

namespace hsr {
namespace io_detail {

bool host_is_little_endian() { return std::endian::native == std::endian::little; }

std::string read_whole_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(Status::FileNotFound, path, "file not found");
  if (!std::filesystem::is_regular_file(path, ec)) fail(Status::FileNotFound, path, "not a regular file");
  std::ifstream in(path, std::ios::binary);
  if (!in) fail(Status::FileNotFound, path, "cannot open file for reading");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) fail(Status::FileNotFound, path, "error while reading the file");
  return std::move(ss).str();
}

void append_double(std::string& out, double v) {
  char buf[64];
  const auto res = std::to_chars(buf, buf + sizeof(buf), v, std::chars_format::general, 17);
  out.append(buf, res.ptr);
}

}  // namespace io_detail

using io_detail::fail;
using io_detail::RawGeometry;

namespace {

/// Calls f(line_number, line) for each line, '\r' stripped.
template <class F>
void for_each_line(std::string_view text, F&& f) {
  std::size_t number = 0;
  while (!text.empty()) {
    ++number;
    std::size_t nl = text.find('\n');
    std::string_view line = nl == std::string_view::npos ? text : text.substr(0, nl);
    text.remove_prefix(nl == std::string_view::npos ? text.size() : nl + 1);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    if (!f(number, line)) return;
  }
}

/// Tokens separated by blanks (and commas/semicolons for CSV-like text).
std::vector<std::string_view> tokens(std::string_view line, bool csv = false) {
  std::vector<std::string_view> out;
  auto sep = [csv](char c) { return c == ' ' || c == '\t' || c == '\v' || c == '\f' || (csv && (c == ',' || c == ';')); };
  std::size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && sep(line[i])) ++i;
    std::size_t j = i;
    while (j < line.size() && !sep(line[j])) ++j;
    if (j > i) out.push_back(line.substr(i, j - i));
    i = j;
  }
  return out;
}

std::string_view strip_comment(std::string_view line) {
  const std::size_t h = line.find('#');
  return h == std::string_view::npos ? line : line.substr(0, h);
}

/// XYZ / XYZN / PWN / TXT: 3 or 6 numbers per line (the first data line decides; extra columns ignored).
/// A first data line holding a single integer is a point count (PTS style) and is skipped.
RawGeometry read_text_points(const std::string& path) {
  const std::string data = io_detail::read_whole_file(path);
  RawGeometry raw;
  int columns = 0;  // 3 or 6 once decided
  bool first = true;
  for_each_line(data, [&](std::size_t lineno, std::string_view line) {
    auto t = tokens(line, true);
    if (t.empty() || t[0].front() == '#') return true;
    if (first && t.size() == 1) {  // PTS-style count line
      first = false;
      double c;
      if (!io_detail::parse_double(t[0], c)) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": not a number");
      return true;
    }
    first = false;
    if (columns == 0) {
      if (t.size() < 3) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": fewer than 3 numbers");
      columns = t.size() >= 6 ? 6 : 3;
    }
    if (t.size() < static_cast<std::size_t>(columns))
      fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": " + std::to_string(t.size()) + " numbers, expected " +
                                        std::to_string(columns) + " as on the first data line");
    double v[6];
    for (int k = 0; k < columns; ++k)
      if (!io_detail::parse_double(t[k], v[k]))
        fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": not a number: '" + std::string(t[k]) + "'");
    raw.points.emplace_back(v[0], v[1], v[2]);
    if (columns == 6) raw.normals.emplace_back(v[3], v[4], v[5]);
    return true;
  });
  return raw;
}

/// OFF and its [ST][C][N]OFF variants (normals follow the coordinates on each vertex line).
RawGeometry read_off(const std::string& path, bool want_faces) {
  const std::string data = io_detail::read_whole_file(path);
  std::vector<std::pair<std::size_t, std::string_view>> lines;
  for_each_line(data, [&](std::size_t n, std::string_view l) {
    l = strip_comment(l);
    if (!tokens(l).empty()) lines.emplace_back(n, l);
    return true;
  });
  if (lines.empty()) fail(Status::BadFormat, path, "bad OFF header: empty file");
  auto head = tokens(lines[0].second);
  std::string_view kw = head[0];
  if (kw.size() < 3 || kw.substr(kw.size() - 3) != "OFF") fail(Status::BadFormat, path, "bad OFF header: first keyword is not OFF");
  std::string_view prefix = kw.substr(0, kw.size() - 3);
  bool has_normals = false;
  if (prefix.starts_with("ST")) prefix.remove_prefix(2);
  if (prefix.starts_with("C")) prefix.remove_prefix(1);
  if (prefix.starts_with("N")) { has_normals = true; prefix.remove_prefix(1); }
  if (!prefix.empty()) fail(Status::BadFormat, path, "unsupported OFF variant '" + std::string(kw) + "'");
  std::vector<std::string_view> counts(head.begin() + 1, head.end());
  std::size_t next = 1;
  if (counts.empty()) {
    if (lines.size() < 2) fail(Status::BadFormat, path, "bad OFF header: missing vertex/face counts");
    counts = tokens(lines[1].second);
    next = 2;
  }
  double nv_d = -1, nf_d = -1;
  if (counts.size() < 2 || !io_detail::parse_double(counts[0], nv_d) || !io_detail::parse_double(counts[1], nf_d) || nv_d < 0 ||
      nf_d < 0 || nv_d != std::floor(nv_d) || nf_d != std::floor(nf_d) || nv_d > 1e15 || nf_d > 1e15)  // cast below
    fail(Status::BadFormat, path, "bad OFF header: invalid vertex/face counts");
  const std::size_t nv = static_cast<std::size_t>(nv_d), nf = static_cast<std::size_t>(nf_d);
  if (lines.size() - next < nv)
    fail(Status::BadFormat, path, "OFF header declares " + std::to_string(nv) + " vertices but the file has only " +
                                      std::to_string(lines.size() - next) + " data lines");
  RawGeometry raw;
  raw.points.reserve(nv);
  const std::size_t need = has_normals ? 6 : 3;
  for (std::size_t i = 0; i < nv; ++i) {
    const auto& [lineno, l] = lines[next + i];
    auto t = tokens(l);
    double v[6];
    if (t.size() < need) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": expected " + std::to_string(need) + " numbers");
    for (std::size_t k = 0; k < need; ++k)
      if (!io_detail::parse_double(t[k], v[k])) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": not a number");
    raw.points.emplace_back(v[0], v[1], v[2]);
    if (has_normals) raw.normals.emplace_back(v[3], v[4], v[5]);
  }
  next += nv;
  if (want_faces) {
    if (lines.size() - next < nf)
      fail(Status::BadFormat, path, "OFF header declares " + std::to_string(nf) + " faces but the file has only " +
                                        std::to_string(lines.size() - next) + " face lines");
    raw.faces.reserve(nf);
    for (std::size_t i = 0; i < nf; ++i) {
      const auto& [lineno, l] = lines[next + i];
      auto t = tokens(l);
      double n = -1;
      if (!io_detail::parse_double(t[0], n) || n < 0 || n != std::floor(n) || n > 1e9 ||
          t.size() < 1 + static_cast<std::size_t>(n))
        fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": bad face");
      std::vector<std::uint32_t> f(static_cast<std::size_t>(n));
      for (std::size_t k = 0; k < f.size(); ++k) {
        double idx;
        if (!io_detail::parse_double(t[1 + k], idx) || idx < 0 || idx != std::floor(idx) || idx > 4294967295.0)
          fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": bad vertex index");
        f[k] = static_cast<std::uint32_t>(idx);
      }
      raw.faces.push_back(std::move(f));
    }
  }
  return raw;
}

/// OBJ: 'v x y z', 'f a b c ...' with a, a/t, a/t/n, a//n, negative (relative) indices. Other records ignored.
RawGeometry read_obj(const std::string& path) {
  const std::string data = io_detail::read_whole_file(path);
  RawGeometry raw;
  for_each_line(data, [&](std::size_t lineno, std::string_view line) {
    auto t = tokens(strip_comment(line));
    if (t.empty()) return true;
    if (t[0] == "v") {
      double v[3];
      if (t.size() < 4) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": vertex with fewer than 3 coordinates");
      for (int k = 0; k < 3; ++k)
        if (!io_detail::parse_double(t[1 + k], v[k])) fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": not a number");
      raw.points.emplace_back(v[0], v[1], v[2]);
    } else if (t[0] == "f") {
      std::vector<std::uint32_t> f;
      for (std::size_t k = 1; k < t.size(); ++k) {
        std::string_view s = t[k].substr(0, t[k].find('/'));
        long long idx = 0;
        const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), idx);
        if (ec != std::errc() || ptr != s.data() + s.size() || idx == 0)
          fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": bad face index '" + std::string(t[k]) + "'");
        const long long n = static_cast<long long>(raw.points.size());
        const long long zero_based = idx > 0 ? idx - 1 : n + idx;
        if (zero_based < 0 || zero_based >= n)
          fail(Status::BadFormat, path, "line " + std::to_string(lineno) + ": face index " + std::to_string(idx) + " out of range");
        f.push_back(static_cast<std::uint32_t>(zero_based));
      }
      raw.faces.push_back(std::move(f));
    }
    return true;
  });
  return raw;
}

enum class Kind { Ply, Text, Off, Obj, Las, E57 };

/// True when the file starts with the LAS signature "LASF" (LAS and LAZ, whatever the extension).
bool has_las_signature(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  char sig[4] = {};
  return in.read(sig, 4) && std::memcmp(sig, "LASF", 4) == 0;
}

Kind kind_of(const std::string& path, bool for_mesh) {
  const std::string ext = file_extension(path);
  // LAS and LAZ are told by content: the signature, then the point format's compression bit (las.cpp).
  if (!for_mesh && (ext == "las" || ext == "laz" || has_las_signature(path))) return Kind::Las;
  if (ext == "ply") return Kind::Ply;
  if (!for_mesh && ext == "e57") return Kind::E57;
  if (ext == "off") return Kind::Off;
  if (ext == "obj") return Kind::Obj;
  if (!for_mesh) {
    if (ext == "xyz" || ext == "xyzn" || ext == "pwn" || ext == "txt" || ext == "pts") return Kind::Text;
  }
  fail(Status::BadFormat, path,
       std::string("unknown ") + (for_mesh ? "mesh" : "point cloud") + " file extension '" + ext + "' (expected " +
           (for_mesh ? "obj, off, ply)" : "ply, xyz, xyzn, pwn, txt, pts, off, obj, las, laz, e57)"));
}

RawGeometry read_raw(const std::string& path, Kind kind, bool want_faces, const E57Limits& e57 = {}) {
  // Existence first, so a missing file is FileNotFound whatever its extension's reader does.
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(Status::FileNotFound, path, "file not found");
  switch (kind) {
    case Kind::Ply: return io_detail::read_ply(path);
    case Kind::Text: return read_text_points(path);
    case Kind::Off: return read_off(path, want_faces);
    case Kind::Obj: return read_obj(path);
    case Kind::Las: return io_detail::read_las(path);
    case Kind::E57: return io_detail::read_e57(path, e57);
  }
  return {};
}

void check_finite(const std::string& path, const std::vector<Vec3>& pts, const char* what) {
  for (std::size_t i = 0; i < pts.size(); ++i)
    if (!pts[i].allFinite()) fail(Status::BadInput, path, std::string("non-finite (NaN/inf) ") + what + " at index " + std::to_string(i));
}

/// Removes consecutive repeated indices; checks range. Faces left with < 3 vertices are dropped.
void clean_faces(const std::string& path, std::size_t num_vertices, std::vector<std::vector<std::uint32_t>>& faces) {
  std::size_t dropped = 0;
  std::vector<std::vector<std::uint32_t>> kept;
  kept.reserve(faces.size());
  for (std::size_t fi = 0; fi < faces.size(); ++fi) {
    std::vector<std::uint32_t> f;
    for (std::uint32_t v : faces[fi]) {
      if (v >= num_vertices)
        fail(Status::BadFormat, path, "face " + std::to_string(fi) + " refers to vertex " + std::to_string(v) + " but there are " +
                                          std::to_string(num_vertices) + " vertices");
      if (f.empty() || f.back() != v) f.push_back(v);
    }
    while (f.size() > 1 && f.back() == f.front()) f.pop_back();
    std::vector<std::uint32_t> sorted = f;
    std::sort(sorted.begin(), sorted.end());
    if (f.size() < 3 || std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end()) { ++dropped; continue; }
    kept.push_back(std::move(f));
  }
  if (dropped) log::warn("'" + path + "': dropped " + std::to_string(dropped) + " degenerate face(s) (fewer than 3 distinct vertices)");
  faces = std::move(kept);
}

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

/// Samples `count` points uniformly by area on the (fan-triangulated) faces, each with its face's normal.
void sample_faces(const std::string& path, RawGeometry& raw, std::size_t count, std::uint64_t seed) {
  struct Tri { Vec3 a, b, c, normal; };
  std::vector<Tri> tris;
  std::vector<double> cumulative;
  double total = 0;
  for (const auto& f : raw.faces) {
    Vec3 newell = Vec3::Zero();  // polygon normal, robust for non-planar / non-convex input
    for (std::size_t k = 0; k < f.size(); ++k) newell += raw.points[f[k]].cross(raw.points[f[(k + 1) % f.size()]]);
    // Overflow-safe (coordinates beyond ~1e154 overflow norm() and the cross products; fuzz_ply / fuzz_off).
    if (!newell.allFinite() || !(newell.stableNorm() > 0)) continue;
    const Vec3 n = newell / newell.stableNorm();
    for (std::size_t k = 1; k + 1 < f.size(); ++k) {
      const Tri t{raw.points[f[0]], raw.points[f[k]], raw.points[f[k + 1]], n};
      const double area = 0.5 * (t.b - t.a).cross(t.c - t.a).norm();
      if (!(area > 0) || !std::isfinite(area)) continue;
      total += area;
      tris.push_back(t);
      cumulative.push_back(total);
    }
  }
  if (tris.empty()) fail(Status::BadInput, path, "cannot sample: the mesh has zero surface area");
  std::mt19937_64 rng(seed);
  std::vector<Vec3> pts, normals;
  pts.reserve(count);
  normals.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double target = uniform01(rng) * total;
    std::size_t ti = std::upper_bound(cumulative.begin(), cumulative.end(), target) - cumulative.begin();
    ti = std::min(ti, tris.size() - 1);
    const Tri& t = tris[ti];
    const double r1 = std::sqrt(uniform01(rng)), r2 = uniform01(rng);
    pts.push_back((1 - r1) * t.a + r1 * (1 - r2) * t.b + r1 * r2 * t.c);
    normals.push_back(t.normal);
  }
  raw.points = std::move(pts);
  raw.normals = std::move(normals);
}

}  // namespace

Vec3 local_origin(const std::vector<Vec3>& pts, bool always, double threshold) {
  return local_origin(bounding_box(pts), always, threshold);
}

Vec3 local_origin(const BBox& box, bool always, double threshold) {
  const Vec3 c = 0.5 * box.min + 0.5 * box.max;  // not (min + max) / 2: that overflows near 1e308 (fuzz_las)
  bool shift = always;
  for (int k = 0; k < 3; ++k) shift = shift || std::abs(c[k]) > threshold;
  Vec3 origin = Vec3::Zero();
  if (!shift) return origin;
  for (int k = 0; k < 3; ++k) {
    const double o = std::round(c[k]);
    if (o == 0) continue;
    const bool exact = o > 0 ? (box.min[k] >= o / 2 && box.max[k] <= 2 * o) : (box.max[k] <= o / 2 && box.min[k] >= 2 * o);
    if (exact || std::abs(c[k]) > threshold) origin[k] = o;
  }
  return origin;
}


std::string file_extension(const std::string& path) {
  const std::string name = std::filesystem::path(path).filename().string();
  const std::size_t dot = name.rfind('.');
  if (dot == std::string::npos || dot == 0) return "";
  std::string ext = name.substr(dot + 1);
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

BBox read_extent(const std::string& path) {
  if (kind_of(path, false) == Kind::Las) {
    const io_detail::LasHeader h = io_detail::read_las_header_only(path);
    BBox box;
    box.min = h.min;
    box.max = h.max;
    if (h.count > 0 && box.valid() && box.min.allFinite() && box.max.allFinite()) return box;
  }
  const PointCloud cloud = read_points(path);
  BBox box = bounding_box(cloud.points);
  box.min += cloud.origin;
  box.max += cloud.origin;
  return box;
}

namespace {

/// read_point_chunks and read_point_parts: `wanted` null reads every part and checks the whole file.
std::string stream_points(const std::string& path, const std::vector<char>* wanted, const std::function<void(const PointChunk&)>& sink,
                          std::size_t chunk_points) {
  if (chunk_points == 0) fail(Status::BadInput, path, "a chunk of the point stream must hold at least one point");
  if (kind_of(path, false) != Kind::Las) {  // read whole, handed on in runs
    if (wanted && wanted->size() != 1) fail(Status::Internal, path, "asked for " + std::to_string(wanted->size()) + " parts of a file of one");
    if (wanted && !(*wanted)[0]) return "";
    const PointCloud cloud = read_points(path);
    PointChunk chunk;
    for (std::size_t at = 0; at < cloud.size(); at += chunk_points) {
      const std::size_t n = std::min(chunk_points, cloud.size() - at);
      chunk.first = at;
      chunk.points.assign(cloud.points.begin() + static_cast<std::ptrdiff_t>(at), cloud.points.begin() + static_cast<std::ptrdiff_t>(at + n));
      for (Vec3& p : chunk.points) p += cloud.origin;
      sink(chunk);
    }
    return cloud.crs;
  }
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(Status::FileNotFound, path, "file not found");
  BBox box;
  std::uint64_t count = 0;
  const std::string crs = io_detail::stream_las(path, chunk_points, [&](const PointChunk& c) {
    for (std::size_t i = 0; i < c.points.size(); ++i) {
      if (!c.points[i].allFinite())
        fail(Status::BadInput, path, "non-finite (NaN/inf) coordinates at index " + std::to_string(c.first + i));
      box.extend(c.points[i]);
    }
    count += c.points.size();
    sink(c);
  }, wanted);
  if (wanted && std::find(wanted->begin(), wanted->end(), 0) != wanted->end()) return crs;  // some parts only
  if (count == 0) fail(Status::BadInput, path, "file holds zero points");
  if (box.min == box.max) fail(Status::BadInput, path, "all " + std::to_string(count) + " points are identical");
  return crs;
}

}  // namespace

std::string read_point_chunks(const std::string& path, const std::function<void(const PointChunk&)>& sink,
                              std::size_t chunk_points) {
  return stream_points(path, nullptr, sink, chunk_points);
}

std::string read_point_parts(const std::string& path, const std::vector<char>& wanted, const std::function<void(const PointChunk&)>& sink,
                             std::size_t chunk_points) {
  return stream_points(path, &wanted, sink, chunk_points);
}

std::vector<PointPart> point_parts(const std::string& path) {
  if (kind_of(path, false) != Kind::Las) return {PointPart{0, 0}};  // one part: the file read whole (its count unknown until then)
  std::error_code ec;
  if (!std::filesystem::exists(path, ec)) fail(Status::FileNotFound, path, "file not found");
  return io_detail::las_parts(path);
}

PointCloud read_points(const std::string& path, const ReadParams& params) {
  std::vector<Vec3> scanners;
  return read_points(path, params, scanners);
}

PointCloud read_points(const std::string& path, const ReadParams& params, std::vector<Vec3>& scanners) {
  const Kind kind = kind_of(path, false);
  const bool mesh_capable = kind == Kind::Ply || kind == Kind::Off || kind == Kind::Obj;
  RawGeometry raw = read_raw(path, kind, mesh_capable && params.sample_count > 0, params.e57);
  scanners = std::move(raw.scanners);
  if (raw.points.empty()) fail(Status::BadInput, path, "file holds zero points");
  check_finite(path, raw.points, "coordinates");
  if (params.sample_count > 0 && !raw.faces.empty()) {
    clean_faces(path, raw.points.size(), raw.faces);
    if (raw.faces.empty()) fail(Status::BadInput, path, "cannot sample: no valid faces");
    sample_faces(path, raw, params.sample_count, params.seed);
  }
  raw.faces.clear();

  PointCloud cloud;
  cloud.source = path;
  if (!raw.normals.empty()) {
    check_finite(path, raw.normals, "normal");
    bool any_zero = false;
    for (auto& n : raw.normals) {
      const double len = n.stableNorm();  // norm() overflows to inf for components above 1e154 (fuzz_ply)
      if (!(len > 1e-30)) { any_zero = true; break; }
      if (std::abs(len - 1.0) > 1e-12) n /= len;  // leave unit normals untouched: exact round trips
    }
    if (any_zero) {
      log::warn("'" + path + "': some normals have zero length; ignoring the normals of the whole cloud");
      raw.normals.clear();
    }
  }
  const BBox box = bounding_box(raw.points);
  if (box.min == box.max) fail(Status::BadInput, path, "all " + std::to_string(raw.points.size()) + " points are identical");

  cloud.origin = local_origin(raw.points, raw.always_shift, params.local_origin_threshold);
  cloud.points = std::move(raw.points);
  if (cloud.origin != Vec3::Zero())
    for (auto& p : cloud.points) p -= cloud.origin;
  check_finite(path, cloud.points, "coordinates (out of the double range after the shift to a local origin)");
  cloud.normals = std::move(raw.normals);
  cloud.attributes = std::move(raw.attributes);
  cloud.crs = std::move(raw.crs);
  return cloud;
}

PolygonMesh read_mesh(const std::string& path) {
  if (is_cityjson_path(path) || is_cityjsonseq_path(path)) {
    CityModel model = read_cityjson(path);
    if (model.buildings.size() != 1)
      fail(Status::BadInput, path, "holds " + std::to_string(model.buildings.size()) + " buildings; a mesh is one");
    return std::move(model.buildings.front().mesh);
  }
  const Kind kind = kind_of(path, true);
  RawGeometry raw = read_raw(path, kind, true);
  if (raw.points.empty()) fail(Status::BadInput, path, "mesh has zero vertices");
  check_finite(path, raw.points, "coordinates");
  clean_faces(path, raw.points.size(), raw.faces);
  if (raw.faces.empty()) fail(Status::BadInput, path, "mesh has no faces");
  PolygonMesh mesh;
  mesh.origin = local_origin(raw.points, false, ReadParams{}.local_origin_threshold);
  mesh.vertices = std::move(raw.points);
  if (mesh.origin != Vec3::Zero())
    for (auto& p : mesh.vertices) p -= mesh.origin;
  mesh.faces = std::move(raw.faces);
  return mesh;
}

namespace {

void check_writable_vertices(const std::string& path, const std::vector<Vec3>& v, const Vec3& origin) {
  if (!origin.allFinite()) fail(Status::BadInput, path, "cannot write: non-finite origin");
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!v[i].allFinite()) fail(Status::BadInput, path, "cannot write: non-finite coordinates at vertex " + std::to_string(i));
}

void write_text(const std::string& path, const std::string& content) {
  AtomicFile file(path, "io");
  file.stream().write(content.data(), static_cast<std::streamsize>(content.size()));
  file.commit();
}

}  // namespace

void write_mesh(const std::string& path, const PolygonMesh& mesh, FileEncoding encoding) {
  if (is_cityjson_path(path)) return write_cityjson(path, mesh, CityJsonParams{});
  const std::string ext = file_extension(path);
  if (ext != "obj" && ext != "ply" && ext != "off")
    fail(Status::BadFormat, path, "unknown mesh output extension '" + ext + "' (expected obj, ply, off, city.json)");
  check_writable_vertices(path, mesh.vertices, mesh.origin);
  for (std::size_t fi = 0; fi < mesh.faces.size(); ++fi) {
    if (mesh.faces[fi].size() < 3) fail(Status::BadInput, path, "cannot write: face " + std::to_string(fi) + " has fewer than 3 vertices");
    for (std::uint32_t v : mesh.faces[fi])
      if (v >= mesh.vertices.size())
        fail(Status::BadInput, path, "cannot write: face " + std::to_string(fi) + " has vertex index " + std::to_string(v) +
                                         " >= " + std::to_string(mesh.vertices.size()) + " vertices");
  }
  std::string out;
  if (ext == "ply") {
    out = io_detail::format_ply(path, mesh.vertices, mesh.origin, {}, {}, &mesh.faces, encoding == FileEncoding::Binary);
  } else {
    const bool obj = ext == "obj";
    if (obj) out += "# written by hsr\n";
    else out += "OFF\n" + std::to_string(mesh.vertices.size()) + " " + std::to_string(mesh.faces.size()) + " 0\n";
    for (const auto& v : mesh.vertices) {
      const Vec3 g = v + mesh.origin;
      if (obj) out += "v ";
      for (int k = 0; k < 3; ++k) { if (k) out += ' '; io_detail::append_double(out, g[k]); }
      out += '\n';
    }
    for (const auto& f : mesh.faces) {
      out += obj ? "f" : std::to_string(f.size());
      for (std::uint32_t v : f) { out += ' '; out += std::to_string(obj ? v + 1ull : v); }
      out += '\n';
    }
  }
  write_text(path, out);
}

void write_points(const std::string& path, const PointCloud& cloud, FileEncoding encoding,
                  const std::vector<std::array<std::uint8_t, 3>>& colors) {
  const std::string ext = file_extension(path);
  if (ext != "ply" && ext != "xyz" && ext != "xyzn" && ext != "pwn")
    fail(Status::BadFormat, path, "unknown point output extension '" + ext + "' (expected ply, xyz, xyzn, pwn)");
  if (!colors.empty() && colors.size() != cloud.size())
    fail(Status::BadInput, path, "cannot write: " + std::to_string(colors.size()) + " colours for " + std::to_string(cloud.size()) + " points");
  if (!cloud.normals.empty() && !cloud.has_normals())
    fail(Status::BadInput, path, "cannot write: " + std::to_string(cloud.normals.size()) + " normals for " + std::to_string(cloud.size()) + " points");
  check_writable_vertices(path, cloud.points, cloud.origin);
  std::string out;
  if (ext == "ply") {
    out = io_detail::format_ply(path, cloud.points, cloud.origin, cloud.normals, colors, nullptr, encoding == FileEncoding::Binary);
  } else {
    const bool with_normals = ext != "xyz";
    if (with_normals && !cloud.has_normals()) fail(Status::BadInput, path, "cannot write ." + ext + ": the cloud has no normals");
    if (!colors.empty()) log::warn("'" + path + "': colours are only written to PLY; ignored");
    out.reserve(cloud.size() * (with_normals ? 140 : 70));
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      const Vec3 g = cloud.points[i] + cloud.origin;
      for (int k = 0; k < 3; ++k) { if (k) out += ' '; io_detail::append_double(out, g[k]); }
      if (with_normals)
        for (int k = 0; k < 3; ++k) { out += ' '; io_detail::append_double(out, cloud.normals[i][k]); }
      out += '\n';
    }
  }
  write_text(path, out);
}

}  // namespace hsr
