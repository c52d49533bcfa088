// LAZ and COPC against their LAS twins (../shared/laz, PDAL's test data; MANIFEST.tsv says which is which):
// decoded records equal the uncompressed records field by field for every point; COPC files hold the same
// points as their twins (shared fields, as sets where the order differs); the LAS reader's attributes
// agree with the per-return counts of the headers; bad LAZ input gives one BadFormat line naming the file.
#include "io/io.h"
#include "io/las_internal.h"
#include "io/laz_items.h"

#include "core/threads.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <tuple>

namespace hsr {
namespace {

using io_detail::LasHeader;

std::string laz_file(const std::string& name) {
  const std::filesystem::path p = std::filesystem::path(HSR_SHARED_LAZ_DIR) / name;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

#define REQUIRE_LAZ(var, name)                                               \
  const std::string var = laz_file(name);                                    \
  if (var.empty()) GTEST_SKIP() << "../shared/laz/" << name << " not found"

/// Name of the field at byte `at` of a record of point format `format` (for messages).
std::string field_at(int format, std::size_t at) {
  static const std::vector<std::pair<std::size_t, const char*>> legacy = {
      {0, "X"}, {4, "Y"}, {8, "Z"}, {12, "intensity"}, {14, "return bits"}, {15, "classification"},
      {16, "scan angle rank"}, {17, "user data"}, {18, "point source ID"}, {20, "GPS time or RGB"}};
  static const std::vector<std::pair<std::size_t, const char*>> extended = {
      {0, "X"}, {4, "Y"}, {8, "Z"}, {12, "intensity"}, {14, "returns"}, {15, "flags"}, {16, "classification"},
      {17, "user data"}, {18, "scan angle"}, {20, "point source ID"}, {22, "GPS time"}, {30, "RGB"}};
  const auto& fields = format >= 6 ? extended : legacy;
  std::string name = "extra bytes";
  for (const auto& [offset, n] : fields)
    if (at >= offset) name = n;
  if (format < 6 && at >= 20) name = (format == 1 || format >= 3) && at < 28 ? "GPS time" : "RGB or later";
  return name;
}

struct Records {
  LasHeader header;
  std::vector<unsigned char> bytes;
  const unsigned char* at(std::size_t i) const { return bytes.data() + i * header.record_length; }
};

Records records_of(const std::string& path) {
  Records r;
  r.header = io_detail::read_las_point_records(path, r.bytes);
  return r;
}

/// Every record of `laz` equals the one of `las`, byte for byte; the first mismatch is named by field.
void expect_same_records(const std::string& laz, const std::string& las) {
  const Records a = records_of(laz), b = records_of(las);
  ASSERT_EQ(a.header.count, b.header.count);
  ASSERT_EQ(a.header.format, b.header.format);
  ASSERT_EQ(a.header.record_length, b.header.record_length);
  ASSERT_EQ(a.bytes.size(), a.header.count * a.header.record_length);
  std::size_t differing = 0;
  for (std::size_t i = 0; i < a.header.count; ++i) {
    if (std::memcmp(a.at(i), b.at(i), a.header.record_length) == 0) continue;
    if (differing++ == 0) {
      std::size_t k = 0;
      while (a.at(i)[k] == b.at(i)[k]) ++k;
      ADD_FAILURE() << laz << ": record " << i << " differs from " << las << " in " << field_at(a.header.format, k);
    }
  }
  EXPECT_EQ(differing, 0u) << "of " << a.header.count << " records";
}

TEST(Laz, PointwiseFilesDecodeToTheirLasTwin) {
  REQUIRE_LAZ(las, "simple.las");
  for (const char* name : {"simple.laz", "laszip-generated.laz", "liblas-generated.laz", "simple-laszip-compressor-version-1.2r0.laz"}) {
    REQUIRE_LAZ(laz, name);
    SCOPED_TRACE(name);
    expect_same_records(laz, las);
  }
}

TEST(Laz, AutzenDecodesToItsLasTwin) {
  REQUIRE_LAZ(laz, "autzen_trim.laz");
  REQUIRE_LAZ(las, "autzen_trim.las");
  expect_same_records(laz, las);  // 110000 points in 3 chunks of 50000
}

/// The fields every format has, in a common frame: integer coordinates in the grid of `frame` (the same
/// scale, offsets that differ by whole steps), then the attributes.
using SharedFields = std::tuple<std::int64_t, std::int64_t, std::int64_t, int, int, int, int, int, int, double,
                                int, int, int>;

std::vector<SharedFields> shared_fields(const Records& r, const LasHeader& frame) {
  std::int64_t shift[3];
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(r.header.scale[k], frame.scale[k]);
    const double steps = (r.header.offset[k] - frame.offset[k]) / frame.scale[k];
    shift[k] = std::llround(steps);
    EXPECT_LT(std::abs(steps - static_cast<double>(shift[k])), 1e-3) << "offsets differ by a fraction of a step";
  }
  const bool ext = r.header.format >= 6;
  std::vector<SharedFields> out;
  for (std::size_t i = 0; i < r.header.count; ++i) {
    const unsigned char* p = r.at(i);
    const auto i32 = [&](int at) { return static_cast<std::int64_t>(laz::load_le<std::int32_t>(p + at)); };
    const auto u16 = [&](int at) { return static_cast<int>(laz::load_le<std::uint16_t>(p + at)); };
    const int ret = ext ? (p[14] & 15) : (p[14] & 7), num = ext ? (p[14] >> 4) : ((p[14] >> 3) & 7);
    const int cls = ext ? p[16] : (p[15] & 31);
    // Formats 6-10 store the scan angle in 0.006 degree steps, the legacy ones whole degrees.
    const int angle = ext ? static_cast<int>(std::lround(0.006 * laz::load_le<std::int16_t>(p + 18)))
                          : static_cast<int>(static_cast<std::int8_t>(p[16]));
    const int user = ext ? p[17] : p[17], source = ext ? u16(20) : u16(18);
    const int gps_at = ext ? 22 : (r.header.format == 1 || r.header.format >= 3 ? 20 : -1);
    const int rgb_at = ext ? (r.header.format == 7 || r.header.format == 8 || r.header.format == 10 ? 30 : -1)
                           : (r.header.format == 2 ? 20 : (r.header.format == 3 || r.header.format == 5 ? 28 : -1));
    const double gps = gps_at >= 0 ? laz::load_le<double>(p + gps_at) : 0.0;
    int rgb[3] = {0, 0, 0};
    if (rgb_at >= 0)
      for (int c = 0; c < 3; ++c) rgb[c] = u16(rgb_at + 2 * c);
    out.emplace_back(i32(0) + shift[0], i32(4) + shift[1], i32(8) + shift[2], u16(12), ret, num, cls, angle, user, gps,
                     source, rgb[0] * 65536 + rgb[1], rgb[2]);
  }
  return out;
}

void expect_same_point_set(const std::string& a_path, const std::string& b_path) {
  const Records a = records_of(a_path), b = records_of(b_path);
  ASSERT_EQ(a.header.count, b.header.count);
  std::vector<SharedFields> fa = shared_fields(a, a.header), fb = shared_fields(b, a.header);
  const bool same_order = fa == fb;
  std::sort(fa.begin(), fa.end());
  std::sort(fb.begin(), fb.end());
  std::size_t differing = 0;
  for (std::size_t i = 0; i < fa.size(); ++i) differing += fa[i] != fb[i];
  EXPECT_EQ(differing, 0u) << a_path << " and " << b_path << ": sorted points that differ, of " << fa.size();
  std::printf("%s vs %s: %s order\n", a_path.c_str(), b_path.c_str(), same_order ? "the same" : "a different");
}

TEST(Laz, CopcWithColorHoldsThePointsOfItsLasTwin) {
  REQUIRE_LAZ(copc, "1.2-with-color.copc.laz");
  REQUIRE_LAZ(las, "1.2-with-color.las");
  EXPECT_EQ(records_of(copc).header.format, 7);
  expect_same_point_set(las, copc);  // format 3 vs 7, octree order
}

TEST(Laz, LoneStarLazAndCopcHoldTheSamePoints) {
  REQUIRE_LAZ(laz, "lone-star.laz");
  REQUIRE_LAZ(copc, "lone-star.copc.laz");
  EXPECT_EQ(records_of(copc).header.format, 6);
  expect_same_point_set(laz, copc);  // format 1 (point10) vs 6 (point14, layered), 518862 points
}

TEST(Laz, DecodingDoesNotDependOnTheThreadCount) {
  REQUIRE_LAZ(laz, "autzen_trim.laz");
  std::vector<unsigned char> one, two;
  {
    const ThreadLimit limit(1);
    io_detail::read_las_point_records(laz, one);
  }
  {
    const ThreadLimit limit(2);
    io_detail::read_las_point_records(laz, two);
  }
  EXPECT_TRUE(one == two);
}

/// read_points on a LAZ and on its LAS twin: the same cloud.
TEST(Laz, ReadPointsGivesTheCloudOfTheLasTwin) {
  REQUIRE_LAZ(laz, "autzen_trim.laz");
  REQUIRE_LAZ(las, "autzen_trim.las");
  const PointCloud a = read_points(laz), b = read_points(las);
  ASSERT_EQ(a.size(), 110000u);
  EXPECT_TRUE(a.points == b.points);
  EXPECT_EQ(a.origin, b.origin);
  EXPECT_EQ(a.crs, b.crs);
  EXPECT_EQ(a.attributes.classification, b.attributes.classification);
  EXPECT_EQ(a.attributes.return_number, b.attributes.return_number);
  EXPECT_EQ(a.attributes.number_of_returns, b.attributes.number_of_returns);
  EXPECT_EQ(a.attributes.intensity, b.attributes.intensity);
  EXPECT_EQ(a.attributes.gps_time, b.attributes.gps_time);
  EXPECT_EQ(a.attributes.rgb, b.attributes.rgb);
}

/// The runs of read_point_chunks joined, checked as they come: consecutive, none empty, none longer than asked.
PointChunk streamed(const std::string& path, std::size_t chunk_points, std::string* crs = nullptr, std::size_t* runs = nullptr) {
  PointChunk all;
  std::size_t n = 0;
  const std::string c = read_point_chunks(
      path,
      [&](const PointChunk& run) {
        EXPECT_EQ(run.first, all.points.size()) << path;
        EXPECT_GE(run.points.size(), 1u);
        EXPECT_LE(run.points.size(), chunk_points);
        all.points.insert(all.points.end(), run.points.begin(), run.points.end());
        const auto append = [](auto& a, const auto& b) { a.insert(a.end(), b.begin(), b.end()); };
        append(all.attributes.classification, run.attributes.classification);
        append(all.attributes.return_number, run.attributes.return_number);
        append(all.attributes.number_of_returns, run.attributes.number_of_returns);
        append(all.attributes.intensity, run.attributes.intensity);
        append(all.attributes.gps_time, run.attributes.gps_time);
        append(all.attributes.rgb, run.attributes.rgb);
        ++n;
      },
      chunk_points);
  if (crs) *crs = c;
  if (runs) *runs = n;
  return all;
}

/// The stream holds read_points' cloud exactly: point i is its local point i plus its origin, to the bit,
/// every attribute equal, whatever the run length (a run of one point, runs cut inside LAZ chunks, the default).
void expect_stream_is_the_cloud(const std::string& path, std::size_t chunk_points) {
  SCOPED_TRACE(path + ", runs of " + std::to_string(chunk_points));
  const PointCloud cloud = read_points(path);
  std::string crs;
  std::size_t runs = 0;
  const PointChunk s = streamed(path, chunk_points, &crs, &runs);
  ASSERT_EQ(s.points.size(), cloud.size());
  // At least ceil(n / run) runs; LAZ runs also end where a LAZ chunk ends.
  EXPECT_GE(runs, (cloud.size() + chunk_points - 1) / chunk_points);
  std::size_t different = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 g = cloud.points[i] + cloud.origin;
    different += !(g.x() == s.points[i].x() && g.y() == s.points[i].y() && g.z() == s.points[i].z());
  }
  EXPECT_EQ(different, 0u);
  EXPECT_EQ(crs, cloud.crs);
  EXPECT_EQ(s.attributes.classification, cloud.attributes.classification);
  EXPECT_EQ(s.attributes.return_number, cloud.attributes.return_number);
  EXPECT_EQ(s.attributes.number_of_returns, cloud.attributes.number_of_returns);
  EXPECT_EQ(s.attributes.intensity, cloud.attributes.intensity);
  EXPECT_EQ(s.attributes.gps_time, cloud.attributes.gps_time);
  EXPECT_EQ(s.attributes.rgb, cloud.attributes.rgb);
}

TEST(PointStream, LasAndLazRunsAreReadPointsCloudToTheBit) {
  REQUIRE_LAZ(las, "autzen_trim.las");
  REQUIRE_LAZ(laz, "autzen_trim.laz");
  REQUIRE_LAZ(las14, "autzen_trim_7.las");
  for (const std::string& path : {las, laz, las14})
    for (std::size_t n : {kPointChunk, std::size_t{50000}, std::size_t{999}}) expect_stream_is_the_cloud(path, n);
}

TEST(PointStream, CopcPointwiseAndOneStreamFilesAreReadPointsCloudToTheBit) {
  for (const char* name : {"simple.las", "simple.laz", "laszip-generated.laz", "simple-laszip-compressor-version-1.2r0.laz",
                           "1.2-with-color.las", "1.2-with-color.copc.laz", "lone-star.copc.laz"}) {
    const std::string path = laz_file(name);
    if (path.empty()) continue;
    for (std::size_t n : {kPointChunk, std::size_t{7}}) expect_stream_is_the_cloud(path, n);
  }
  REQUIRE_LAZ(small, "simple.laz");
  expect_stream_is_the_cloud(small, 1);
}

TEST(PointStream, OtherFormatsAreReadWholeAndHandedOnInRuns) {
  PointCloud cloud;
  cloud.origin = Vec3(155000, 463000, 0);  // written back as file coordinates: local + origin
  for (int i = 0; i < 100; ++i) cloud.points.push_back(Vec3(0.25 * i, -0.5 * i, 0.125 * (i % 7)));
  const std::string path = (std::filesystem::temp_directory_path() / "hsr_point_stream_test.ply").string();
  write_points(path, cloud, FileEncoding::Binary);
  expect_stream_is_the_cloud(path, 9);
  std::filesystem::remove(path);
}

/// The points of the parts `wanted` names, through read_point_parts, checked as they come: every run inside one
/// wanted part, runs in file order.
std::vector<Vec3> parts_read(const std::string& path, const std::vector<PointPart>& parts, const std::vector<char>& wanted) {
  std::vector<Vec3> out;
  std::uint64_t next = 0;
  read_point_parts(path, wanted, [&](const PointChunk& run) {
    std::size_t at = 0;
    while (at < parts.size() && parts[at].first + parts[at].count <= run.first) ++at;
    EXPECT_LT(at, parts.size());
    if (at >= parts.size()) return;
    EXPECT_TRUE(wanted[at]) << "a run of an unwanted part";
    EXPECT_LE(run.first + run.points.size(), parts[at].first + parts[at].count) << "a run spans two parts";
    EXPECT_GE(run.first, next);
    next = run.first + run.points.size();
    out.insert(out.end(), run.points.begin(), run.points.end());
  });
  return out;
}

// DECISIONS #133: a file's parts (LAZ chunks, COPC nodes, runs of LAS records) cover its points once, and
// read_point_parts hands on exactly the wanted parts' points; a LAZ chunk not wanted is not decoded: with some
// chunks' bytes overwritten, the whole file fails, and the other chunks alone read as the intact file's.
TEST(PointStream, OnlyTheWantedPartsAreRead) {
  for (const char* name : {"autzen_trim.laz", "autzen_trim.las", "lone-star.laz", "lone-star.copc.laz"}) {
    const std::string path = laz_file(name);
    if (path.empty()) continue;
    SCOPED_TRACE(name);
    const std::vector<PointPart> parts = point_parts(path);
    ASSERT_GE(parts.size(), 2u);
    std::uint64_t covered = 0;
    for (const PointPart& part : parts) {
      EXPECT_EQ(part.first, covered);
      EXPECT_GT(part.count, 0u);
      covered += part.count;
    }
    std::vector<Vec3> all;
    read_point_chunks(path, [&](const PointChunk& c) { all.insert(all.end(), c.points.begin(), c.points.end()); });
    ASSERT_EQ(all.size(), covered);
    std::vector<char> odd(parts.size(), 0);
    for (std::size_t i = 1; i < parts.size(); i += 2) odd[i] = 1;
    std::vector<Vec3> want;
    for (std::size_t i = 1; i < parts.size(); i += 2)
      want.insert(want.end(), all.begin() + static_cast<std::ptrdiff_t>(parts[i].first),
                  all.begin() + static_cast<std::ptrdiff_t>(parts[i].first + parts[i].count));
    EXPECT_TRUE(parts_read(path, parts, odd) == want);
    EXPECT_TRUE(parts_read(path, parts, std::vector<char>(parts.size(), 0)).empty());
  }
  REQUIRE_LAZ(laz, "lone-star.laz");
  const std::vector<PointPart> parts = point_parts(laz);
  ASSERT_GE(parts.size(), 4u);
  std::vector<Vec3> intact;
  read_point_chunks(laz, [&](const PointChunk& c) { intact.insert(intact.end(), c.points.begin(), c.points.end()); });
  // The middle tenth of the file overwritten: the chunks there are broken.
  const std::string broken = (std::filesystem::path(HSR_TEST_TMP_DIR) / "lone-star-broken.laz").string();
  std::filesystem::copy_file(laz, broken, std::filesystem::copy_options::overwrite_existing);
  const auto size = std::filesystem::file_size(broken);
  {
    std::fstream f(broken, std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(static_cast<std::streamoff>(size * 45 / 100));
    const std::string junk(size / 10, '\xA5');
    f.write(junk.data(), static_cast<std::streamsize>(junk.size()));
  }
  EXPECT_THROW(read_point_chunks(broken, [](const PointChunk&) {}), Error);
  // A part is broken when it fails or differs read alone; the others, read together, are the intact file's.
  std::vector<char> good(parts.size(), 0);
  std::vector<Vec3> want;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    std::vector<char> one(parts.size(), 0);
    one[i] = 1;
    std::vector<Vec3> got;
    try {
      read_point_parts(broken, one, [&](const PointChunk& c) { got.insert(got.end(), c.points.begin(), c.points.end()); });
    } catch (const Error&) {
      continue;
    }
    const auto from = intact.begin() + static_cast<std::ptrdiff_t>(parts[i].first);
    if (got != std::vector<Vec3>(from, from + static_cast<std::ptrdiff_t>(parts[i].count))) continue;
    good[i] = 1;
    want.insert(want.end(), got.begin(), got.end());
  }
  const auto bad = std::count(good.begin(), good.end(), 0);
  EXPECT_GE(bad, 1);
  EXPECT_LT(bad, static_cast<std::ptrdiff_t>(parts.size()));
  std::vector<Vec3> got;
  EXPECT_NO_THROW(read_point_parts(broken, good, [&](const PointChunk& c) { got.insert(got.end(), c.points.begin(), c.points.end()); }));
  EXPECT_TRUE(got == want);
  std::filesystem::remove(broken);
}

TEST(PointStream, BadInputIsOneLineNamingTheFile) {
  REQUIRE_LAZ(las, "simple.las");
  try {
    read_point_chunks(las, [](const PointChunk&) {}, 0);
    FAIL() << "a run of no points was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadInput);
    EXPECT_NE(std::string(e.what()).find("simple.las"), std::string::npos) << e.what();
  }
  EXPECT_THROW(read_point_chunks("/nonexistent/tile.laz", [](const PointChunk&) {}), Error);
}

TEST(Laz, ChunkTableOffsetAtTheFilesEnd) {
  // A streaming compressor writes -1 where the table's offset goes and appends the offset to the file.
  REQUIRE_LAZ(laz, "autzen_trim.laz");
  REQUIRE_LAZ(las, "autzen_trim.las");
  std::string f = test::read_file(laz);
  auto* p = reinterpret_cast<unsigned char*>(f.data());
  const std::uint32_t point_offset = laz::load_le<std::uint32_t>(p + 96);
  const std::int64_t table_at = laz::load_le<std::int64_t>(p + point_offset);
  laz::store_le(p + point_offset, std::int64_t{-1});
  f.append(8, '\0');
  laz::store_le(reinterpret_cast<unsigned char*>(f.data()) + f.size() - 8, table_at);
  const auto path = test::scratch_dir("table_at_end") / "autzen.laz";
  test::write_file(path, f);
  expect_same_records(path.string(), las);
}

TEST(Laz, ChosenByContentNotByExtension) {
  REQUIRE_LAZ(laz, "simple.laz");
  const auto dir = test::scratch_dir("by_content");
  const auto renamed = dir / "simple.dat";
  std::filesystem::copy_file(laz, renamed);
  const PointCloud a = read_points(renamed.string()), b = read_points(laz);
  EXPECT_EQ(a.size(), 1065u);
  EXPECT_TRUE(a.points == b.points);
}

// ---- the LAS reader's attributes against what the headers say ------------------------------------------

/// The header's points by return (5 legacy counters; LAS 1.4: 15 64-bit counters at 255).
std::vector<std::uint64_t> header_by_return(const std::string& path) {
  const std::string h = test::read_file(path);
  const auto* p = reinterpret_cast<const unsigned char*>(h.data());
  std::vector<std::uint64_t> out;
  if (h[25] >= 4) {
    for (int i = 0; i < 15; ++i) out.push_back(laz::load_le<std::uint64_t>(p + 255 + 8 * i));
  } else {
    for (int i = 0; i < 5; ++i) out.push_back(laz::load_le<std::uint32_t>(p + 111 + 4 * i));
  }
  return out;
}

void expect_returns_match_header(const std::string& path) {
  const PointCloud c = read_points(path);
  const std::vector<std::uint64_t> header = header_by_return(path);
  ASSERT_EQ(c.attributes.return_number.size(), c.size());
  std::vector<std::uint64_t> counted(header.size(), 0);
  for (std::uint8_t r : c.attributes.return_number)
    if (r >= 1 && r <= header.size()) ++counted[r - 1];
  EXPECT_EQ(counted, header) << path;
}

TEST(LasAttributes, ReturnNumbersAgreeWithTheHeadersCounts) {
  for (const char* name : {"simple.las", "autzen_trim.las", "autzen_trim_7.las", "1.2-with-color.las", "autzen_trim.laz",
                           "lone-star.laz", "lone-star.copc.laz", "1.2-with-color.copc.laz"}) {
    REQUIRE_LAZ(path, name);
    SCOPED_TRACE(name);
    expect_returns_match_header(path);
  }
}

TEST(LasAttributes, Format7HoldsTheAttributesOfFormat3) {
  REQUIRE_LAZ(f3, "autzen_trim.las");
  REQUIRE_LAZ(f7, "autzen_trim_7.las");
  const PointCloud a = read_points(f3), b = read_points(f7);
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(a.attributes.classification, b.attributes.classification);
  EXPECT_EQ(a.attributes.return_number, b.attributes.return_number);
  EXPECT_EQ(a.attributes.number_of_returns, b.attributes.number_of_returns);
  EXPECT_EQ(a.attributes.intensity, b.attributes.intensity);
  EXPECT_EQ(a.attributes.gps_time, b.attributes.gps_time);
  EXPECT_EQ(a.attributes.rgb, b.attributes.rgb);
  std::size_t far = 0;
  for (std::size_t i = 0; i < a.size(); ++i) far += ((a.points[i] + a.origin) - (b.points[i] + b.origin)).cwiseAbs().maxCoeff() > 1e-6;
  EXPECT_EQ(far, 0u);
}

TEST(LasAttributes, KnownValuesOfAutzen) {
  REQUIRE_LAZ(path, "autzen_trim.las");
  const PointCloud c = read_points(path);
  std::map<int, std::size_t> classes;
  for (auto k : c.attributes.classification) ++classes[k];
  EXPECT_GT(classes[2], 0u) << "ground (class 2)";
  EXPECT_EQ(c.attributes.gps_time.size(), c.size());
  EXPECT_EQ(c.attributes.rgb.size(), c.size());
  EXPECT_EQ(c.attributes.intensity.size(), c.size());
  for (std::size_t i = 0; i < c.size(); ++i) {
    ASSERT_GE(c.attributes.number_of_returns[i], c.attributes.return_number[i]) << "point " << i;
    ASSERT_GE(c.attributes.return_number[i], 1) << "point " << i;
  }
  EXPECT_NE(c.crs.find("NAD83"), std::string::npos) << c.crs.substr(0, 80);
}

TEST(LasAttributes, CrsFromGeoTiffKeysWhenThereIsNoWkt) {
  REQUIRE_LAZ(path, "lone-star.laz");  // a GeoTIFF key directory, no WKT record
  // Its keys say GeographicTypeGeoKey 4326 (and no projected CRS), though the coordinates look like UTM: the
  // reader reports what the file says.
  const std::string crs = read_points(path).crs;
  EXPECT_EQ(crs, "EPSG:4326");
}

// ---- bad input ------------------------------------------------------------------------------------------

/// `bytes` written to a scratch file, read: the BadFormat message (the test fails if it reads).
std::string bad_format_message(const std::string& name, const std::string& bytes) {
  const auto path = test::scratch_dir("bad_" + name) / (name + ".laz");
  test::write_file(path, bytes);
  try {
    read_points(path.string());
  } catch (const Error& e) {
    EXPECT_EQ(e.status(), Status::BadFormat) << e.one_line();
    EXPECT_EQ(e.stage(), "io");
    EXPECT_NE(e.one_line().find(path.string()), std::string::npos) << "the message names the file: " << e.one_line();
    EXPECT_EQ(e.one_line().find('\n'), std::string::npos) << "one line";
    std::printf("%s: %s\n", name.c_str(), e.one_line().c_str());
    return e.one_line();
  }
  ADD_FAILURE() << name << ": read without an error";
  return "";
}

/// The offset of the LASzip VLR's payload in a LAS header block.
std::size_t laszip_payload_at(const std::string& f) {
  const auto* p = reinterpret_cast<const unsigned char*>(f.data());
  std::size_t at = laz::load_le<std::uint16_t>(p + 94);
  const std::uint32_t vlrs = laz::load_le<std::uint32_t>(p + 100);
  for (std::uint32_t i = 0; i < vlrs; ++i) {
    if (laz::load_le<std::uint16_t>(p + at + 18) == 22204) return at + 54;
    at += 54 + laz::load_le<std::uint16_t>(p + at + 20);
  }
  return 0;
}

TEST(LazErrors, TruncatedFile) {
  REQUIRE_LAZ(path, "autzen_trim.laz");
  const std::string f = test::read_file(path);
  EXPECT_NE(bad_format_message("cut_half", f.substr(0, f.size() / 2)).find("truncated"), std::string::npos);
  const std::size_t point_offset = laz::load_le<std::uint32_t>(reinterpret_cast<const unsigned char*>(f.data()) + 96);
  EXPECT_NE(bad_format_message("cut_head", f.substr(0, point_offset + 4)).find("more than a file of"), std::string::npos);
}

TEST(LazErrors, TruncatedStreamOfAnUnchunkedFile) {
  REQUIRE_LAZ(path, "simple-laszip-compressor-version-1.2r0.laz");  // compressor 1: one stream, no table
  const std::string f = test::read_file(path);
  EXPECT_NE(bad_format_message("cut_stream", f.substr(0, f.size() - 5000)).find("decodes past"), std::string::npos);
}

TEST(LazErrors, BrokenChunkTable) {
  REQUIRE_LAZ(path, "autzen_trim.laz");
  std::string f = test::read_file(path);
  const std::size_t point_offset = laz::load_le<std::uint32_t>(reinterpret_cast<const unsigned char*>(f.data()) + 96);
  std::string far = f;
  laz::store_le(reinterpret_cast<unsigned char*>(far.data()) + point_offset, std::int64_t{1} << 40);
  EXPECT_NE(bad_format_message("table_offset", far).find("outside"), std::string::npos);
  const std::int64_t table_at = laz::load_le<std::int64_t>(reinterpret_cast<const unsigned char*>(f.data()) + point_offset);
  std::string version = f;
  version[table_at] = 7;
  EXPECT_NE(bad_format_message("table_version", version).find("version 7"), std::string::npos);
  std::string cut = f.substr(0, f.size() - 6);  // the table's coded bytes cut
  EXPECT_NE(bad_format_message("table_cut", cut).find("chunk table"), std::string::npos);
}

TEST(LazErrors, UnknownCompressorAndItemVersion) {
  REQUIRE_LAZ(path, "simple.laz");
  const std::string f = test::read_file(path);
  const std::size_t at = laszip_payload_at(f);
  ASSERT_GT(at, 0u);
  std::string compressor = f;
  compressor[at] = 9;
  EXPECT_NE(bad_format_message("compressor", compressor).find("unknown LASzip compressor 9"), std::string::npos);
  std::string version = f;
  version[at + 34 + 4] = 7;  // POINT10's version
  EXPECT_NE(bad_format_message("item_version", version).find("POINT10 v7"), std::string::npos);
  std::string wave = f;
  wave[at + 34 + 6] = laz::kWavePacket13;  // GPSTIME11 replaced by a type we do not decode
  EXPECT_NE(bad_format_message("item_type", wave).find("unsupported LASzip item"), std::string::npos);
}

TEST(LazErrors, CountsThatDisagree) {
  REQUIRE_LAZ(path, "autzen_trim.laz");
  const std::string f = test::read_file(path);
  std::string fewer = f;  // fixed chunks of 50000: the table's third chunk has no points left
  laz::store_le(reinterpret_cast<unsigned char*>(fewer.data()) + 107, std::uint32_t{60000});
  EXPECT_NE(bad_format_message("count_fewer", fewer).find("with no points (the header declares 60000)"), std::string::npos);
  std::string more = f;  // the last chunk would need 10001 points: its bytes run out
  laz::store_le(reinterpret_cast<unsigned char*>(more.data()) + 107, std::uint32_t{110001});
  EXPECT_NE(bad_format_message("count_more", more).find("chunk 2 of 3 is bad: it decodes past"), std::string::npos);
}

TEST(LazErrors, CountsThatDisagreeWithVariableChunks) {
  REQUIRE_LAZ(path, "1.2-with-color.copc.laz");
  std::string f = test::read_file(path);
  laz::store_le(reinterpret_cast<unsigned char*>(f.data()) + 247, std::uint64_t{1000});  // LAS 1.4 point count
  EXPECT_NE(bad_format_message("count_copc", f).find("chunk table holds 1065 points, the header declares 1000"), std::string::npos);
}

TEST(LazErrors, LayeredChunkThatDisagreesWithTheTable) {
  REQUIRE_LAZ(path, "1.2-with-color.copc.laz");
  std::string f = test::read_file(path);
  const std::size_t point_offset = laz::load_le<std::uint32_t>(reinterpret_cast<const unsigned char*>(f.data()) + 96);
  const std::size_t first_chunk = point_offset + 8;
  laz::store_le(reinterpret_cast<unsigned char*>(f.data()) + first_chunk + 36, std::uint32_t{5});  // its point count
  EXPECT_NE(bad_format_message("chunk_count", f).find("it says 5 points"), std::string::npos);
  std::string short_layers = test::read_file(path);  // the XY layer claims all the chunk's bytes and more
  laz::store_le(reinterpret_cast<unsigned char*>(short_layers.data()) + first_chunk + 40, std::uint32_t{1} << 30);
  EXPECT_NE(bad_format_message("layer_size", short_layers).find("layers need"), std::string::npos);
}

TEST(LazErrors, CompressedWithoutItsLaszipRecord) {
  REQUIRE_LAZ(path, "simple.laz");
  std::string f = test::read_file(path);
  const std::size_t at = laszip_payload_at(f);
  f[at - 54 + 18] = 1;  // the record id is no longer 22204
  EXPECT_NE(bad_format_message("no_vlr", f).find("without the LASzip record"), std::string::npos);
}

}  // namespace
}  // namespace hsr
