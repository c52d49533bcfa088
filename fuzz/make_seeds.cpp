// Writes the seed corpus of the fuzz targets with the project's own writers and synth:
//   hsr_fuzz_seeds OUT_DIR   →  OUT_DIR/{ply,xyz,off,las,e57,pipeline,extraction}/seed_*
// Small inputs on purpose (libFuzzer mutates faster and its max_len follows the largest seed).
// LAS has no writer in stage io, so its seeds are encoded here (ASPRS LAS 1.2 format 1 and 1.4 format 6).
#include "core/error.h"
#include "fuzz_cloud.h"
#include "io/e57_writer.h"
#include "io/io.h"
#include "synth/synth.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <utility>

namespace fs = std::filesystem;
using namespace hsr;

namespace {

void write_bytes(const fs::path& p, const std::string& bytes) {
  std::ofstream out(p, std::ios::binary | std::ios::trunc);
  out << bytes;
}

template <class T>
void put(std::string& s, std::size_t at, T v) {
  if (s.size() < at + sizeof(T)) s.resize(at + sizeof(T), '\0');
  std::memcpy(&s[at], &v, sizeof(T));  // the host is little-endian (x86-64), as LAS is
}

/// A minimal LAS file: header of 227 (1.2) or 375 (1.4) bytes, no VLR, points scaled by 1e-3.
std::string make_las(const PointCloud& c, int minor, int format, int record_length) {
  const std::uint16_t header_size = minor >= 4 ? 375 : 227;
  std::string s(header_size, '\0');
  std::memcpy(&s[0], "LASF", 4);
  s[24] = 1;
  s[25] = static_cast<char>(minor);
  put<std::uint16_t>(s, 94, header_size);
  put<std::uint32_t>(s, 96, header_size);
  put<std::uint8_t>(s, 104, static_cast<std::uint8_t>(format));
  put<std::uint16_t>(s, 105, static_cast<std::uint16_t>(record_length));
  put<std::uint32_t>(s, 107, minor >= 4 ? 0u : static_cast<std::uint32_t>(c.size()));
  const double scale = 1e-3;
  const Vec3 offset(500000.0, 4000000.0, 100.0);  // UTM-like, as real LAS files
  for (int k = 0; k < 3; ++k) {
    put<double>(s, 131 + 8 * k, scale);
    put<double>(s, 155 + 8 * k, offset[k]);
  }
  if (minor >= 4) put<std::uint64_t>(s, 247, c.size());
  for (const Vec3& p : c.points) {
    std::string rec(static_cast<std::size_t>(record_length), '\0');
    for (int k = 0; k < 3; ++k) put<std::int32_t>(rec, 4 * k, static_cast<std::int32_t>(std::lround(p[k] / scale)));
    s += rec;
  }
  return s;
}

/// E57 seeds from the project's writer: one float scan with a pose; a structured scan of bit-packed scaled
/// integers with invalid states, intensity and colour over small packets; a spherical scan.
void write_e57_seeds(const fs::path& dir, const PointCloud& c) {
  E57WriteScan a;
  a.points = c.points;
  a.rotation = {0, 0, 0, 1};
  a.translation = Vec3(1, 2, 1.5);
  write_bytes(dir / "seed_float.e57", e57_file_bytes({a}));
  E57WriteScan b = a;
  b.scaled_integer_scale = 1e-3;
  for (std::size_t i = 0; i < b.points.size(); ++i) {
    b.row.push_back(static_cast<std::uint32_t>(i / 4));
    b.column.push_back(static_cast<std::uint32_t>(i % 4));
    b.invalid_state.push_back(static_cast<std::uint8_t>(i % 5 == 0 ? 2 : 0));
    b.intensity.push_back(static_cast<float>(i % 8) / 7.0f);
    b.color.push_back({static_cast<std::uint8_t>(i), 128, 255});
  }
  E57WriteOptions small_packets;
  small_packets.max_chunk_bytes = 16;
  write_bytes(dir / "seed_structured.e57", e57_file_bytes({b, a}, small_packets));
  E57WriteScan s;
  s.spherical = true;
  for (std::size_t i = 0; i < c.size(); ++i) s.points.emplace_back(1.0 + 0.1 * double(i % 7), 0.3 * double(i), 0.05 * double(i % 11));
  write_bytes(dir / "seed_spherical.e57", e57_file_bytes({s}));
}

PointCloud first_points(const PointCloud& c, std::size_t n) {
  PointCloud out;
  const std::size_t step = std::max<std::size_t>(1, c.size() / n);
  for (std::size_t i = 0; i < c.size() && out.size() < n; i += step) {
    out.points.push_back(c.points[i]);
    if (c.has_normals()) out.normals.push_back(c.normals[i]);
  }
  return out;
}

/// One polygon in fuzz_complex.h's 8 bytes: integer normal (-3..3 each), centre on the 1/16 grid, radius.
std::string polygon_bytes(int nx, int ny, int nz, int cx, int cy, int cz, double radius, int corners) {
  std::string b;
  for (int v : {nx + 3, ny + 3, nz + 3, cx, cy, cz}) b.push_back(static_cast<char>(v));
  b.push_back(static_cast<char>(std::lround((radius - 0.05) / 0.75 * 255)));
  b.push_back(static_cast<char>(corners - 3));
  return b;
}

/// fuzz_extraction: a box inside the box, three planes crossing at the centre, two coplanar polygons and
/// a tilted pair, each with every partitioner and three label patterns (all inside, alternating, mixed).
void write_extraction_seeds(const fs::path& dir) {
  const std::string inner_box = polygon_bytes(1, 0, 0, 4, 8, 8, 0.4, 4) + polygon_bytes(1, 0, 0, 12, 8, 8, 0.4, 4) +
                                polygon_bytes(0, 1, 0, 8, 4, 8, 0.4, 4) + polygon_bytes(0, 1, 0, 8, 12, 8, 0.4, 4) +
                                polygon_bytes(0, 0, 1, 8, 8, 4, 0.4, 4) + polygon_bytes(0, 0, 1, 8, 8, 12, 0.4, 4);
  const std::string cross = polygon_bytes(1, 0, 0, 8, 8, 8, 0.3, 6) + polygon_bytes(0, 1, 0, 8, 8, 8, 0.3, 6) +
                            polygon_bytes(0, 0, 1, 8, 8, 8, 0.3, 6);
  const std::string coplanar = polygon_bytes(0, 0, 1, 5, 5, 8, 0.2, 5) + polygon_bytes(0, 0, 1, 11, 11, 8, 0.2, 3) +
                               polygon_bytes(1, 1, 0, 8, 8, 8, 0.5, 8);
  const std::string tilted = polygon_bytes(1, 2, 3, 8, 8, 8, 0.6, 7) + polygon_bytes(-3, 1, 2, 6, 9, 7, 0.5, 5);
  const std::pair<const char*, const std::string*> sets[] = {
      {"inner_box", &inner_box}, {"cross", &cross}, {"coplanar", &coplanar}, {"tilted", &tilted}};
  const std::string labels[] = {"", "\x55\xAA", "\xA3\x1C\x77"};
  for (const auto& [name, polygons] : sets)
    for (std::uint8_t method = 0; method < 4; ++method)
      for (std::size_t l = 0; l < 3; ++l) {
        std::string bytes;
        bytes.push_back(static_cast<char>(method | (l << 3) | (l << 5)));  // lambda and format vary with l
        bytes.push_back(static_cast<char>(polygons->size() / 8 - 1));
        bytes += *polygons + labels[l];
        write_bytes(dir / ("seed_" + std::string(name) + "_" + std::to_string(method) + "_" + std::to_string(l)), bytes);
      }
  // Eight polygons and 40 label bytes: libFuzzer's input size limit follows the largest seed.
  for (std::uint8_t method = 0; method < 4; ++method) {
    std::string bytes;
    bytes.push_back(static_cast<char>(method | 8));
    bytes.push_back(static_cast<char>(7));
    bytes += inner_box + tilted;
    for (int k = 0; k < 40; ++k) bytes.push_back(static_cast<char>(37 * k + 11));
    write_bytes(dir / ("seed_eight_" + std::to_string(method)), bytes);
  }
}

/// Moves and scales the cloud into [0.5, 9.5]^3 (the pipeline seed's coordinate range).
PointCloud fit_in_ten(PointCloud c) {
  const BBox b = bounding_box(c.points);
  const double extent = std::max({b.size().x(), b.size().y(), b.size().z(), 1e-9});
  for (auto& p : c.points) p = (p - b.min) * (9.0 / extent) + Vec3::Constant(0.5);
  return c;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s OUT_DIR\n", argv[0]);
    return 2;
  }
  const fs::path root = argv[1];
  for (const char* d : {"ply", "xyz", "off", "las", "e57", "pipeline", "extraction"}) fs::create_directories(root / d);
  try {
    SynthParams sp;
    sp.target_points = 400;
    sp.seed = 3;
    const SynthScan box = run_synth("box", sp);
    const SynthScan house = run_synth("house", sp);
    const PointCloud small = first_points(box.cloud, 40);
    PointCloud small_no_normals = small;
    small_no_normals.normals.clear();

    // PLY: points ascii/binary, with and without normals, with colours; meshes ascii/binary.
    write_points((root / "ply/seed_points_binary.ply").string(), small, FileEncoding::Binary);
    write_points((root / "ply/seed_points_ascii.ply").string(), small, FileEncoding::Ascii);
    write_points((root / "ply/seed_points_nonormals.ply").string(), small_no_normals, FileEncoding::Ascii);
    write_points((root / "ply/seed_points_colors.ply").string(), small_no_normals, FileEncoding::Binary,
                 std::vector<std::array<std::uint8_t, 3>>(small.size(), {200, 10, 30}));
    write_mesh((root / "ply/seed_mesh_ascii.ply").string(), box.truth, FileEncoding::Ascii);
    write_mesh((root / "ply/seed_mesh_binary.ply").string(), box.truth, FileEncoding::Binary);

    // XYZ family: 3 and 6 columns, plus the PTS-style count line and comments the reader accepts.
    write_points((root / "xyz/seed_xyzn.xyzn").string(), small, FileEncoding::Ascii);
    write_points((root / "xyz/seed_xyz.xyz").string(), small_no_normals, FileEncoding::Ascii);
    write_bytes(root / "xyz/seed_pts.xyz", "# comment\n3\n0 0 0\n1,0,0\n0;1;0 255 255 255\n");

    // OFF: meshes written by the project, and a point-only NOFF.
    write_mesh((root / "off/seed_box.off").string(), box.truth);
    write_mesh((root / "off/seed_house.off").string(), house.truth);
    write_bytes(root / "off/seed_noff.off", "NOFF\n3 0 0\n0 0 0 0 0 1\n1 0 0 0 0 1\n0 1 0 0 0 1\n");

    // LAS 1.2 format 1 and LAS 1.4 format 6.
    write_bytes(root / "las/seed_12_f1.las", make_las(small, 2, 1, 28));
    write_bytes(root / "las/seed_14_f6.las", make_las(small, 4, 6, 30));
    write_e57_seeds(root / "e57", small);

    // Pipeline: the synth scans, each partitioner.
    const PointCloud box200 = fit_in_ten(first_points(box.cloud, fuzz::kMaxFuzzPoints));
    const PointCloud house200 = fit_in_ten(first_points(house.cloud, fuzz::kMaxFuzzPoints));
    for (std::uint8_t method = 0; method < 4; ++method) {
      write_bytes(root / ("pipeline/seed_box_" + std::to_string(method)), fuzz::encode_fuzz_case(box200, method, 4));
      write_bytes(root / ("pipeline/seed_house_" + std::to_string(method)),
                  fuzz::encode_fuzz_case(house200, method, 2));
    }
    write_extraction_seeds(root / "extraction");
  } catch (const Error& e) {
    std::fprintf(stderr, "hsr_fuzz_seeds: %s\n", e.one_line().c_str());
    return 1;
  }
  return 0;
}
