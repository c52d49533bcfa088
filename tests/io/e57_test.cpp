// E57 (ASTM E2807) reader against the project's own writer (io/e57_writer.h; public E57 files only when
// $HSR_E57_PUBLIC_DATA names them, last test): exact round trips of 8-byte floats, bit-packed scaled integers
// over many packets, several scans
// turned by their poses, the scanner positions, structured scans' invalid points dropped, spherical
// coordinates, intensity and colour scaled to 16 bits; the CRC-32C's known answer; truncated, corrupt or
// over-limit files give one BadFormat line naming the file, and mutated files (checksums made right again)
// never crash.
#include "io/e57_internal.h"
#include "io/e57_writer.h"
#include "io/io.h"
#include "io/io_internal.h"

#include "core/log.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>

namespace hsr {
namespace {

namespace e57 = io_detail::e57;

std::string write_file(const std::string& name, const std::string& bytes) {
  // A folder per test: ctest runs this file's tests in parallel, and scratch_dir empties its folder.
  const std::filesystem::path dir = std::filesystem::path(HSR_TEST_TMP_DIR) / "e57" /
                                    ::testing::UnitTest::GetInstance()->current_test_info()->name();
  std::filesystem::create_directories(dir);
  const auto p = dir / name;
  std::ofstream(p, std::ios::binary) << bytes;
  return p.string();
}

/// Points on a small grid, deterministic, exactly representable.
std::vector<Vec3> grid_points(int n, double step, Vec3 base = Vec3::Zero()) {
  std::vector<Vec3> out;
  for (int i = 0; i < n; ++i) out.push_back(base + Vec3((i % 7) * step, ((i / 7) % 5) * step, (i / 35) * step + 0.25));
  return out;
}

/// The file with its page checksums made right again after its bytes were changed.
std::string with_checksums(std::string f) {
  for (std::size_t p = 0; p + e57::kPageBytes <= f.size(); p += e57::kPageBytes) {
    const std::uint32_t crc = e57::crc32c(reinterpret_cast<const unsigned char*>(f.data()) + p, e57::kPagePayload);
    std::string c;
    io_detail::store_scalar(c, crc, false);
    f.replace(p + e57::kPagePayload, 4, c);
  }
  return f;
}

void expect_one_line_bad_format(const std::string& path, const std::string& must_contain = "") {
  try {
    read_points(path);
    ADD_FAILURE() << "no error for " << path;
  } catch (const Error& e) {
    EXPECT_EQ(e.stage(), "io");
    EXPECT_EQ(e.status(), Status::BadFormat) << e.one_line();
    EXPECT_EQ(e.one_line().find('\n'), std::string::npos) << e.one_line();
    EXPECT_NE(e.one_line().find(path), std::string::npos) << e.one_line();
    if (!must_contain.empty()) EXPECT_NE(e.one_line().find(must_contain), std::string::npos) << e.one_line();
  }
}

TEST(E57, Crc32cKnownAnswer) {
  const std::string s = "123456789";
  EXPECT_EQ(e57::crc32c(reinterpret_cast<const unsigned char*>(s.data()), s.size()), 0xE3069283u);
}

TEST(E57, LogicalAndPhysicalOffsets) {
  EXPECT_EQ(e57::physical_offset(1019), 1019u);
  EXPECT_EQ(e57::physical_offset(1020), 1024u);
  EXPECT_EQ(e57::logical_offset(2048 + 5), 2040u + 5);
  EXPECT_EQ(e57::logical_offset(1020), UINT64_MAX);  // inside the first page's checksum
  for (std::uint64_t l : {0ull, 47ull, 1020ull, 123456ull}) EXPECT_EQ(e57::logical_offset(e57::physical_offset(l)), l);
}

TEST(E57, FloatScanRoundTripIsExact) {
  E57WriteScan s;
  s.points = grid_points(500, 0.125);  // 12 kB of floats: several pages
  s.translation = Vec3(1.5, -2.0, 1.25);
  const std::string path = write_file("float.e57", e57_file_bytes({s}));
  std::vector<Vec3> scanners;
  const PointCloud c = read_points(path, {}, scanners);
  ASSERT_EQ(c.size(), s.points.size());
  EXPECT_EQ(c.origin, Vec3::Zero());
  for (std::size_t i = 0; i < c.size(); ++i) EXPECT_EQ(c.points[i], s.points[i] + s.translation) << i;
  ASSERT_EQ(scanners.size(), 1u);
  EXPECT_EQ(scanners[0], s.translation);
  EXPECT_TRUE(c.attributes.empty());
}

TEST(E57, ScaledIntegersOverManyPacketsWithinHalfAStep) {
  E57WriteScan s;
  for (int i = 0; i < 3000; ++i) s.points.emplace_back(std::sin(i) * 7.3, std::cos(0.7 * i) * 3.1, 0.001 * i);
  s.scaled_integer_scale = 1e-3;  // 14, 13 and 12 bits per value: values straddle bytes and packets
  E57WriteOptions o;
  o.max_chunk_bytes = 37;  // odd chunks: hundreds of data packets
  const PointCloud c = read_points(write_file("scaled.e57", e57_file_bytes({s}, o)));
  ASSERT_EQ(c.size(), s.points.size());
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double want = std::llround(s.points[i][k] / 1e-3) * 1e-3;  // the value the raw integer stands for
      EXPECT_EQ(c.points[i][k], want) << i << " " << k;
      EXPECT_LE(std::abs(c.points[i][k] - s.points[i][k]), 0.5e-3 + 1e-12);
    }
}

TEST(E57, SeveralScansAreTurnedByTheirPosesInScanOrder) {
  std::vector<E57WriteScan> scans(3);
  scans[0].points = grid_points(40, 0.5);
  scans[0].translation = Vec3(0, 0, 1.5);
  scans[1].points = grid_points(50, 0.25);
  scans[1].rotation = {0, 0, 0, 1};  // 180 degrees about z: (x, y, z) -> (-x, -y, z)
  scans[1].translation = Vec3(4, 3, 1.5);
  scans[2].points = grid_points(60, 0.5);
  const Eigen::Quaterniond q(Eigen::AngleAxisd(0.6, Vec3(1, 2, 3).normalized()));
  scans[2].rotation = {q.w(), q.x(), q.y(), q.z()};
  scans[2].translation = Vec3(-2, 1, 0.5);
  std::vector<Vec3> scanners;
  const PointCloud c = read_points(write_file("poses.e57", e57_file_bytes(scans)), {}, scanners);
  ASSERT_EQ(c.size(), 150u);
  ASSERT_EQ(scanners.size(), 3u);
  std::size_t at = 0;
  for (std::size_t k = 0; k < 3; ++k) {
    EXPECT_EQ(scanners[k], scans[k].translation);
    for (const Vec3& p : scans[k].points) {
      Vec3 want = p + scans[k].translation;
      if (k == 1) want = Vec3(-p.x(), -p.y(), p.z()) + scans[k].translation;
      if (k == 2) want = q.toRotationMatrix() * p + scans[k].translation;
      if (k < 2) EXPECT_EQ(c.points[at], want) << at;  // exact rotations stay exact
      EXPECT_LE((c.points[at] - want).norm(), 1e-12) << at;
      ++at;
    }
  }
}

TEST(E57, StructuredScanDropsInvalidPoints) {
  E57WriteScan s;
  for (std::uint32_t r = 0; r < 6; ++r)
    for (std::uint32_t col = 0; col < 9; ++col) {
      s.points.emplace_back(r, col, 2.0);
      s.row.push_back(r);
      s.column.push_back(col);
      s.invalid_state.push_back(static_cast<std::uint8_t>((r * 9 + col) % 4 == 1 ? 2 : (r * 9 + col) % 7 == 3 ? 1 : 0));
    }
  const PointCloud c = read_points(write_file("structured.e57", e57_file_bytes({s})));
  std::vector<Vec3> want;
  for (std::size_t i = 0; i < s.points.size(); ++i)
    if (s.invalid_state[i] == 0) want.push_back(s.points[i]);
  ASSERT_EQ(c.points.size(), want.size());
  EXPECT_LT(want.size(), s.points.size());
  for (std::size_t i = 0; i < want.size(); ++i) EXPECT_EQ(c.points[i], want[i]);
}

TEST(E57, SphericalCoordinates) {
  E57WriteScan s;
  s.spherical = true;
  for (int i = 0; i < 200; ++i) s.points.emplace_back(1.0 + 0.01 * i, -3.0 + 0.03 * i, -1.2 + 0.012 * i);
  s.translation = Vec3(10, 20, 1.5);
  const PointCloud c = read_points(write_file("spherical.e57", e57_file_bytes({s})));
  ASSERT_EQ(c.size(), s.points.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    const double r = s.points[i][0], az = s.points[i][1], el = s.points[i][2];
    const Vec3 want = Vec3(r * std::cos(el) * std::cos(az), r * std::cos(el) * std::sin(az), r * std::sin(el)) + s.translation;
    EXPECT_LE((c.points[i] + c.origin - want).norm(), 1e-12) << i;
    EXPECT_NEAR((c.points[i] + c.origin - s.translation).norm(), r, 1e-12);
  }
}

TEST(E57, IntensityAndColourAreKeptIn16Bits) {
  std::vector<E57WriteScan> scans(2);
  for (std::size_t k = 0; k < 2; ++k) {
    scans[k].points = grid_points(30, 0.5, Vec3(5.0 * k, 0, 0));
    for (int i = 0; i < 30; ++i) {
      scans[k].intensity.push_back(static_cast<float>(i) / 29.0f);
      scans[k].color.push_back({static_cast<std::uint8_t>(8 * i), static_cast<std::uint8_t>(255 - i), static_cast<std::uint8_t>(k * 100)});
    }
  }
  const PointCloud c = read_points(write_file("colour.e57", e57_file_bytes(scans)));
  ASSERT_EQ(c.size(), 60u);
  ASSERT_EQ(c.attributes.intensity.size(), 60u);
  ASSERT_EQ(c.attributes.rgb.size(), 60u);
  for (std::size_t k = 0; k < 2; ++k)
    for (std::size_t i = 0; i < 30; ++i) {
      const std::size_t at = 30 * k + i;
      EXPECT_EQ(c.attributes.intensity[at], std::lround(double(scans[k].intensity[i]) * 65535.0)) << at;
      for (std::size_t ch = 0; ch < 3; ++ch) EXPECT_EQ(c.attributes.rgb[at][ch], 257u * scans[k].color[i][ch]) << at;  // 65535 / 255
    }
  // A scan without colour drops the file's colour (one value per point or none).
  scans[1].color.clear();
  const PointCloud d = read_points(write_file("colour_part.e57", e57_file_bytes(scans)));
  EXPECT_TRUE(d.attributes.rgb.empty());
  EXPECT_EQ(d.attributes.intensity.size(), 60u);
}

TEST(E57, TruncatedFilesAreOneLine) {
  E57WriteScan s;
  s.points = grid_points(400, 0.25);
  const std::string bytes = e57_file_bytes({s});
  for (std::size_t n : {std::size_t{0}, std::size_t{20}, std::size_t{1024}, bytes.size() / 2, bytes.size() - 1024, bytes.size() - 1})
    expect_one_line_bad_format(write_file("cut.e57", bytes.substr(0, n)));
}

TEST(E57, CorruptPageFailsItsChecksum) {
  E57WriteScan s;
  s.points = grid_points(400, 0.25);
  std::string bytes = e57_file_bytes({s});
  bytes[3000] = static_cast<char>(bytes[3000] ^ 0x10);
  expect_one_line_bad_format(write_file("crc.e57", bytes), "page 2 fails its CRC-32C");
}

TEST(E57, LimitsRefuseWithOneLine) {
  E57WriteScan s;
  s.points = grid_points(400, 0.25);
  const std::string path = write_file("limits.e57", e57_file_bytes({s, s}));
  ReadParams rp;
  rp.e57.max_points = 799;
  EXPECT_THROW(read_points(path, rp), Error);
  try { read_points(path, rp); } catch (const Error& e) { EXPECT_NE(e.one_line().find("max_points"), std::string::npos) << e.one_line(); }
  rp = {};
  rp.e57.max_scans = 1;
  try { read_points(path, rp); ADD_FAILURE(); } catch (const Error& e) { EXPECT_NE(e.one_line().find("max_scans"), std::string::npos); }
  rp = {};
  rp.e57.max_xml_bytes = 100;
  try { read_points(path, rp); ADD_FAILURE(); } catch (const Error& e) { EXPECT_NE(e.one_line().find("max_xml_bytes"), std::string::npos); }
  rp = {};
  EXPECT_EQ(read_points(path, rp).size(), 800u);
}

TEST(E57, ALyingRecordCountIsOneLine) {
  E57WriteScan s;
  s.points = grid_points(100, 0.25);
  std::string bytes = e57_file_bytes({s});
  // Same length, so the XML section's length stays right: 100 -> 900 points.
  const std::size_t at = bytes.find("recordCount=\"100\"");
  ASSERT_NE(at, std::string::npos);
  bytes[at + 13] = '9';
  expect_one_line_bad_format(write_file("count.e57", with_checksums(bytes)), "truncated");
}

TEST(E57, MutatedFilesNeverCrash) {
  std::vector<E57WriteScan> scans(2);
  scans[0].points = grid_points(60, 0.25);
  scans[0].scaled_integer_scale = 1e-3;
  scans[0].intensity.assign(60, 0.5f);
  scans[1].points = grid_points(40, 0.5);
  scans[1].invalid_state.assign(40, 0);
  scans[1].rotation = {0, 1, 0, 0};
  E57WriteOptions o;
  o.max_chunk_bytes = 64;
  const std::string bytes = e57_file_bytes(scans, o);
  const log::Level was = log::level();
  log::set_level(log::Level::Quiet);  // mutated names would warn for every dropped intensity
  std::size_t read_ok = 0, refused = 0;
  for (std::size_t i = 0; i < bytes.size(); i += 7) {
    if (i % e57::kPageBytes >= e57::kPagePayload) continue;
    for (unsigned char flip : {0x01, 0x80, 0xFF}) {
      std::string m = bytes;
      m[i] = static_cast<char>(m[i] ^ flip);
      const std::string path = write_file("mutated.e57", with_checksums(m));
      try {
        const PointCloud c = read_points(path);
        for (const Vec3& p : c.points) ASSERT_TRUE(p.allFinite());
        ++read_ok;
      } catch (const Error& e) {
        ASSERT_EQ(e.stage(), "io") << e.one_line();
        ASSERT_TRUE(e.status() == Status::BadFormat || e.status() == Status::BadInput) << e.one_line();
        ASSERT_EQ(e.one_line().find('\n'), std::string::npos);
        ++refused;
      }
    }
  }
  log::set_level(was);
  EXPECT_GT(read_ok, 0u);
  EXPECT_GT(refused, 0u);
}

TEST(E57, UnknownFieldTypeAndMissingCoordinatesAreOneLine) {
  E57WriteScan s;
  s.points = grid_points(10, 0.25);
  std::string bytes = e57_file_bytes({s});
  std::string a = bytes;
  a.replace(a.find("cartesianZ"), 10, "cartesianQ");
  expect_one_line_bad_format(write_file("noz.e57", with_checksums(a)), "neither cartesianX/Y/Z");
  std::string b = bytes;
  b.replace(b.find("<cartesianY type=\"Float\"") + 18, 5, "Blob ");  // same length: the XML's length stays right
  expect_one_line_bad_format(write_file("blob.e57", with_checksums(b)), "not supported");
}

// Public E57 files, written by other software (libE57Format's test data: github.com/asmaloney/libE57Format-test-data,
// its reference/ files from libe57.org), when a checkout of it is named by $HSR_E57_PUBLIC_DATA (not in the suite's
// data: the project downloads nothing). The counts are those libE57Format's own tests expect; the same points
// stored as doubles and as scaled integers (or floats) must read to the same doubles.
std::string public_e57(const char* file) {
  const char* dir = std::getenv("HSR_E57_PUBLIC_DATA");
  if (!dir || !*dir) return "";
  const std::filesystem::path p = std::filesystem::path(dir) / file;
  return std::filesystem::exists(p) ? p.string() : "";
}

std::vector<Vec3> global_points(const PointCloud& c) {
  std::vector<Vec3> out;
  for (const Vec3& p : c.points) out.push_back(p + c.origin);
  return out;
}

TEST(E57, PublicFilesOfOtherWritersReadAsTheirAuthorsExpect) {
  const std::string bunny_double = public_e57("reference/bunnyDouble.e57");
  if (bunny_double.empty())
    GTEST_SKIP() << "set HSR_E57_PUBLIC_DATA to a checkout of libE57Format-test-data to read public E57 files";
  const PointCloud bd = read_points(bunny_double), bi = read_points(public_e57("reference/bunnyInt32.e57"));
  EXPECT_EQ(bd.size(), 30571u);
  EXPECT_EQ(global_points(bd), global_points(bi)) << "double and scaled-integer bunnies differ";
  const PointCloud cd = read_points(public_e57("self/ColouredCubeDouble.e57"));
  const PointCloud cf = read_points(public_e57("self/ColouredCubeFloat.e57"));
  EXPECT_EQ(cd.size(), 7680u);
  EXPECT_EQ(global_points(cd), global_points(cf));
  EXPECT_EQ(cd.attributes.rgb.size(), cd.size());
  EXPECT_EQ(cd.attributes.rgb, cf.attributes.rgb);
  const PointCloud colours = read_points(public_e57("3rdParty/las2e57/ColourRepresentation.e57"));
  EXPECT_EQ(colours.size(), 153u);
  EXPECT_EQ(colours.attributes.rgb.size(), 153u);
  for (const char* bad : {"self/bad-crc.e57", "self/empty.e57", "self/ZeroPoints.e57", "self/ZeroPointsInvalid.e57",
                          "self/InvalidCVHeader.e57"}) {
    try {
      read_points(public_e57(bad));
      ADD_FAILURE() << bad << " was read";
    } catch (const Error& e) {
      EXPECT_EQ(e.one_line().find('\n'), std::string::npos) << e.one_line();
      EXPECT_NE(e.one_line().find(std::filesystem::path(bad).filename().string()), std::string::npos) << e.one_line();
    }
  }
}

}  // namespace
}  // namespace hsr
