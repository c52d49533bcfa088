// The LAS writer (io/las_writer.h) against io's own reader: coordinates on the integer grid, the attributes,
// the CRS both ways, same bytes for the same cloud, and the inputs it refuses.
#include "io/io.h"
#include "io/las_writer.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace hsr;
using namespace hsr::test;

namespace {

PointCloud sample_cloud() {
  PointCloud c;
  c.origin = Vec3(155000, 463000, 0);
  for (int i = 0; i < 200; ++i) {
    c.points.emplace_back(0.37 * i - 30, 0.011 * i * i - 50, 2.5 + std::sin(i));
    c.attributes.classification.push_back(static_cast<std::uint8_t>(i % 3 == 0 ? 2 : i % 3 == 1 ? 6 : 5));
    c.attributes.return_number.push_back(static_cast<std::uint8_t>(1 + i % 2));
    c.attributes.number_of_returns.push_back(2);
  }
  return c;
}

TEST(LasWriter, ReadsBackOnTheGridWithItsAttributesAndCrs) {
  const auto dir = scratch_dir("roundtrip");
  PointCloud c = sample_cloud();
  c.crs = "EPSG:28992";
  write_las((dir / "a.las").string(), c);
  const PointCloud r = read_points((dir / "a.las").string());
  ASSERT_EQ(r.size(), c.size());
  EXPECT_EQ(r.crs, "EPSG:28992");
  EXPECT_EQ(r.attributes.classification, c.attributes.classification);
  EXPECT_EQ(r.attributes.return_number, c.attributes.return_number);
  EXPECT_EQ(r.attributes.number_of_returns, c.attributes.number_of_returns);
  for (std::size_t i = 0; i < c.size(); ++i)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(r.points[i][k] + r.origin[k], c.points[i][k] + c.origin[k], 0.0005 + 1e-9) << i;
}

TEST(LasWriter, WritesWktAndGeographicCodes) {
  const auto dir = scratch_dir("crs");
  PointCloud c = sample_cloud();
  LasWriteParams p;
  p.crs = "PROJCS[\"test\"]";
  write_las((dir / "w.las").string(), c, p);
  EXPECT_EQ(read_points((dir / "w.las").string()).crs, "PROJCS[\"test\"]");
  p.crs = "EPSG:4326";
  write_las((dir / "g.las").string(), c, p);
  EXPECT_EQ(read_points((dir / "g.las").string()).crs, "EPSG:4326");
}

TEST(LasWriter, SameCloudSameBytes) {
  const auto dir = scratch_dir("bytes");
  const PointCloud c = sample_cloud();
  write_las((dir / "1.las").string(), c);
  write_las((dir / "2.las").string(), c);
  EXPECT_EQ(read_file(dir / "1.las"), read_file(dir / "2.las"));
}

TEST(LasWriter, RefusesWhatFormatOneCannotHold) {
  const auto dir = scratch_dir("refuse");
  PointCloud c = sample_cloud();
  EXPECT_EQ(status_of([&] { write_las((dir / "e.las").string(), PointCloud{}); }), Status::BadInput);
  c.attributes.classification[3] = 40;
  EXPECT_EQ(status_of([&] { write_las((dir / "c.las").string(), c); }), Status::BadInput);
  c = sample_cloud();
  c.points[0].x() = 1e9;
  EXPECT_EQ(status_of([&] { write_las((dir / "r.las").string(), c); }), Status::BadInput);
  LasWriteParams bad_crs;
  bad_crs.crs = "EPSG:99999999";
  EXPECT_EQ(status_of([&] { write_las((dir / "k.las").string(), sample_cloud(), bad_crs); }), Status::BadInput);
  EXPECT_EQ(count_entries(dir), 0u);  // nothing left behind
}

}  // namespace
