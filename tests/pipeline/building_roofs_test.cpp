// Building mode on the roofs real surveys hold (issue 24): one flat roof alone is a prism, a sparse steep
// gable or hip house gets both halves of its roof and its walls, the ground comes from a raster or from the
// file's classified ground points, and a model is never a slab much thinner than the points it stands for.
#include "core/error.h"
#include "core/face_class.h"
#include "core/hull2d.h"
#include "core/log.h"
#include "core/raster.h"
#include "eval/eval.h"
#include "pipeline/pipeline.h"
#include "io/io.h"
#include "synth/synth.h"
#include "test_meshes.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <random>

using namespace hsr;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Path of a scan in ../shared/airborne_more (beside ../shared/airborne), or "" when it is absent (the test skips).
std::string airborne_more(const std::string& file) {
  if (test::shared_airborne("").empty()) return {};
  const std::filesystem::path p = std::filesystem::path(test::shared_airborne("")) / ".." / "airborne_more" / file;
  return std::filesystem::exists(p) ? p.string() : std::string();
}

/// The convex hull of the scan's points in plan as its footprint (a footprint as hsr city gives one).
Footprint hull_footprint(const PointCloud& cloud) {
  std::vector<Vec2> plan;
  for (const Vec3& p : cloud.points) plan.emplace_back(p.x(), p.y());
  return {{convex_hull_2d(plan), {}}};
}

/// Step 7's run (try_gable_halves: gable_halves, two_surface_planes) split one candidate and its valid model was kept.
void step7_split_one_candidate_and_kept(const PipelineResult& r) {
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  ASSERT_TRUE(r.report["scene"].contains("gable_halves"));
  const nlohmann::json& g = r.report["scene"]["gable_halves"];
  EXPECT_EQ(g["candidates"], 1);
  EXPECT_TRUE(g["kept"].get<bool>()) << g.dump();
}

/// Half density: every other point of `full` with its normal, from point `first` (0: the even points, 1: the odd).
PointCloud every_other_point(const PointCloud& full, std::size_t first) {
  PointCloud half;
  half.origin = full.origin;
  for (std::size_t i = first; i < full.size(); i += 2) {
    half.points.push_back(full.points[i]);
    half.normals.push_back(full.normals[i]);
  }
  return half;
}

/// A rectangle w x d turned by `angle` about (cx, cy): its corners, counter-clockwise.
std::vector<Vec2> rectangle(double cx, double cy, double w, double d, double angle) {
  const Vec2 u(std::cos(angle), std::sin(angle)), v(-u.y(), u.x());
  const Vec2 c(cx, cy);
  return {c - 0.5 * w * u - 0.5 * d * v, c + 0.5 * w * u - 0.5 * d * v, c + 0.5 * w * u + 0.5 * d * v,
          c - 0.5 * w * u + 0.5 * d * v};
}

/// The prism over a convex counter-clockwise outline from z0 to z1, faces outward.
PolygonMesh prism(const std::vector<Vec2>& outline, double z0, double z1) {
  PolygonMesh m;
  const auto n = static_cast<std::uint32_t>(outline.size());
  for (const Vec2& p : outline) m.vertices.emplace_back(p.x(), p.y(), z0);
  for (const Vec2& p : outline) m.vertices.emplace_back(p.x(), p.y(), z1);
  std::vector<std::uint32_t> bottom, top;
  for (std::uint32_t i = 0; i < n; ++i) {
    bottom.push_back(n - 1 - i);
    top.push_back(n + i);
    m.faces.push_back({i, (i + 1) % n, n + (i + 1) % n, n + i});
  }
  m.faces.push_back(bottom);
  m.faces.push_back(top);
  return m;
}

bool inside_convex(const std::vector<Vec2>& poly, const Vec2& p) {
  for (std::size_t i = 0; i < poly.size(); ++i) {
    const Vec2 a = poly[i], b = poly[(i + 1) % poly.size()];
    if ((b - a).x() * (p - a).y() - (b - a).y() * (p - a).x() < 0) return false;
  }
  return true;
}

/// Points on the horizontal polygon at height z, on a jittered grid of `density` points per m², with
/// vertical noise sigma; normals up.
void sample_flat(PointCloud& cloud, const std::vector<Vec2>& poly, double z, double density, double sigma,
                 std::mt19937_64& rng) {
  BBox b;
  for (const Vec2& p : poly) b.extend(Vec3(p.x(), p.y(), z));
  const double step = 1.0 / std::sqrt(density);
  std::uniform_real_distribution<double> jitter(-0.4 * step, 0.4 * step);
  std::normal_distribution<double> noise(0.0, sigma);
  for (double x = b.min.x() + 0.5 * step; x < b.max.x(); x += step)
    for (double y = b.min.y() + 0.5 * step; y < b.max.y(); y += step) {
      const Vec2 p(x + jitter(rng), y + jitter(rng));
      if (!inside_convex(poly, p)) continue;
      cloud.points.emplace_back(p.x(), p.y(), z + noise(rng));
      cloud.normals.emplace_back(0, 0, 1);
    }
}

/// The smallest width of points in plan over 180 directions (a slab standing for a house has a small one).
double plan_width(const std::vector<Vec3>& pts) {
  double best = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 180; ++a) {
    const Vec2 u(std::cos(a * kPi / 180), std::sin(a * kPi / 180));
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (const Vec3& p : pts) {
      lo = std::min(lo, u.dot(p.head<2>()));
      hi = std::max(hi, u.dot(p.head<2>()));
    }
    best = std::min(best, hi - lo);
  }
  return best;
}

PipelineResult reconstruct(const PointCloud& cloud, const PolygonMesh* truth, SceneParams scene = {},
                           const Raster* raster = nullptr) {
  PipelineParams pp;
  pp.scene = scene;
  pp.truth = truth;
  pp.ground_raster = raster;
  pp.eval.mesh_samples = 50000;
  return run_pipeline(cloud, pp);
}

// A flat roof, 9 x 6 m turned by 20 degrees, 8 m above the ground, seen from the air at 8 points/m²: its
// roof alone in the scan.
struct FlatRoof {
  std::vector<Vec2> outline = rectangle(3.0, -2.0, 9.0, 6.0, 20.0 * kPi / 180.0);
  double height = 8.0;
  PointCloud cloud;
  FlatRoof() {
    std::mt19937_64 rng(7);
    sample_flat(cloud, outline, height, 8.0, 0.03, rng);
  }
};

// An outer wall through the outermost of its outline points (RecoveryParams::wall_edge_quantile, DECISIONS #167):
// a flat 12 x 8 m roof at 6 m, seen at 2 points/m² (a half-density survey), its points on a jittered grid. The roof's
// edge lies beyond its outermost points; with the wall through them the model is nearer the truth in plan than
// with the wall where 0.9 of them are inside (#54), which leaves a strip of the roof and its points outside.
TEST(BuildingRoofs, AnOuterWallStandsThroughTheOutermostOutlinePoint) {
  const std::vector<Vec2> outline = rectangle(0.0, 0.0, 12.0, 8.0, 0.0);
  PointCloud cloud;
  std::mt19937_64 rng(11);
  sample_flat(cloud, outline, 6.0, 2.0, 0.03, rng);
  const PolygonMesh truth = prism(outline, 0.0, 6.0);
  SceneParams given;
  given.building.ground_z = 0.0;
  const PipelineResult r = reconstruct(cloud, &truth, given);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const BBox points = bounding_box(cloud.points), model = bounding_box(r.mesh.vertices);
  for (int a = 0; a < 2; ++a) {
    EXPECT_LE(model.min[a], points.min[a] + 1e-6) << "axis " << a << ": every roof point inside the walls";
    EXPECT_GE(model.max[a], points.max[a] - 1e-6) << "axis " << a;
  }
  PipelineParams pp;
  pp.scene = given;
  pp.truth = &truth;
  pp.eval.mesh_samples = 50000;
  pp.recovery.wall_edge_quantile = 0.9;
  const PipelineResult inside = run_pipeline(cloud, pp);
  ASSERT_TRUE(inside.eval.validity.valid()) << inside.eval.validity.summary();
  const BBox narrow = bounding_box(inside.mesh.vertices);
  EXPECT_GT(narrow.min.x() + narrow.min.y() - narrow.max.x() - narrow.max.y(),
            model.min.x() + model.min.y() - model.max.x() - model.max.y() + 0.1) << "the test no longer shows the cause";
  EXPECT_LT(r.eval.accuracy.truth_to_mesh_mean, inside.eval.accuracy.truth_to_mesh_mean);
  EXPECT_GT(r.eval.validity.volume, inside.eval.validity.volume);
}

TEST(BuildingRoofs, ASingleFlatRoofIsItsPrismOnTheGivenGround) {
  const FlatRoof roof;
  const PolygonMesh truth = prism(roof.outline, 0.0, roof.height);
  // The checks would fail for the points' box: it is 30 % larger in plan than the turned roof.
  const BBox box = bounding_box(roof.cloud.points);
  ASSERT_GT(box.size().x() * box.size().y(), 1.3 * 54.0);
  SceneParams given;
  given.building.ground_z = 0.0;
  const PipelineResult r = reconstruct(roof.cloud, &truth, given);  // `auto`: a roof-only scan is a building
  EXPECT_EQ(r.report["scene"]["mode"], "building") << r.report["scene"]["reason"];
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_NEAR(r.eval.validity.volume / test::volume_of(truth), 1.0, 0.04);
  EXPECT_LT(r.eval.accuracy.truth_to_mesh_mean, 0.004) << "a wall or the roof is missing";
  EXPECT_LT(r.eval.accuracy.mesh_to_truth_mean, 0.004) << "the model reaches beyond the prism";
  EXPECT_EQ(r.mesh.num_faces(), 6u) << "a prism over a rectangle: roof, ground, four walls";
}

TEST(BuildingRoofs, AFlatRoofAloneWithoutGroundStandsOnAnAssumedStorey) {
  const FlatRoof roof;
  const PipelineResult r = reconstruct(roof.cloud, nullptr);
  EXPECT_EQ(r.report["scene"]["ground_source"], "assumed storey");
  EXPECT_NE(r.report["scene"]["ground_note"].get<std::string>().find("--ground-z"), std::string::npos);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const SceneParams defaults;
  const PolygonMesh truth = prism(roof.outline, roof.height - defaults.building.assumed_wall_height, roof.height);
  EXPECT_NEAR(r.eval.validity.volume / test::volume_of(truth), 1.0, 0.05);
}

TEST(BuildingRoofs, TheGroundFromARaster) {
  FlatRoof roof;
  // A terrain model 1.5 m above the file's zero, sloping 1 % along x, 0.5 m cells, covering the roof.
  Raster dtm;
  dtm.x0 = -10;
  dtm.y0 = 10;
  dtm.dx = 0.5;
  dtm.dy = -0.5;
  dtm.width = 60;
  dtm.height = 50;
  dtm.source = "test.tif";
  for (int row = 0; row < dtm.height; ++row)
    for (int col = 0; col < dtm.width; ++col) dtm.z.push_back(static_cast<float>(1.5 + 0.01 * (dtm.x0 + (col + 0.5) * dtm.dx)));
  const PipelineResult r = reconstruct(roof.cloud, nullptr, {}, &dtm);
  EXPECT_EQ(r.report["scene"]["ground_source"], "raster");
  // The median under the roof, whose centre is at x = 3: 1.53, on the box grid (diagonal / 1000).
  EXPECT_NEAR(r.report["scene"]["ground_z"].get<double>(), 1.53, 0.03);
  EXPECT_NEAR(bounding_box(r.mesh.vertices).min.z(), 1.53, 0.03);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
}

TEST(BuildingRoofs, TheGroundFromTheFilesClassifiedGroundPoints) {
  FlatRoof roof;
  std::mt19937_64 rng(3);
  PointCloud cloud = roof.cloud;
  cloud.attributes.classification.assign(cloud.size(), 6);
  // Ground (class 2) at z = 0.7 in a band 1-5 m around the roof; a tree (class 5) beside it.
  const std::vector<Vec2> wide = rectangle(3.0, -2.0, 19.0, 16.0, 20.0 * kPi / 180.0);
  PointCloud band;
  sample_flat(band, wide, 0.7, 4.0, 0.03, rng);
  for (const Vec3& p : band.points) {
    const Vec2 q = p.head<2>();
    if (inside_convex(rectangle(3.0, -2.0, 11.0, 8.0, 20.0 * kPi / 180.0), q)) continue;
    cloud.points.push_back(p);
    cloud.normals.emplace_back(0, 0, 1);
    cloud.attributes.classification.push_back(2);
  }
  std::normal_distribution<double> crown(0.0, 1.2);
  for (int i = 0; i < 300; ++i) {
    cloud.points.emplace_back(12.0 + crown(rng), 5.0 + crown(rng), 9.0 + crown(rng));
    cloud.normals.emplace_back(0, 0, 1);
    cloud.attributes.classification.push_back(5);
  }
  const PolygonMesh truth = prism(roof.outline, 0.7, roof.height);
  const PipelineResult r = reconstruct(cloud, &truth);
  EXPECT_EQ(r.report["scene"]["mode"], "building");
  EXPECT_NE(r.report["scene"]["reason"].get<std::string>().find("class 6"), std::string::npos);
  EXPECT_EQ(r.report["scene"]["ground_source"], "classified ground points");
  EXPECT_NEAR(r.report["scene"]["ground_z"].get<double>(), 0.7, 0.03);
  EXPECT_EQ(r.report["counts"]["class_left_out_points"], 300);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_NEAR(r.eval.validity.volume / test::volume_of(truth), 1.0, 0.04) << "the tree (class 5) is no part of it";
  EXPECT_LT(r.eval.accuracy.mesh_to_truth_mean, 0.004);
}

TEST(BuildingRoofs, SparseSteepGableAndHipHousesGetTheirWholeRoof) {
  // aerial_steep: 45-60 degree gable or hip roofs, here at 4 points/m² (Vaihingen), no ground, no trees.
  int gables = 0, hips = 0;
  for (std::uint64_t seed = 1; seed <= 6; ++seed) {
    SynthParams p;
    p.seed = seed;
    p.aerial_density = 4.0;
    p.aerial_ground = 0;
    p.aerial_trees = 0;
    const SynthScan scan = run_synth("aerial_steep", p);
    std::size_t roof_planes = 0;
    for (const SynthPlane& pl : scan.planes) roof_planes += std::abs(pl.plane.normal.z()) > 0.3 && pl.plane.normal.z() > 0 && pl.plane.normal.z() < 0.75;
    (roof_planes >= 4 ? hips : gables) += 1;
    const PipelineResult r = reconstruct(scan.cloud, &scan.truth);
    const std::string what = "seed " + std::to_string(seed);
    EXPECT_EQ(r.report["scene"]["mode"], "building") << what << ": " << r.report["scene"]["reason"];
    EXPECT_TRUE(r.eval.validity.valid()) << what << ": " << r.eval.validity.summary();
    // Both halves (every roof plane): each true roof plane holding a plane's worth of points (30, the
    // smallest plane detection takes) has its points on the model, their median within 0.3 m (r ~ 0.5 m).
    for (std::size_t k = 0; k < scan.planes.size(); ++k) {
      if (!(scan.planes[k].plane.normal.z() > 0.3) || scan.planes[k].points < 30) continue;
      std::vector<Vec3> on;
      for (std::size_t i = 0; i < scan.cloud.size(); ++i)
        if (scan.point_plane[i] == static_cast<int>(k)) on.push_back(scan.cloud.points[i]);
      std::vector<double> d = point_mesh_distances(on, r.mesh);
      std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
      EXPECT_LT(d[d.size() / 2], 0.3) << what << ": roof plane " << k << " (" << on.size() << " points) is missing";
    }
    // The whole house: 2 % (a lean-to shed of fewer than 30 points, seed 6, is below any plane and missed).
    EXPECT_LT(r.eval.accuracy.truth_to_mesh_mean, 0.02) << what << ": a roof half or a wall is missing";
    EXPECT_LT(r.eval.accuracy.mesh_to_truth_mean, 0.015) << what << ": a part was added";
    EXPECT_NEAR(r.eval.validity.volume / test::volume_of(scan.truth), 1.0, 0.1) << what;
    // Never a slab: the model is as wide in plan as the building (the points' own width is a little less).
    EXPECT_GT(plan_width(r.mesh.vertices), 0.9 * plan_width(scan.truth.vertices)) << what << ": a thin slab";
  }
  EXPECT_GT(gables, 0);
  EXPECT_GT(hips, 0);
}

// A lean-to roof, 8 x 5 m rising 25 degrees, 3 to 5.3 m over the ground at z = 0, among a tree's points
// (as many as 0.7 of the roof's, scattered in a ball beside it): one plane, and more than a third of the
// points on none. Object mode could enclose nothing with one plane ("all parallel"); `auto` takes it for the
// roof it is, and the model is the roof's prism on the ground, as wide as the roof, the tree left out.
TEST(BuildingRoofs, ALeanToRoofAloneAmongTreesIsABuilding) {
  const std::vector<Vec2> outline = rectangle(0.0, 0.0, 8.0, 5.0, 0.0);
  const double slope = std::tan(25.0 * kPi / 180.0), z0 = 3.0;  // z = z0 + slope (x + 4)
  std::mt19937_64 rng(11);
  PointCloud cloud;
  sample_flat(cloud, outline, 0.0, 6.0, 0.02, rng);
  const Vec3 up = Vec3(-slope, 0.0, 1.0).normalized();
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    cloud.points[i].z() += z0 + slope * (cloud.points[i].x() + 4.0);
    cloud.normals[i] = up;
  }
  const std::size_t roof_points = cloud.size();
  std::normal_distribution<double> g(0.0, 1.0);
  while (cloud.size() < roof_points + roof_points * 7 / 10) {
    const Vec3 d(g(rng), g(rng), g(rng));
    const double rad = 2.5 * std::cbrt(std::uniform_real_distribution<double>(0.0, 1.0)(rng));
    cloud.points.push_back(Vec3(7.5, 1.0, 6.0) + rad * d.normalized());
    cloud.normals.push_back(Vec3(g(rng), g(rng), g(rng)).normalized());
  }
  SceneParams given;
  given.building.ground_z = 0.0;
  const PipelineResult r = reconstruct(cloud, nullptr, given);
  ASSERT_LT(r.report["scene"]["roof_share"].get<double>(), SceneParams{}.auto_min_roof_share)
      << "the test needs a scan rule (a) alone would call an object";
  EXPECT_EQ(r.report["scene"]["mode"], "building") << r.report["scene"]["reason"];
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const double volume = 8.0 * 5.0 * (z0 + 4.0 * slope);  // the lean-to's: area x mean height
  EXPECT_NEAR(r.eval.validity.volume / volume, 1.0, 0.1) << "the tree is in the model, or a part is missing";
  const BBox box = bounding_box(r.mesh.vertices);
  EXPECT_LT(box.max.x(), 4.6) << "the tree is in the model";
  EXPECT_GT(plan_width(r.mesh.vertices), 0.9 * 5.0) << "a thin slab";
  // The same scan stood on its side (the plane 65 degrees from horizontal) is no roof: still an error.
  PointCloud side = cloud;
  for (std::size_t i = 0; i < side.size(); ++i) {
    side.points[i] = Vec3(side.points[i].z(), side.points[i].y(), -side.points[i].x());
    side.normals[i] = Vec3(side.normals[i].z(), side.normals[i].y(), -side.normals[i].x());
  }
  EXPECT_THROW(reconstruct(side, nullptr), Error);
}

// A flat-roofed house, 10 x 8 m and 6 m high, with a garage against one side, 4 m wide and 2.3 m high, and a
// low strip 1.5 m wide, 14 m long and 1.8 m high (a wall top, a row of cars) against the other, seen from the
// air at 2 points/m² (r ~ 0.85 m: "low" is under 4 r = 3.4 m, "off the ground" above 2 r = 1.7 m), or a
// patch of terrain 0.3 m high against a third side; the walls were not scanned. The garage's eave meets the
// house's in plan only: no garage point is among the house's nearest neighbours, a storey lies between them.
// Wider than a car, off the ground and touching the house, it is a wing of the building; the strip, off the
// ground and touching the house but narrower than a car, and the patch, within 2 r of the ground, stay out.
TEST(BuildingRoofs, ALowGarageAgainstTheHouseIsPartOfItACarWideStripIsNot) {
  // With the garage (x 5..9) the strip (x -6.5..-5, 1.8 m high); without it, the terrain patch (y -9.25..-4.25,
  // 0.3 m: with the garage, two low planes on two sides would pass for a ground).
  for (const bool strip : {true, false}) {
    std::mt19937_64 rng(5);
    PointCloud cloud;
    sample_flat(cloud, rectangle(0.0, 0.0, 10.0, 8.0, 0.0), 6.0, 2.0, 0.02, rng);
    if (strip) {
      sample_flat(cloud, rectangle(7.0, 0.0, 4.0, 6.0, 0.0), 2.3, 2.0, 0.02, rng);
      sample_flat(cloud, rectangle(-5.75, 0.0, 1.5, 14.0, 0.0), 1.8, 2.0, 0.02, rng);
    } else {
      sample_flat(cloud, rectangle(0.0, -6.75, 8.0, 5.0, 0.0), 0.3, 2.0, 0.02, rng);
    }
    SceneParams given;
    given.building.ground_z = 0.0;
    const PipelineResult r = reconstruct(cloud, nullptr, given);
    const std::string beside = strip ? "the strip" : "the terrain patch";
    EXPECT_TRUE(r.eval.validity.valid()) << beside << ": " << r.eval.validity.summary();
    EXPECT_EQ(r.report["scene"]["planes"]["clutter"], 1) << beside << " alone is clutter";
    const BBox box = bounding_box(r.mesh.vertices);
    if (strip) EXPECT_GT(box.max.x(), 8.5) << "the garage is missing";
    EXPECT_GT(box.min.x(), -5.2) << beside << " is in the model";
    EXPECT_GT(box.min.y(), -4.5) << beside << " is in the model";
    const double volume = 10.0 * 8.0 * 6.0 + (strip ? 4.0 * 6.0 * 2.3 : 0.0);
    EXPECT_NEAR(r.eval.validity.volume / volume, 1.0, 0.1) << beside;
  }
}

// A flat-roofed house (10 x 8 m, 8 m high) with, along one side, a flat strip as narrow as a car (1.9 m) but
// 2.4 m over the ground and 8 m long: a storey's lean-to, no car; the walls not scanned. At 2 points/m² "low" (4 r) reaches 3.4 m, so the strip is low and, under
// car_max_width, was taken for a car (AHN3_16804 at half density: a 1.9 m wide flat strip 2.5 m up, 54 points,
// left out, p2m 8 %). Standing higher than a car (car_max_height), it is a wing of the building.
TEST(BuildingRoofs, ANarrowLowStripHigherThanACarIsAWing) {
  for (const double height : {2.4, 1.8}) {  // higher than a car (2 m), as high as one
    std::mt19937_64 rng(5);
    PointCloud cloud;
    sample_flat(cloud, rectangle(0.0, 0.0, 10.0, 8.0, 0.0), 8.0, 2.0, 0.02, rng);
    sample_flat(cloud, rectangle(-5.95, 0.0, 1.9, 8.0, 0.0), height, 2.0, 0.02, rng);
    SceneParams given;
    given.building.ground_z = 0.0;
    const PipelineResult r = reconstruct(cloud, nullptr, given);
    ASSERT_LT(height, given.building.building_min_height * r.report["resolved"]["structure"]["spacing"].get<double>())
        << "the test needs a low strip";
    EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
    const BBox box = bounding_box(r.mesh.vertices);
    if (height > 2.0) {
      EXPECT_LT(box.min.x(), -6.4) << "the strip " << height << " m high is left out";
      EXPECT_NEAR(r.eval.validity.volume / (10.0 * 8.0 * 8.0 + 1.9 * 8.0 * height), 1.0, 0.1);
    } else {
      EXPECT_GT(box.min.x(), -5.2) << "the strip " << height << " m high, a car's, is in the model";
    }
  }
}

// A house (12 x 8 m, flat roof at 7 m) with a flat wing (6 x 5 m) at 3 m on one side, on ground scanned all
// round at z = 0, 4 points/m² (r ~ 0.6 m). The wing lies within 6 r of the lowest points, where ground planes
// are looked for, but it stands more than 4 r (what a roof rises over the ground) above the ground plane: a
// low roof, not a second ground. Taken for ground it was left out (AHN3_16764: a 65-point wing 2.9 m over a
// 34-point ground plane, which also set the ground's height to its own).
TEST(BuildingRoofs, ALowWingIsNoSecondGround) {
  std::mt19937_64 rng(3);
  PointCloud cloud;
  const std::vector<Vec2> house = rectangle(0.0, 0.0, 12.0, 8.0, 0.0), wing = rectangle(0.0, 6.5, 6.0, 5.0, 0.0);
  sample_flat(cloud, house, 7.0, 4.0, 0.02, rng);
  sample_flat(cloud, wing, 3.0, 4.0, 0.02, rng);
  PointCloud ground;
  sample_flat(ground, rectangle(0.0, 2.0, 30.0, 30.0, 0.0), 0.0, 4.0, 0.02, rng);
  for (std::size_t i = 0; i < ground.size(); ++i) {
    const Vec2 p = ground.points[i].head<2>();
    if (inside_convex(house, p) || inside_convex(wing, p)) continue;
    cloud.points.push_back(ground.points[i]);
    cloud.normals.push_back(ground.normals[i]);
  }
  const PipelineResult r = reconstruct(cloud, nullptr);
  EXPECT_EQ(r.report["scene"]["ground_source"], "plane");
  EXPECT_NEAR(r.report["scene"]["ground_z"].get<double>() + cloud.origin.z(), 0.0, 0.1) << "the wing is taken for ground";
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const BBox box = bounding_box(r.mesh.vertices);
  EXPECT_GT(box.max.y() + cloud.origin.y(), 8.5) << "the wing is missing";
  const double volume = 12.0 * 8.0 * 7.0 + 6.0 * 5.0 * 3.0;
  EXPECT_NEAR(r.eval.validity.volume / volume, 1.0, 0.1);
}

// The forced fallback (extraction.cpp force_best_cell_inside): Vaihingen_00021 (187 points, one roof plane
// of 49, one wall recovered) on City3D's ground, 2.8 m under its lowest point, ended "no cell labelled
// inside": no cell won by being inside (the roof's votes against the tall box's closure faces). The cell
// most points vote inside is kept, with what lies under it: the house, not a sliver.
TEST(BuildingRoofs, ASmallRoofHighOverItsGivenGroundStillStandsOnIt) {
  const std::string path = airborne_more("Vaihingen_00021.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams pp;
  pp.scene.mode = SceneMode::Building;
  pp.scene.building.ground_z = 265.0 - cloud.origin.z();  // City3D's ground, in the cloud's local frame
  const PipelineResult r = run_pipeline(cloud, pp);
  EXPECT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const BBox box = bounding_box(r.mesh.vertices), points = bounding_box(cloud.points);
  EXPECT_NEAR(box.min.z(), pp.scene.building.ground_z, 0.05);  // it stands on the given ground
  // As wide as the roof's points in plan (a sliver cell would be a fraction of it).
  EXPECT_GT((box.max - box.min).head<2>().prod(), 0.5 * (points.max - points.min).head<2>().prod());
}


// A building reconstructed in its own frame (BuildingParams::own_frame, off by default): Dales3d_00281 turned 37 degrees
// about z lost its 38-point hip-end slope (the partition's axis-aligned box left a wedge under it that the
// min-cut kept outside: 75 of 396 points to explain unexplained). In its own frame the turned scan gives the
// model of the scan as shared, turned: every point explained, the same volume; without the rule the slope is
// lost again.
TEST(BuildingRoofs, ATurnedBuildingKeepsEveryRoofPart) {
  const std::string path = airborne_more("Dales3d_00281.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  const double a = 37.0 * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  PointCloud turned = cloud;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3& p = cloud.points[i];
    const Vec3& n = cloud.normals[i];
    turned.points[i] = Vec3(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z());
    turned.normals[i] = Vec3(c * n.x() - s * n.y(), s * n.x() + c * n.y(), n.z());
  }
  PipelineParams on;
  on.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  on.scene.building.left_out_roof_walls = false;  // and #159's walls around the slope, apart
  on.scene.building.own_frame = true;
  on.recovery.partner_max_behind = -1;  // #177 apart: with it the turned scan's own-frame run leaves 12 % unexplained
  const PipelineResult as_shared = run_pipeline(cloud, on);
  const PipelineResult r = run_pipeline(turned, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["counts"]["points_unexplained"].get<int>(), as_shared.report["counts"]["points_unexplained"].get<int>());
  EXPECT_LT(r.report["quality"]["points_unexplained_share"].get<double>(), 0.01);
  EXPECT_NEAR(r.eval.validity.volume / as_shared.eval.validity.volume, 1.0, 0.01);
  EXPECT_TRUE(r.report["scene"].contains("own_frame_turn_deg"));
  PipelineParams off;
  off.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  off.scene.building.left_out_roof_walls = false;
  off.scene.building.own_frame = false;
  const PipelineResult lost = run_pipeline(turned, off);
  EXPECT_GT(lost.report["quality"]["points_unexplained_share"].get<double>(), 0.1) << "the test no longer shows the cause";
}

}  // namespace

// A building's small planes (BuildingParams::small_plane_points, off by default; issue 42 item 3): AHN3_09896 at
// half density (every other point) has one roof half on a plane of 30 points or more and the other under it: the
// model is a lean-to over one half (p2m 3.1 %). Searched again among the points on no plane with planes of 13,
// the other half is a plane that touches the first: a roof, and the model has both halves (p2m 0.28 %).
TEST(BuildingRoofs, ASmallRoofPartAtHalfDensityIsModelled) {
  const std::string path = airborne_more("AHN3_09896.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud full = read_points(path);
  const PointCloud half = every_other_point(full, 1);
  PipelineParams on;
  on.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  on.scene.building.small_plane_points = 13;
  const PipelineResult r = run_pipeline(half, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["counts"]["small_planes"].get<int>(), 1);
  EXPECT_EQ(r.report["scene"]["planes"]["roof"].get<int>(), 2);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.005);
  // The kept run's mesh -> points figures are measured at the end only (run_eval's MeshToPoints::Later, issue 43):
  // the same as an evaluation of the model at once, in the result and in the report.
  const EvalResult at_once = run_eval(half, r.mesh, nullptr, on.eval);
  EXPECT_FALSE(r.eval.m2p_later);
  EXPECT_EQ(r.eval.accuracy.m2p_mean, at_once.accuracy.m2p_mean);
  EXPECT_EQ(r.eval.accuracy.m2p_max, at_once.accuracy.m2p_max);
  EXPECT_EQ(r.report["accuracy"]["m2p_mean"].get<double>(), at_once.accuracy.m2p_mean);
  PipelineParams off;
  off.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  off.scene.building.small_plane_points = 0;
  const PipelineResult without = run_pipeline(half, off);
  EXPECT_EQ(without.report["scene"]["planes"]["roof"].get<int>(), 1) << "the test no longer shows the cause";
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.02);
}

// Step 5's runs (BuildingParams::finer_outline_points, #116) run at once when the run has more than one thread
// (run_finer_outlines, DECISIONS #157), each stopped when it finds the first run's segments, with step 6's run on
// the first run's segments beside them (#163), and one after the other with one thread: the same runs tried, the
// same ones kept, the same model. Vaihingen_00002 keeps step 5's second run (outline segments of 4 points), so
// step 6 runs again on those; AHN3_00061 keeps no finer outline and keeps step 6's run made beside step 5's.
TEST(BuildingRoofs, FinerOutlineRunsAtOnceKeepWhatOneAfterTheOtherKeeps) {
  const std::string more = (std::filesystem::path(test::shared_airborne("")) / ".." / "airborne_more").string();
  if (test::shared_airborne("").empty() || !std::filesystem::exists(more)) GTEST_SKIP() << "../shared/airborne_more not found";
  for (const bool box_walls : {false, true})  // #183's second pass apart (the cases below), then with it
  for (const char* name : {"Vaihingen_00002", "AHN3_00061"}) {
    SCOPED_TRACE(std::string(name) + (box_walls ? ", box_face_roof_walls" : ""));
    PipelineParams one, two;
    one.threads = 1;
    two.threads = 2;
    one.scene.building.box_face_roof_walls = two.scene.building.box_face_roof_walls = box_walls;
    const PointCloud cloud = read_points((std::filesystem::path(more) / (std::string(name) + ".ply")).string());
    const PipelineResult a = run_pipeline(cloud, one), b = run_pipeline(cloud, two);
    const nlohmann::json& finer = a.report["scene"]["finer_outline"];
    ASSERT_TRUE(finer.is_object());
    const bool finer_kept = finer["kept_segment_points"].get<int>() != one.structure.min_segment_points;
    const nlohmann::json& tighter = a.report["scene"]["tighter_planes"];
    ASSERT_TRUE(tighter.is_object());
    if (!box_walls) {
      EXPECT_EQ(finer_kept, std::string(name) == "Vaihingen_00002") << "the test no longer shows both cases";
      if (!finer_kept) EXPECT_TRUE(tighter["kept"].get<bool>()) << "step 6's run beside step 5's is not shown kept";
    }
    EXPECT_EQ(finer, b.report["scene"]["finer_outline"]);
    nlohmann::json tighter_two = b.report["scene"]["tighter_planes"];
    EXPECT_FALSE(tighter.contains("beside")) << "one thread: no run beside";
    if (!finer_kept) EXPECT_EQ(tighter_two.value("beside", std::string()), "step 5");  // DECISIONS #201's report
    tighter_two.erase("beside");
    EXPECT_EQ(tighter, tighter_two);
    EXPECT_EQ(a.mesh.vertices, b.mesh.vertices);
    EXPECT_EQ(a.mesh.faces, b.mesh.faces);
    EXPECT_EQ(a.report["accuracy"], b.report["accuracy"]);
  }
}

// A small upright plane under an eave is no wall (BuildingParams::small_wall_max_overhang; DECISIONS #107):
// AHN3_01218 as shared is a flat roof whose 16 scanned wall points, found among the points on no plane, stand
// 0.8 r inside the roof's outermost points while the roof reaches 9 r beyond them on the inner side. Kept as a
// wall, it explains that roof side, whose recovered wall at the eave goes (4 -> 3 recovered walls) and the
// model's wall moves inside the eave line. With the overhang test it stays clutter and the four walls of the
// roof's outline are recovered.
TEST(BuildingRoofs, ASmallWallUnderAnEaveIsNoWall) {
  const std::string path = airborne_more("AHN3_01218.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams on;
  on.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  on.scene.building.small_plane_points = 13;
  on.scene.building.small_wall_max_overhang = 0.5;
  const PipelineResult r = run_pipeline(cloud, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["counts"]["small_planes"].get<int>(), 1);
  EXPECT_EQ(r.report["scene"]["planes"]["wall"].get<int>(), 0);
  EXPECT_EQ(r.report["counts"]["recovered_planes"].get<int>(), 4);
  PipelineParams untested = on;
  untested.scene.building.small_wall_max_overhang = -1.0;
  const PipelineResult kept = run_pipeline(cloud, untested);
  EXPECT_EQ(kept.report["scene"]["planes"]["wall"].get<int>(), 1) << "the test no longer shows the cause";
  EXPECT_EQ(kept.report["counts"]["recovered_planes"].get<int>(), 3);
}

// A small plane too steep for a roof is none (BuildingParams::small_roof_max_slope_deg; DECISIONS #107):
// AHN3_00989 as shared gets four small planes; one, on the side of its tall chimney-like block, is tilted about
// 73 degrees from level, too little for a wall. Kept as a roof, it cuts the main roof's corner (City3D -> hsr on
// City3D's ground 0.32 -> 0.59 %); with the slope test it stays clutter and the model is the one without small
// planes, plus the small planes that fit.
TEST(BuildingRoofs, ASmallPlaneTooSteepForARoofIsNone) {
  const std::string path = airborne_more("AHN3_00989.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams on;
  on.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  on.scene.building.small_plane_points = 13;
  on.scene.building.small_roof_max_slope_deg = 60.0;
  on.scene.building.box_face_roof_walls = false;  // this rule alone (#183's second pass apart)
  const PipelineResult r = run_pipeline(cloud, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["counts"]["small_planes"].get<int>(), 4);
  EXPECT_EQ(r.report["scene"]["planes"]["roof"].get<int>(), 3);
  PipelineParams untested = on;
  untested.scene.building.small_roof_max_slope_deg = 90.0;
  const PipelineResult kept = run_pipeline(cloud, untested);
  EXPECT_EQ(kept.report["scene"]["planes"]["roof"].get<int>(), 4) << "the test no longer shows the cause";
  EXPECT_GT(kept.eval.accuracy.p2m_mean, r.eval.accuracy.p2m_mean);
}

// A finer outline, decided by the result (BuildingParams::finer_outline_points; DECISIONS #116): Vaihingen_00048
// at half density (the even points) is a gable whose west roof reaches 2 m farther out along its last 7.5 m.
// That short side holds 5 boundary points, under a segment's 6: no wall is recovered there, the long side's wall
// cuts the strip of roof off (p2m over 1 %). Reconstructed again with segments of 5 points (and fewer), the side
// has its wall, the strip is in the model and that run is kept.
TEST(BuildingRoofs, AShortRoofSideAtHalfDensityGetsItsWall) {
  const std::string path = airborne_more("Vaihingen_00048.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud full = read_points(path);
  const PointCloud half = every_other_point(full, 0);
  PipelineParams on;
  on.scene.building.box_face_roof_walls = false;  // this rule alone (#183's second pass apart: it walls the strip too)
  const PipelineResult r = run_pipeline(half, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_LT(r.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 6);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.007);
  PipelineParams off = on;
  off.scene.building.tighter_planes_distance = 0;  // this rule alone (step 6, #137, apart)
  off.scene.building.finer_outline_points = 0;
  const PipelineResult without = run_pipeline(half, off);
  EXPECT_FALSE(without.report["scene"].contains("finer_outline"));
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.01) << "the test no longer shows the cause";
  EXPECT_GT(r.report["counts"]["outline_segments"].get<int>(), without.report["counts"]["outline_segments"].get<int>());
}

// Segments of 4 and 3 points (BuildingParams::finer_outline_points 3; DECISIONS #131): AHN3_09495 as shared is a
// steep gable (40 degrees) with a shallow slope (84 and 88 points, 17 degrees) raised on each side of its ridge.
// With 5- and 4-point segments the outline has 20 segments, as with 6, and neither shallow slope is on the model
// (p2m 1.11 %); with 3-point segments it has 21, the west slope gets its wall and is on the model (0.75 %), and
// that run is kept.
TEST(BuildingRoofs, AShallowSlopesThreePointSideGetsItsWall) {
  const std::string path = airborne_more("AHN3_09495.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams defaults;
  defaults.scene.building.tighter_planes_distance = 0;  // step 5 alone (step 6, #137, is tested below)
  defaults.scene.building.left_out_roof_walls = false;    // and #159's walls around the slope, apart
  const PipelineResult r = run_pipeline(cloud, defaults);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 3);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.009);
  PipelineParams five = defaults;
  five.scene.building.finer_outline_points = 5;
  const PipelineResult before = run_pipeline(cloud, five);
  EXPECT_EQ(before.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 6);
  EXPECT_GT(before.eval.accuracy.p2m_mean, 0.010) << "the test no longer shows the cause";
  EXPECT_EQ(r.report["scene"]["finer_outline"]["tried"].size(), 3u) << "5, 4 and 3 points";
  PipelineParams one = defaults;
  one.scene.building.finer_outline_runs = 1;  // the finest count alone
  const PipelineResult finest = run_pipeline(cloud, one);
  const nlohmann::json& tried = finest.report["scene"]["finer_outline"]["tried"];
  ASSERT_EQ(tried.size(), 1u);
  EXPECT_EQ(tried[0]["segment_points"].get<int>(), 3);
  EXPECT_EQ(finest.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 3);
}

// With a footprint, step 5 tries the finest count alone (BuildingParams::finer_outline_runs_on_footprint;
// DECISIONS #172): the footprint's walls stand for its edges, so the finer counts before it add nothing a city
// user gets. AHN3_09495 given the convex hull of its points in plan: one run, of 3-point segments, and the same
// model kept as with all three counts.
TEST(BuildingRoofs, WithAFootprintStepFiveTriesTheFinestCountAlone) {
  const std::string path = airborne_more("AHN3_09495.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams given;
  given.scene.building.tighter_planes_distance = 0;  // step 5 alone
  given.scene.building.left_out_roof_walls = false;
  given.footprint = hull_footprint(cloud);
  const PipelineResult r = run_pipeline(cloud, given);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& tried = r.report["scene"]["finer_outline"]["tried"];
  ASSERT_EQ(tried.size(), 1u);
  EXPECT_EQ(tried[0]["segment_points"].get<int>(), 3);
  PipelineParams three = given;
  three.scene.building.finer_outline_runs_on_footprint = 3;
  const PipelineResult all = run_pipeline(cloud, three);
  EXPECT_EQ(all.report["scene"]["finer_outline"]["tried"].size(), 3u) << "5, 4 and 3 points";
  EXPECT_EQ(all.report["scene"]["finer_outline"]["kept_segment_points"], r.report["scene"]["finer_outline"]["kept_segment_points"]);
  EXPECT_NEAR(all.eval.accuracy.p2m_mean, r.eval.accuracy.p2m_mean, 1e-12) << "the same model kept";
}

// With a footprint, steps 5 and 6 are one run (BuildingParams::one_second_run_on_footprint; DECISIONS #189): step
// 6's run takes step 5's finest outline (3-point segments) with its 1 r inliers, step 5 makes no run of its own,
// and the model kept is the first run's or that run's, whichever the result says. AHN3_09495 at half density
// given the convex hull of its points. (Here the one run is not kept, p2m 1.14 % against the first's; the two
// runs of before keep step 6's tighter planes on the first outline, 0.77 %: one of the buildings the one run
// loses, measured in #189.)
TEST(BuildingRoofs, WithAFootprintStepsFiveAndSixAreOneRun) {
  const std::string path = airborne_more("AHN3_09495.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud half = every_other_point(read_points(path), 0);
  PipelineParams given;
  given.footprint = hull_footprint(half);
  const PipelineResult r = run_pipeline(half, given);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_FALSE(r.report["scene"].contains("finer_outline")) << "step 5 made a run of its own";
  const nlohmann::json& tighter = r.report["scene"]["tighter_planes"];
  EXPECT_EQ(tighter["outline_segment_points"].get<int>(), 3);
  PipelineParams first = given;  // the first run alone
  first.scene.building.finer_outline_points = 0;
  first.scene.building.tighter_planes_distance = 0;
  const PipelineResult alone = run_pipeline(half, first);
  EXPECT_NEAR(tighter["p2m_before"].get<double>(), alone.eval.accuracy.p2m_mean, 1e-12);
  EXPECT_LE(r.eval.accuracy.p2m_mean, alone.eval.accuracy.p2m_mean + 1e-12) << "kept a worse model";
  EXPECT_NEAR(r.eval.accuracy.p2m_mean,
              tighter["kept"].get<bool>() ? tighter["p2m"].get<double>() : alone.eval.accuracy.p2m_mean, 1e-12);
  PipelineParams two = given;
  two.scene.building.one_second_run_on_footprint = false;
  const PipelineResult before = run_pipeline(half, two);
  ASSERT_TRUE(before.eval.validity.valid()) << before.eval.validity.summary();
  EXPECT_EQ(before.report["scene"]["finer_outline"]["tried"].size(), 1u) << "step 5's own run, 3 points";
  EXPECT_FALSE(before.report["scene"]["tighter_planes"].contains("outline_segment_points"));
}

// With a footprint and two threads, step 6's run begins beside the first run, on the kNN graph and normals of
// its detection (TighterPlanesAhead; DECISIONS #201), and gives the model step 6's run after the first gives: the
// same vertices and faces with one thread (no run beside) and with two. AHN3_18539 given the convex hull of its
// points.
TEST(BuildingRoofs, StepSixBesideTheFirstRunIsStepSixAfterIt) {
  const std::string path = airborne_more("AHN3_18539.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams one;
  one.footprint = hull_footprint(cloud);
  one.threads = 1;
  PipelineParams two = one;
  two.threads = 2;
  const PipelineResult after = run_pipeline(cloud, one), beside = run_pipeline(cloud, two);
  ASSERT_TRUE(after.eval.validity.valid()) << after.eval.validity.summary();
  const nlohmann::json &t1 = after.report["scene"]["tighter_planes"], &t2 = beside.report["scene"]["tighter_planes"];
  EXPECT_FALSE(t1.contains("beside")) << "one thread: no run beside the first";
  EXPECT_EQ(t2.value("beside", std::string()), "first run");
  EXPECT_TRUE(t2["kept"].get<bool>()) << "step 6's run is the model here";
  EXPECT_EQ(t1["kept"], t2["kept"]);
  EXPECT_EQ(after.mesh.vertices, beside.mesh.vertices);
  EXPECT_EQ(after.mesh.faces, beside.mesh.faces);
  EXPECT_EQ(after.eval.accuracy.p2m_mean, beside.eval.accuracy.p2m_mean);
}

// Tighter planes, decided by the result (BuildingParams::tighter_planes_distance; DECISIONS #137): AHN3_09495 at
// half density (the even points) is a steep gable with a shallow slope raised on each side of its ridge. With the
// planes' inliers within 2 r (0.9 m here, more than the steps between the slopes) the shallow slopes are not on the
// model (p2m 1.16 %); with 1 r they are (0.73 %) and that run is kept. Not the box: the gable's volume is well
// under its bounding box's, and its ridge is as high as the points'.
TEST(BuildingRoofs, ARoofStepAtHalfDensityIsNoRidge) {
  const std::string path = airborne_more("AHN3_09495.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud full = read_points(path);
  const PointCloud half = every_other_point(full, 0);
  const PipelineResult r = run_pipeline(half, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& tighter = r.report["scene"]["tighter_planes"];
  EXPECT_TRUE(tighter["kept"].get<bool>());
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.008);
  const BBox box = bounding_box(r.mesh.vertices), points = bounding_box(half.points);
  const Vec3 side = box.max - box.min;
  EXPECT_LT(r.eval.validity.volume, 0.8 * side.x() * side.y() * side.z()) << "the bounding box, not a gable";
  EXPECT_GT(box.max.z(), points.max.z() - 0.5);  // the ridge is where the points' is
  PipelineParams off;
  off.scene.building.tighter_planes_distance = 0;
  const PipelineResult without = run_pipeline(half, off);
  EXPECT_FALSE(without.report["scene"].contains("tighter_planes"));
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.011) << "the test no longer shows the cause";
  EXPECT_NEAR(tighter["p2m_before"].get<double>(), without.eval.accuracy.p2m_mean, 1e-12);
}

// Step 6's second distance, decided by the result (BuildingParams::tighter_planes_second_distance; DECISIONS #246):
// AHN3_11442 as shared (1,648 points). Step 6's run with the planes' inliers within 1 r explains its points no
// better (p2m 0.424 -> 0.438 %) and is not kept; the model leaves more than a plane's worth of points farther than
// the detection's inlier distance, so the second distance (0.5 r) is tried: seven roof planes where the first had
// four, p2m 0.340 %, kept. Off: the model of before, with no second run in its report.
TEST(BuildingRoofs, WhereStepSixGainsNothingATighterSecondDistanceIsTriedAndKeptByTheResult) {
  const std::string path = airborne_more("AHN3_11442.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& scene = r.report["scene"];
  ASSERT_TRUE(scene.contains("tighter_planes_second"));
  EXPECT_FALSE(scene["tighter_planes"]["kept"].get<bool>()) << "the second distance is step 6's second chance";
  const nlohmann::json& second = scene["tighter_planes_second"];
  EXPECT_TRUE(second["kept"].get<bool>());
  EXPECT_EQ(second["distance"].get<double>(), PipelineParams{}.scene.building.tighter_planes_second_distance);
  EXPECT_GE(second["far_points_before"].get<int>(), 30) << "a plane's worth of points left far";
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.0036);
  PipelineParams off;
  off.scene.building.tighter_planes_second_distance = 0;
  const PipelineResult o = run_pipeline(cloud, off);
  EXPECT_FALSE(o.report["scene"].contains("tighter_planes_second"));
  EXPECT_GT(o.eval.accuracy.p2m_mean, 0.004) << "the test no longer shows the cause";
  EXPECT_NEAR(second["p2m_before"].get<double>(), o.eval.accuracy.p2m_mean, 1e-12);
  EXPECT_LT(r.eval.accuracy.p2m_mean, (1.0 - off.scene.building.finer_outline_min_gain) * o.eval.accuracy.p2m_mean);
}

// By turns (hsr city at `-j 1`, DECISIONS #235) a building gives its turn up (PipelineParams::turn_over) once its
// first run and step 0 are done: steps 5 and 6 then run beside the next building's first runs, on the idle core,
// as step 7 did (DECISIONS #249). AHN3_09495's step 6 run is kept: its line comes after the turn, and the model is
// the same with a turn and without one.
TEST(BuildingRoofs, StepsFiveAndSixRunAfterTheTurnAndTheModelIsTheSame) {
  const std::string path = airborne_more("AHN3_09495.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams plain;
  plain.threads = 2;  // by turns a building's run has the two cores of `-j 1`
  PipelineParams turned = plain;
  turned.turn_over = [] { std::fprintf(stderr, "the turn given up\n"); };
  const log::Level level = log::level();
  log::set_level(log::Level::Info);
  testing::internal::CaptureStderr();
  const PipelineResult t = run_pipeline(cloud, turned);
  const std::string lines = testing::internal::GetCapturedStderr();
  log::set_level(level);
  ASSERT_TRUE(t.eval.validity.valid()) << t.eval.validity.summary();
  ASSERT_TRUE(t.report["scene"]["tighter_planes"]["kept"].get<bool>()) << "the test no longer shows step 6's run";
  const std::size_t turn = lines.find("the turn given up"), step6 = lines.find("planes' inliers within");
  ASSERT_NE(turn, std::string::npos) << lines;
  ASSERT_NE(step6, std::string::npos) << lines;
  EXPECT_LT(turn, step6) << "step 6 was judged before the turn:\n" << lines;
  const PipelineResult p = run_pipeline(cloud, plain);
  EXPECT_EQ(t.mesh.vertices, p.mesh.vertices);
  EXPECT_EQ(t.mesh.faces, p.mesh.faces);
  EXPECT_EQ(t.report["scene"]["tighter_planes"], p.report["scene"]["tighter_planes"]);
}

// By turns step 6's run is not begun beside the first run (TighterPlanesAhead::begins_after_the_turn, DECISIONS
// #250): it is made after the turn, beside the next building's first runs. AHN3_15708, given the convex hull of its
// points in plan as its footprint (as hsr city gives one): without a turn the run begins beside the first, by turns
// it does not, and the model and step 6's verdict are the same.
TEST(BuildingRoofs, ByTurnsStepSixsRunIsNotBegunBesideTheFirstRun) {
  const std::string path = airborne_more("AHN3_15708.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams plain;
  plain.threads = 2;  // threads to spare: the run may begin beside the first
  plain.footprint = hull_footprint(cloud);
  PipelineParams turned = plain;
  turned.turn_over = [] {};
  const PipelineResult p = run_pipeline(cloud, plain);
  const PipelineResult t = run_pipeline(cloud, turned);
  ASSERT_TRUE(p.report["scene"].contains("tighter_planes"));
  EXPECT_EQ(p.report["scene"]["tighter_planes"].value("beside", ""), "first run") << "without a turn, beside it";
  EXPECT_FALSE(t.report["scene"]["tighter_planes"].contains("beside")) << "by turns, after the turn";
  EXPECT_EQ(t.mesh.vertices, p.mesh.vertices);
  EXPECT_EQ(t.mesh.faces, p.mesh.faces);
  nlohmann::json made_beside = p.report["scene"]["tighter_planes"];
  made_beside.erase("beside");
  EXPECT_EQ(t.report["scene"]["tighter_planes"], made_beside);
}

// A small roof that meets the building's roof in plan is a roof of it (BuildingParams::small_roof_meets_in_plan;
// DECISIONS #140): AHN3_03746 is a gable with a lower annex whose eave lies a storey under the main roof's, its
// wall unscanned. At full density the annex roof is a first-size plane and a roof; at half density (the even
// points) it holds 24 points, a small plane, and touches no plane of the building (no inlier among another's
// nearest neighbours): it was clutter and the annex was left out (p2m 0.58 %). Within wing_reach r in plan of the
// gable's inliers, which stand higher (under its eave), it is a roof of the building (0.38 %).
TEST(BuildingRoofs, ASmallAnnexRoofAStoreyUnderTheEaveIsARoof) {
  const std::string path = airborne_more("AHN3_03746.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud half = every_other_point(read_points(path), 0);
  const PipelineResult r = run_pipeline(half, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["scene"]["planes"]["roof"].get<int>(), 4);
  EXPECT_EQ(r.report["scene"]["planes"]["clutter"].get<int>(), 0);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.0045);
  PipelineParams off;
  off.scene.building.small_roof_meets_in_plan = false;
  const PipelineResult without = run_pipeline(half, off);
  ASSERT_TRUE(without.eval.validity.valid()) << without.eval.validity.summary();
  EXPECT_EQ(without.report["scene"]["planes"]["clutter"].get<int>(), 1) << "the test no longer shows the cause";
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.0052);
}

namespace {

/// `cloud` with Gaussian noise of `sigma` on every coordinate (x, y, z of each point in turn), from a splitmix64
/// stream of `seed` through Box-Muller: the same numbers on every platform (std::normal_distribution's are not).
PointCloud with_noise(const PointCloud& cloud, std::uint64_t seed, double sigma) {
  std::uint64_t state = seed;
  const auto next = [&state] {
    std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  };
  std::vector<double> g;
  while (g.size() < 3 * cloud.size()) {
    const double u1 = (static_cast<double>(next() >> 11) + 0.5) / 9007199254740992.0;
    const double u2 = static_cast<double>(next() >> 11) / 9007199254740992.0;
    const double r = std::sqrt(-2.0 * std::log(u1));
    g.push_back(r * std::cos(2.0 * kPi * u2) * sigma);
    g.push_back(r * std::sin(2.0 * kPi * u2) * sigma);
  }
  PointCloud noisy = cloud;
  for (std::size_t i = 0; i < cloud.size(); ++i) noisy.points[i] += Vec3(g[3 * i], g[3 * i + 1], g[3 * i + 2]);
  return noisy;
}

}  // namespace

// "Higher" in the small roof's eave test has a margin (BuildingParams::small_roof_eave_drop; DECISIONS #176):
// Vaihingen_00021 is a flat roof (187 points, 0.35 m apart) with a few clumps of points near its east end. With
// 3 cm of noise the clumps and the roof's edge fit small planes at the roof's own height, a few degrees off level;
// a roof inlier within reach in plan stood a hair above them, so they were roofs under its eave and the model's east
// end became sloped pieces (on City3D's ground, z = 265 m). Twelve noise draws: with the margin every model has the
// one roof; with any amount most draws had two or more.
TEST(BuildingRoofs, APatchOfTheRoofTiltedByNoiseIsNoRoofUnderItsEave) {
  const std::string path = airborne_more("Vaihingen_00021.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PipelineParams on;
  on.scene.mode = SceneMode::Building;
  on.scene.building.ground_z = 265.0 - cloud.origin.z();
  PipelineParams off = on;
  off.scene.building.small_roof_eave_drop = 0.0;
  int more_roofs_off = 0;
  double p2m_on = 0, p2m_off = 0;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    const PointCloud noisy = with_noise(cloud, seed, 0.03);
    const PipelineResult r = run_pipeline(noisy, on);
    ASSERT_TRUE(r.eval.validity.valid()) << "seed " << seed << ": " << r.eval.validity.summary();
    EXPECT_EQ(r.report["scene"]["planes"]["roof"].get<int>(), 1) << "seed " << seed;
    const PipelineResult without = run_pipeline(noisy, off);
    more_roofs_off += without.report["scene"]["planes"]["roof"].get<int>() > 1;
    p2m_on += r.eval.accuracy.p2m_mean / 12;
    p2m_off += without.eval.accuracy.p2m_mean / 12;
  }
  EXPECT_GE(more_roofs_off, 6) << "the test no longer shows the cause";
  EXPECT_LT(p2m_on, 0.026);
  EXPECT_GT(p2m_off, 0.028);
}

// A roof part standing on another roof gets its walls (BuildingParams::left_out_roof_walls; DECISIONS #159):
// AHN3_11936 is a flat roof at 5 m with a 5 m² sloped structure of 53 inliers on it, up to 6.9 m. Its plane is
// detected but its outline holds no segment, so no wall stands under it and the model was the flat roof's box
// (p2m 0.75 %, 13 points unexplained, the model's top at 5.5 m). The first model leaves the roof out, stages 3
// to 7 run again with walls around it, and that model is kept: the structure on the model, its top at the points'.
TEST(BuildingRoofs, ARaisedRoofPartOnAFlatRoofGetsItsWalls) {
  const std::string path = airborne_more("AHN3_11936.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& left = r.report["scene"]["left_out_roofs"];
  EXPECT_TRUE(left["kept"].get<bool>());
  ASSERT_EQ(left["roofs"].size(), 1u);
  EXPECT_GE(left["roofs"][0]["inliers"].get<int>(), 30);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.003);
  EXPECT_EQ(r.report["counts"]["points_unexplained"].get<int>(), 0);
  const BBox box = bounding_box(r.mesh.vertices), points = bounding_box(cloud.points);
  EXPECT_GT(box.max.z(), points.max.z() - 0.3) << "the structure's top on the model";
  PipelineParams off;
  off.scene.building.left_out_roof_walls = false;
  off.scene.building.tighter_planes_second_distance = 0;  // this rule alone (#246 brings the no-walls model to 0.69 %)
  const PipelineResult without = run_pipeline(cloud, off);
  ASSERT_TRUE(without.eval.validity.valid()) << without.eval.validity.summary();
  EXPECT_FALSE(without.report["scene"].contains("left_out_roofs"));
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.007) << "the test no longer shows the cause";
  EXPECT_GT(without.report["counts"]["points_unexplained"].get<int>(), 10);
  EXPECT_LT(bounding_box(without.mesh.vertices).max.z(), points.max.z() - 1.0);
}

// The walls around a left-out roof hold in the later runs (BuildingParams::left_out_roof_walls_carried; DECISIONS
// #166): AHN3_16207 turned 37 degrees about its centre. Its first model leaves out a 51-point roof; with walls
// around it p2m 0.59 -> 0.51 %, kept. The finer outlines of step 5 were then measured against that model without
// those walls (0.49 % at best, not 5 % lower: none kept, the building ended at 0.51 %, worse than without #159).
// With the walls in every later run the 5-point outline has them and is kept: p2m under 0.47 %.
TEST(BuildingRoofs, ALeftOutRoofsWallsHoldInTheFinerOutlineRuns) {
  const std::string path = airborne_more("AHN3_16207.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  PointCloud turned = cloud;
  Vec3 centre = Vec3::Zero();
  for (const Vec3& p : cloud.points) centre += p;
  centre /= static_cast<double>(cloud.size());
  const double a = 37.0 * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const Vec3 p = cloud.points[i] - centre;
    const Vec3& n = cloud.normals[i];
    turned.points[i] = Vec3(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z());
    turned.normals[i] = Vec3(c * n.x() - s * n.y(), s * n.x() + c * n.y(), n.z());
  }
  PipelineParams on;
  on.recovery.wall_edge_quantile = 0.9;  // #54's walls: with #167's the first model keeps the roof (no walls kept)
  on.recovery.partner_max_behind = -1;    // #177 apart: with it no finer outline is kept on this scan
  const PipelineResult r = run_pipeline(turned, on);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_TRUE(r.report["scene"]["left_out_roofs"]["kept"].get<bool>());
  EXPECT_NE(r.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 6) << "a finer outline kept";
  ASSERT_TRUE(r.report["scene"].contains("left_out_roofs_carried"));
  EXPECT_EQ(r.report["scene"]["left_out_roofs_carried"].size(), 1u);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.0047);
  PipelineParams off = on;
  off.scene.building.left_out_roof_walls_carried = false;
  const PipelineResult without = run_pipeline(turned, off);
  ASSERT_TRUE(without.eval.validity.valid()) << without.eval.validity.summary();
  EXPECT_TRUE(without.report["scene"]["left_out_roofs"]["kept"].get<bool>());
  EXPECT_FALSE(without.report["scene"].contains("left_out_roofs_carried"));
  EXPECT_EQ(without.report["scene"]["finer_outline"]["kept_segment_points"].get<int>(), 6) << "the test no longer shows the cause";
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.005);
}

namespace {

/// The area of `mesh`'s faces that stand upright facing along x or y exactly: on a turned building, the faces on
/// the partition's axis-aligned box.
double axis_aligned_wall_area(const PolygonMesh& mesh) {
  double area = 0;
  for (const auto& f : mesh.faces) {
    Vec3 n = Vec3::Zero();  // Newell's normal, twice the area
    for (std::size_t i = 0; i < f.size(); ++i) n += mesh.vertices[f[i]].cross(mesh.vertices[f[(i + 1) % f.size()]]);
    const double a = 0.5 * n.norm();
    if (a > 0 && std::max(std::abs(n.x()), std::abs(n.y())) >= (1.0 - 1e-9) * n.norm()) area += a;
  }
  return area;
}

}  // namespace

// A model that runs to the partition's box gets walls around its roofs (BuildingParams::box_face_roof_walls;
// DECISIONS #183): AHN3_19114 at half density (the even points), a flat roof turned 35 degrees with a 2 x 2.5 m
// annex at its south-west end whose sides hold two or three outline points, too few for a segment. No wall stands
// there and the model ran out to the axis-aligned box (26 m² of faces on it, p2m 0.48 %). No roof is left out, but
// the model reaches the box: stages 3 to 7 run again with walls around the roof's rectangle, and that model is
// kept (p2m 0.45 %): nothing on the box.
TEST(BuildingRoofs, AModelThatRunsToThePartitionsBoxGetsWallsAroundItsRoofs) {
  const std::string path = airborne_more("AHN3_19114.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud half = every_other_point(read_points(path), 0);
  const PipelineResult r = run_pipeline(half, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& walled = r.report["scene"]["left_out_roofs"];
  EXPECT_EQ(walled["why"].get<std::string>(), "box");
  EXPECT_TRUE(walled["kept"].get<bool>());
  EXPECT_LT(axis_aligned_wall_area(r.mesh), 0.01) << "faces on the box";
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.0046);
  PipelineParams off;
  off.scene.building.box_face_roof_walls = false;
  const PipelineResult without = run_pipeline(half, off);
  ASSERT_TRUE(without.eval.validity.valid()) << without.eval.validity.summary();
  EXPECT_FALSE(without.report["scene"].contains("left_out_roofs"));
  EXPECT_GT(axis_aligned_wall_area(without.mesh), 10.0) << "the test no longer shows the cause";
  EXPECT_GT(without.eval.accuracy.p2m_mean, 0.0047);
}

// The outline prism (BuildingParams::outline_prism, DECISIONS #135), the rule alone: a roof of 12 points between
// 10 and 12 m over a 4 x 3 m plan, 4 points of ground around at 0 m. The roof points are those above the gap,
// the ground is the lowest point, the roof the 0.7 quantile of the roof points' heights, the outline their convex
// hull; the mesh is a valid closed solid holding every roof point in plan. Without the ground points the ground
// is assumed one storey under the lowest roof point; a given ground wins over both.
TEST(BuildingRoofs, TheOutlinePrismStandsOnItsGroundUpToItsRoofQuantile) {
  PointCloud cloud;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 3; ++j) cloud.points.emplace_back(i * 4.0 / 3.0, j * 1.5, 10.0 + 2.0 * u(rng));
  const std::size_t roof = cloud.size();
  for (const Vec2& g : {Vec2(-1, -1), Vec2(5, -1), Vec2(5, 4), Vec2(-1, 4)}) cloud.points.emplace_back(g.x(), g.y(), 0.0);
  std::vector<double> heights;
  for (std::size_t i = 0; i < roof; ++i) heights.push_back(cloud.points[i].z());
  std::sort(heights.begin(), heights.end());
  const double r = 1.0;
  BuildingParams params;
  params.outline_prism_beyond_hull = 0.0;  // at the hull (#135); beyond it: the next test
  const OutlinePrism p = outline_prism(cloud, r, params, {});
  ASSERT_FALSE(p.mesh.faces.empty());
  EXPECT_EQ(p.under_roof_points, 4u);
  for (std::size_t i = 0; i < cloud.size(); ++i) EXPECT_EQ(p.roof[i], i < roof) << i;
  EXPECT_EQ(p.ground_source, GroundSource::LowestPoints);
  EXPECT_DOUBLE_EQ(p.ground_z, 0.0);
  EXPECT_GT(p.roof_z, heights[6]);
  EXPECT_LT(p.roof_z, heights[9]);
  const EvalResult eval = run_eval(cloud, p.mesh, nullptr, {});
  EXPECT_TRUE(eval.validity.valid()) << eval.validity.summary();
  const BBox box = bounding_box(p.mesh.vertices);
  EXPECT_NEAR(box.min.z(), 0.0, 1e-12);
  EXPECT_NEAR(box.max.z(), p.roof_z, 1e-12);
  EXPECT_NEAR(box.size().x(), 4.0, 1e-9);
  EXPECT_NEAR(box.size().y(), 3.0, 1e-9);
  EXPECT_NEAR(eval.validity.volume, 4.0 * 3.0 * p.roof_z, 1e-6) << "the prism over the roof points' rectangle";
  EXPECT_EQ(std::count(p.mesh.face_class.begin(), p.mesh.face_class.end(), FaceClass::Roof), 1);
  EXPECT_EQ(std::count(p.mesh.face_class.begin(), p.mesh.face_class.end(), FaceClass::Ground), 1);

  PointCloud roof_only;
  roof_only.points.assign(cloud.points.begin(), cloud.points.begin() + static_cast<std::ptrdiff_t>(roof));
  const OutlinePrism assumed = outline_prism(roof_only, r, params, {});
  EXPECT_EQ(assumed.ground_source, GroundSource::Assumed);
  EXPECT_DOUBLE_EQ(assumed.ground_z, heights.front() - params.assumed_wall_height);
  EXPECT_FALSE(assumed.ground_note.empty());
  EXPECT_EQ(assumed.under_roof_points, 0u);

  params.ground_z = -2.0;
  const OutlinePrism given = outline_prism(cloud, r, params, {});
  EXPECT_EQ(given.ground_source, GroundSource::Given);
  EXPECT_NEAR(bounding_box(given.mesh.vertices).min.z(), -2.0, 1e-12);

  PointCloud line;  // points on a line in plan span no area: no prism
  for (int i = 0; i < 6; ++i) line.points.emplace_back(i, 0.0, 10.0 + 0.3 * i);
  EXPECT_TRUE(outline_prism(line, r, BuildingParams{}, {}).mesh.faces.empty());
}

// The outline prism's walls half a spacing outside its points (BuildingParams::outline_prism_beyond_hull,
// DECISIONS #219): a flat roof of 5 x 4 points a metre apart, no ground. Its spacing in plan is sqrt(12 m² / 20),
// and each wall stands half of it outside the outermost row; 0 puts them on the rows. A given outline (a
// footprint's) is where the walls stand, the rule or not.
TEST(BuildingRoofs, TheOutlinePrismStandsHalfASpacingOutsideItsOutermostPoints) {
  PointCloud cloud;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 4; ++j) cloud.points.emplace_back(i, j, 10.0 + 0.01 * ((i + j) % 2));
  const double s = std::sqrt(12.0 / 20.0);
  BuildingParams params;
  ASSERT_DOUBLE_EQ(params.outline_prism_beyond_hull, 0.5) << "the default (#219)";
  for (double k : {0.5, 0.0, 1.0}) {
    params.outline_prism_beyond_hull = k;
    const OutlinePrism p = outline_prism(cloud, 0.8, params, {});
    ASSERT_FALSE(p.mesh.faces.empty()) << k;
    const BBox box = bounding_box(p.mesh.vertices);
    EXPECT_NEAR(box.min.x(), -k * s, 1e-9) << k;
    EXPECT_NEAR(box.max.x(), 4.0 + k * s, 1e-9) << k;
    EXPECT_NEAR(box.min.y(), -k * s, 1e-9) << k;
    EXPECT_NEAR(box.max.y(), 3.0 + k * s, 1e-9) << k;
    EXPECT_NEAR(p.beyond_hull, k * s, 1e-12) << k;
    const EvalResult eval = run_eval(cloud, p.mesh, nullptr, {});
    EXPECT_TRUE(eval.validity.valid()) << k << ": " << eval.validity.summary();
    EXPECT_NEAR(eval.validity.volume, (4.0 + 2 * k * s) * (3.0 + 2 * k * s) * (p.roof_z - p.ground_z), 1e-6) << k;
  }
  params.outline_prism_beyond_hull = 0.5;
  const std::vector<Vec2> ring{{-1, -1}, {5, -1}, {5, 4}, {-1, 4}};
  const BBox given = bounding_box(outline_prism(cloud, 0.8, params, {}, &ring).mesh.vertices);
  EXPECT_NEAR(given.min.x(), -1.0, 1e-12);
  EXPECT_NEAR(given.max.y(), 4.0, 1e-12);
}

// Issue 42 "valid for all": Vaihingen_00026 (21 points) and its every other point hold no plane of 15 points. A
// building scan (its normals face up, or `--scene building`) still gets a model: the outline prism, valid,
// building, said in the quality; object mode, the rule switched off and `auto` with the normals turned down give
// no model.
TEST(BuildingRoofs, AScanWithNoPlaneIsTheOutlinePrism) {
  const std::string path = airborne_more("Vaihingen_00026.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud full = read_points(path);
  const PointCloud half = every_other_point(full, 1);
  for (const PointCloud* cloud : std::vector<const PointCloud*>{&full, &half}) {
    const std::string what = std::to_string(cloud->size()) + " points";
    const PipelineResult r = run_pipeline(*cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << what << ": " << r.eval.validity.summary();
    EXPECT_EQ(r.report["scene"]["mode"], "building") << what;
    EXPECT_EQ(r.report["quality"]["fallback"], "outline prism") << what;
    EXPECT_EQ(r.report["quality"]["scene"], "building") << what;
    EXPECT_DOUBLE_EQ(r.report["quality"]["points_explained_share"].get<double>(), 1.0) << what;
    // City3D's box: 15.6 % (full), 24.6 % (half); at the hull (#135) 7.3 / 2.8 %, half a spacing out (#219) 11.1 / 13.0 %
    EXPECT_LT(r.eval.accuracy.p2m_mean, 0.14) << what;
    PipelineParams object;
    object.scene.mode = SceneMode::Object;
    EXPECT_THROW(run_pipeline(*cloud, object), Error) << what << ": an object without planes is no block";
    PointCloud bare = *cloud;  // its normals facing down: `auto` cannot tell an aerial scan; a building is given
    for (Vec3& n : bare.normals) n = -n;
    try {
      run_pipeline(bare, PipelineParams{});
      ADD_FAILURE() << what << ": normals facing down, no plane: `auto` cannot tell";
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::NoPlanes) << what;
    }
    PipelineParams building;
    building.scene.mode = SceneMode::Building;
    EXPECT_EQ(run_pipeline(bare, building).report["quality"]["fallback"], "outline prism") << what;
    PipelineParams off;
    off.scene.building.outline_prism = false;
    try {
      run_pipeline(*cloud, off);
      ADD_FAILURE() << what << ": no plane, no model without the rule";
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::NoPlanes) << what;
    }
  }
}

// Issue 42 "valid for all" on fresh half-density draws (DECISIONS #226). Vaihingen_00015's every other point (47
// points: a steep gable, no plane of 15) has normals that lean sideways (a draw of 35 of its points: 0.66 of all
// within 60 degrees of +z, 0.03 of -z). `auto` asks most of the normals that lean up or down to lean up, and gives the outline prism (before:
// `no plane found`, no model); its normals turned down still give no model.
TEST(BuildingRoofs, ASparseSteepRoofWithNoPlaneIsTheOutlinePrism) {
  const std::string path = airborne_more("Vaihingen_00015.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud half = every_other_point(read_points(path), 1);
  ASSERT_EQ(half.size(), 47u) << "the test no longer shows the case";
  std::size_t up = 0;
  for (const Vec3& n : half.normals) up += n.z() >= std::cos(SceneParams{}.auto_steep_roof_deg * M_PI / 180.0) * n.norm();
  ASSERT_LT(static_cast<double>(up), SceneParams{}.auto_min_roof_share * static_cast<double>(half.size()))
      << "under the share of all points: the case the rule was changed for";
  const PipelineResult r = run_pipeline(half, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["fallback"], "outline prism");
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  PointCloud down = half;
  for (Vec3& n : down.normals) n = -n;
  EXPECT_THROW(run_pipeline(down, PipelineParams{}), Error) << "normals facing down: `auto` cannot tell";
}

// A small scan seen from above whose planes enclose nothing in either kind, also with the smaller planes, gets the
// outline prism (DECISIONS #231; Vaihingen_00015 at half density, two fresh draws: one steep plane taken for a wall
// and a flat part of 10 points, under any plane's size): a wall of 40 points and, a metre above its top, 10 roof
// points facing up. `auto` says object (one plane encloses nothing), the building run finds no roof, #227's planes
// of 15 the same: before, no model. `--scene building` still says why it made none; normals turned down too.
TEST(BuildingRoofs, ASmallScanWhosePlanesEncloseNothingEitherWayIsTheOutlinePrism) {
  PointCloud cloud;
  for (int y = 0; y < 8; ++y)
    for (int z = 1; z < 6; ++z) cloud.points.emplace_back(0.0, y, z), cloud.normals.emplace_back(-1.0, 0.0, 0.0);
  for (int x = 2; x < 7; ++x)
    for (int y = 0; y < 2; ++y) cloud.points.emplace_back(x, 3.0 * y + 2.0, 6.0), cloud.normals.emplace_back(0.0, 0.0, 1.0);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["fallback"], "outline prism");
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  PipelineParams building;
  building.scene.mode = SceneMode::Building;
  EXPECT_EQ(test::status_of([&] { run_pipeline(cloud, building); }), Status::DegenerateInput);
  PointCloud down = cloud;
  for (Vec3& n : down.normals) n = -n;
  EXPECT_EQ(test::status_of([&] { run_pipeline(down, PipelineParams{}); }), Status::DegenerateInput);
}

// A small scan whose first planes make no model in either kind is detected again with the small-scan rule's smaller
// planes (DECISIONS #227; Vaihingen_00015 with 3 cm noise, a fresh draw): a wall of 40 points (8 x 5, 1 m apart) and
// a flat roof of 25 beside it, a metre above its top. Planes of 30 find the wall alone; `auto` says object, and one
// plane encloses nothing. With the roof's plane of 15 the scan is the building: valid, the roof and the wall, every
// point on the model; the report says which planes. Asked for planes of 15 the first detection finds both; asked for
// planes of 26, the retry takes half of them, 13.
TEST(BuildingRoofs, ASmallScanWhosePlanesMakeNoModelTriesTheSmallerPlanes) {
  PointCloud cloud;
  for (int y = 0; y < 8; ++y)
    for (int z = 1; z < 6; ++z) cloud.points.emplace_back(0.0, y, z), cloud.normals.emplace_back(-1.0, 0.0, 0.0);
  for (int x = 2; x < 7; ++x)
    for (int y = 0; y < 5; ++y) cloud.points.emplace_back(x, y + 1.5, 6.0), cloud.normals.emplace_back(0.0, 0.0, 1.0);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  EXPECT_EQ(r.report["counts"]["planes"], 2);
  EXPECT_EQ(r.report["structure_small_scan"], 15);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 1e-6);
  PipelineParams told;
  told.structure.min_region_points = 15;  // the smaller planes asked for: one detection, the same model
  EXPECT_TRUE(run_pipeline(cloud, told).eval.validity.valid());
  PipelineParams bigger;
  bigger.structure.min_region_points = 26;  // planes the roof cannot hold: the retry's are 13
  const PipelineResult b = run_pipeline(cloud, bigger);
  EXPECT_TRUE(b.eval.validity.valid());
  EXPECT_EQ(b.report["structure_small_scan"], 13);
}

// Issue 42 "auto = building for all" (SceneParams::auto_choice_small_scans, DECISIONS #136): Vaihingen_00015 (95
// points, no plane of 30: the small-scan rule's planes, a 41-point wall and a 34-point level roof) has 0.45 of its
// plane points on planes facing up, 0.25 from the rule's edge, and was `object` in every variant (at half density
// a slab explaining 44 % of its points; bench/building measures the variants). Its figures rest on two planes, so
// both kinds are tried: the building is kept; with the small-scan trigger off it is the object again.
TEST(BuildingRoofs, ASmallScanThatAutoCallsAnObjectIsTriedAsABuilding) {
  const std::string path = airborne_more("Vaihingen_00015.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud full = read_points(path);
  for (const PointCloud* cloud : std::vector<const PointCloud*>{&full}) {
    const std::string what = std::to_string(cloud->size()) + " points";
    const PipelineResult r = run_pipeline(*cloud, PipelineParams{});
    ASSERT_TRUE(r.eval.validity.valid()) << what;
    EXPECT_EQ(r.report["quality"]["scene"], "building") << what;
    EXPECT_EQ(r.report["quality"]["scene_choice"], "auto, both tried") << what;
    ASSERT_TRUE(r.report["scene"].contains("choice")) << what;
    EXPECT_TRUE(r.report["scene"]["choice"]["small_scan"].get<bool>()) << what;
    EXPECT_LT(r.report["scene"]["choice"]["margin"].get<double>(), -0.1) << what << ": far from the edge";
    EXPECT_GT(r.report["quality"]["points_explained_share"].get<double>(), 0.95) << what;
    PipelineParams margin_only;
    margin_only.scene.auto_choice_small_scans = false;
    EXPECT_EQ(run_pipeline(*cloud, margin_only).report["quality"]["scene"], "object") << what << ": the test no longer shows the case";
  }
}

/// The points of `full` (with their normals) whose bit is set in `mask`: hex, four points a digit, the lowest bit
/// the first point. A draw of bench/building/variants.py's sub50 (numpy's generator) kept exactly.
PointCloud masked_points(const PointCloud& full, const std::string& mask) {
  PointCloud out;
  out.origin = full.origin;
  for (std::size_t i = 0; i < full.size(); ++i) {
    const char c = mask.at(i / 4);
    const int digit = c <= '9' ? c - '0' : c - 'a' + 10;
    if (!((digit >> (i % 4)) & 1)) continue;
    out.points.push_back(full.points[i]);
    out.normals.push_back(full.normals[i]);
  }
  return out;
}

// Issue 42 "auto = building for all", half density, draw 8 (`variants.py --seed 8`, sub50; DECISIONS #203).
// AHN3_00061: a steep hipped roof (faces at 49-52 degrees); at half density the detection finds three faces whose
// two lines are hips, the ridge's two faces not adjacent: no horizontal line, so the scene was not level and rule
// (a) saw 0.00 of its points on planes facing up (object, far from the edge: never tried as a building). A hip is a
// level roof's line (SceneParams::auto_level_hips): the building, by rule (a) alone.
TEST(BuildingRoofs, ASteepHippedRoofAtHalfDensityIsABuilding) {
  const std::string path = airborne_more("AHN3_00061.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = masked_points(read_points(path),
      "4d2b269112b68260646f4c772d970841eb6fd1966ffcba685b265aff282b16d0fd5b5460854120a5d4691aa03c76af4dd79d989b5100a0a300607483858efc0bc8795aa33df58fe0");
  ASSERT_EQ(cloud.size(), 274u);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  EXPECT_EQ(r.report["quality"]["scene_choice"], "auto") << "decided by the rule, not on its edge";
  EXPECT_GE(r.report["scene"]["roof_share"].get<double>(), 0.9);
  EXPECT_GT(r.report["quality"]["points_explained_share"].get<double>(), 0.99);
  PipelineParams no_hips;
  no_hips.scene.auto_level_hips = false;
  const PipelineResult o = run_pipeline(cloud, no_hips);
  EXPECT_EQ(o.report["quality"]["scene"], "object") << "the test no longer shows the case";
  EXPECT_LT(o.report["scene"]["roof_share"].get<double>(), 0.1);
}

// Draw 15 of the same (DECISIONS #231): 286 points, five faces (48-52 degrees and a flat part); one face is an
// upper step of a slope whose centroid stands above its hip's line midway, which read as a tilted top over a
// tilted bottom and left every hip uncounted: not level, 0.12 of the points facing up, object (p2m 1.56 % where
// the building's is 0.31 %). Only a level line can be an object's equator: the building, by rule (a).
TEST(BuildingRoofs, AHipBesideAnUpperStepOfASlopeIsStillAHip) {
  const std::string path = airborne_more("AHN3_00061.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = masked_points(read_points(path),
      "d010006e6d031e9dfa4b0aa74f7bab85dec1482773a4d3632a6dd98a9917ba03c52edfbc8b770c1e085ad72d20b55f73d4dc68d1e0212f7a9d1cceffb0f7924c40e6473293d04e41");
  ASSERT_EQ(cloud.size(), 286u);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  EXPECT_EQ(r.report["quality"]["scene_choice"], "auto") << "decided by the rule, not on its edge";
  EXPECT_GE(r.report["scene"]["roof_share"].get<double>(), 0.9);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.008) << "the object's was 1.56 % of the diagonal";
}

// The same draw, Vaihingen_00021 (96 points, the small-scan rule's planes: a 26-point flat roof and a 20-point
// wall; nothing under the roof: one layer). Step 0 tries both kinds (#136). The object is a 2 m slab over the roof
// that takes in a row of points 1.9 m above it (a neighbour's edge or a tree: 18 % of the points are left
// unexplained as shared) and explains 0.99 of the points against the building's 0.96: by #84's comparison the
// slab won. A roof-only scan is never a slab (SceneParams::auto_choice_one_layer_building): the valid building is
// kept. And step 0's building run after the object's first run is the building's first (DetectionMemo::
// building_ran): it gets the walls around its roof (walls_for_left_out_roofs), as a building's first run does.
TEST(BuildingRoofs, ARoofOnlySmallScanIsNeverASlab) {
  const std::string path = airborne_more("Vaihingen_00021.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = masked_points(read_points(path), "1b7ec0395c177d6169c132ee8f6da59312c29bb2ffe4882");
  ASSERT_EQ(cloud.size(), 96u);
  const PipelineResult r = run_pipeline(cloud, PipelineParams{});
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["scene"], "building");
  EXPECT_EQ(r.report["quality"]["scene_choice"], "auto, both tried");
  const nlohmann::json& choice = r.report["scene"]["choice"];
  EXPECT_TRUE(choice["one_layer"].get<bool>());
  EXPECT_EQ(choice["kept"], "building");
  const double object = choice["candidates"][0]["points_explained_share"].get<double>(),
               building = choice["candidates"][1]["points_explained_share"].get<double>();
  EXPECT_EQ(choice["candidates"][0]["scene"], "object");
  EXPECT_GE(object, building + SceneParams{}.auto_choice_min_gain) << "the slab explains more: #84 alone keeps it";
  ASSERT_TRUE(r.report["scene"].contains("left_out_roofs")) << "step 0's building run is the building's first";
  EXPECT_TRUE(r.report["scene"]["left_out_roofs"]["kept"].get<bool>());
  EXPECT_GT(building, 0.95);
  PipelineParams compare;
  compare.scene.auto_choice_one_layer_building = false;
  EXPECT_EQ(run_pipeline(cloud, compare).report["quality"]["scene"], "object") << "the test no longer shows the case";
}

// PipelineParams::footprint_prism_when_no_model (DECISIONS #174): a building whose points hold no roof plane (two
// facades of a 10 x 8 m footprint, 6 m high, seen by the scanner; the roof unseen: a shed at a tile's edge, under
// trees) makes no model in building mode; on its footprint it is the footprint prism: valid, the footprint's plan
// exactly, from the given ground to the 0.7 quantile of the points' heights, said in the quality. Without the
// footprint, or with the rule off, the run's error stands.
TEST(BuildingRoofs, AFootprintWhoseRunMakesNoModelIsItsPrism) {
  PointCloud cloud;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 0.01);
  for (double z = 0.15; z < 6.0; z += 0.3) {
    for (double x = 0.15; x < 10.0; x += 0.3) cloud.points.emplace_back(x, noise(rng), z);
    for (double y = 0.15; y < 8.0; y += 0.3) cloud.points.emplace_back(noise(rng), y, z);
  }
  std::vector<double> heights;
  for (const Vec3& p : cloud.points) heights.push_back(p.z());
  std::sort(heights.begin(), heights.end());
  PipelineParams params;
  params.scene.mode = SceneMode::Building;
  params.scene.building.ground_z = 0.0;
  params.footprint = {{rectangle(5.0, 4.0, 10.0, 8.0, 0.0), {}}};
  const PipelineResult r = run_pipeline(cloud, params);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  EXPECT_EQ(r.report["quality"]["fallback"], "footprint prism");
  EXPECT_NE(r.report["scene"]["fallback"]["why"].get<std::string>().find("roof"), std::string::npos)
      << r.report["scene"]["fallback"]["why"];
  const BBox box = bounding_box(r.mesh.vertices);
  EXPECT_NEAR(box.min.x(), 0.0, 1e-9);
  EXPECT_NEAR(box.max.x(), 10.0, 1e-9);
  EXPECT_NEAR(box.min.y(), 0.0, 1e-9);
  EXPECT_NEAR(box.max.y(), 8.0, 1e-9);
  EXPECT_NEAR(box.min.z(), 0.0, 1e-12);
  const double roof = r.report["scene"]["fallback"]["roof_z"].get<double>();
  EXPECT_NEAR(box.max.z(), roof, 1e-12);
  EXPECT_GT(roof, heights[heights.size() * 6 / 10]);
  EXPECT_LT(roof, heights[heights.size() * 8 / 10]);
  EXPECT_NEAR(r.eval.validity.volume, 80.0 * roof, 1e-6);

  PipelineParams off = params;
  off.footprint_prism_when_no_model = false;
  PipelineParams no_footprint = params;
  no_footprint.footprint.clear();
  for (const PipelineParams* p : {&off, &no_footprint}) {
    try {
      run_pipeline(cloud, *p);
      ADD_FAILURE() << "the walls alone made a model: the test no longer shows the case";
    } catch (const Error& e) {
      EXPECT_EQ(e.status(), Status::DegenerateInput) << e.one_line();
    }
  }
}

// The runs decided by the result look both ways (BuildingParams::unseen_roof_distance, off by default; DECISIONS #205):
// aerial_steep seed 4 at 4 points/m² with the main direction from the rectangle (#195, off by default). There
// the walls around the roofs (#183) lower p2m (0.259 -> 0.184 %) while they fill the gable's far end up to the
// ridge: an upright fin over the roof's points that no point sees, and step 5's repair no longer beat it by
// p2m (DECISIONS #195, seed 4 traced). With the rule the walled model's unseen surface grows by more than its
// points come closer, it is not kept, and steps 5 and 6 repair the first model: the house within 1 % of its
// truth. Without it the fin stays (model -> truth over 2 %).
TEST(BuildingRoofs, AModelIsKeptOnlyWhereItsPointsSeeIt) {
  SynthParams p;
  p.seed = 4;
  p.aerial_density = 4.0;
  p.aerial_ground = 0;
  p.aerial_trees = 0;
  const SynthScan scan = run_synth("aerial_steep", p);
  SceneParams scene;
  scene.building.main_direction_from_rectangle = true;
  scene.building.unseen_roof_distance = 2.0;  // off by default (DECISIONS #205)
  const PipelineResult r = reconstruct(scan.cloud, &scan.truth, scene);
  ASSERT_TRUE(r.eval.validity.valid()) << r.eval.validity.summary();
  const nlohmann::json& walled = r.report["scene"]["left_out_roofs"];
  EXPECT_FALSE(walled["kept"].get<bool>()) << walled;
  EXPECT_LT(walled["p2m"].get<double>(), 0.95 * walled["p2m_before"].get<double>()) << "p2m alone would keep it";
  // its points 11.7 point-metres closer, its unseen surface 48 more (273 -> 321): not kept
  EXPECT_GT(walled["unseen"].get<double>() - walled["unseen_before"].get<double>(),
            walled["p2m_sum_before"].get<double>() - walled["p2m_sum"].get<double>());
  EXPECT_LT(r.eval.accuracy.mesh_to_truth_mean, 0.01) << "a part was added";
  EXPECT_LT(r.eval.accuracy.truth_to_mesh_mean, 0.01) << "a part is missing";
  scene.building.unseen_roof_distance = 0.0;
  const PipelineResult off = reconstruct(scan.cloud, &scan.truth, scene);
  ASSERT_TRUE(off.eval.validity.valid()) << off.eval.validity.summary();
  EXPECT_TRUE(off.report["scene"]["left_out_roofs"]["kept"].get<bool>());
  EXPECT_FALSE(off.report["scene"]["left_out_roofs"].contains("unseen"));
  EXPECT_GT(off.eval.accuracy.mesh_to_truth_mean, 0.02) << "the test no longer shows the cause";
}

// BuildingParams::gable_halves (DECISIONS #215; off by default, on here): Vaihingen_00004 as shared (58 points at 4 per m², r = 0.87 m) is a
// small gable, its ridge running north-south: the east slope's points and the west slope's upper ones make one
// plane of 42 (the detection's 2 r inlier distance and its leftovers take them over the ridge), the west slope's
// lower points lie on no plane, and the model was a shed. Step 7 splits that plane into the gable's two halves and
// keeps the model by its result: two roof faces sloping away from each other, p2m lower. Off: the shed.
TEST(BuildingRoofs, AGablesSmallerHalfIsNotLostInTheLargerHalfsPlane) {
  const std::string path = airborne_more("Vaihingen_00004.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  ASSERT_EQ(cloud.size(), 58u);
  PipelineParams params;
  params.scene.mode = SceneMode::Building;
  params.scene.building.ground_z = 265.0 - cloud.origin.z();  // City3D's ground
  params.scene.building.gable_halves = true;  // off by default (DECISIONS #215)
  const PipelineResult r = run_pipeline(cloud, params);
  ASSERT_NO_FATAL_FAILURE(step7_split_one_candidate_and_kept(r));
  // two tilted faces facing up, one sloping east, one west
  int east = 0, west = 0;
  for (const auto& face : r.mesh.faces) {
    const Vec3 n = newell_vector(r.mesh.vertices, face).normalized();
    if (n.z() < 0.2 || n.z() > 0.98) continue;
    if (n.x() > 0.2) ++east;
    if (n.x() < -0.2) ++west;
  }
  EXPECT_GE(east, 1);
  EXPECT_GE(west, 1) << "the west slope is on the model";
  PipelineParams off = params;
  off.scene.building.gable_halves = false;
  const PipelineResult o = run_pipeline(cloud, off);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.9 * o.eval.accuracy.p2m_mean);
  EXPECT_FALSE(o.report["scene"].contains("gable_halves"));
}

// BuildingParams::two_surface_planes (DECISIONS #223; off by default, on here): AHN3_08596 as shared (1,224 points, r =
// 0.36 m) is a gable whose north side holds two surfaces, a 38° slope and, beside the ridge's east end, a 16° one.
// The detection's 2 r inlier distance and 25° normals grow both into one plane of 621 points (its points up to
// 0.6 m off it), and the model had one north face. Step 7 splits that plane where two planes explain its points
// (no ridge between them) and keeps the model by its result: a flatter north face beside the steep one, p2m under
// half. Step 6 off: on its own ground step 6 keeps its tighter planes, in whose detection the two surfaces are
// already apart (no candidate there; the city's run with the footprint keeps the first run's, DECISIONS #223).
TEST(BuildingRoofs, TwoSurfacesInOneRoofPlaneAreSplitByTheResult) {
  const std::string path = airborne_more("AHN3_08596.ply");
  if (path.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  const PointCloud cloud = read_points(path);
  ASSERT_EQ(cloud.size(), 1224u);
  PipelineParams params;
  params.scene.building.tighter_planes_distance = 0.0;
  params.scene.building.two_surface_planes = true;  // off by default (DECISIONS #223)
  const PipelineResult r = run_pipeline(cloud, params);
  ASSERT_NO_FATAL_FAILURE(step7_split_one_candidate_and_kept(r));
  // the north faces' tilts (the roof's north side faces +y)
  const auto north_tilts = [](const PolygonMesh& mesh) {
    std::vector<double> tilts;
    for (const auto& face : mesh.faces) {
      const Vec3 n = newell_vector(mesh.vertices, face).normalized();
      if (n.z() > 0.2 && n.y() > 0.1) tilts.push_back(std::acos(n.z()) * 180.0 / M_PI);
    }
    return tilts;
  };
  const std::vector<double> with = north_tilts(r.mesh);
  EXPECT_TRUE(std::any_of(with.begin(), with.end(), [](double t) { return t < 25.0; })) << "the flatter surface";
  EXPECT_TRUE(std::any_of(with.begin(), with.end(), [](double t) { return t > 30.0; })) << "the steep slope";
  PipelineParams off = params;
  off.scene.building.two_surface_planes = false;
  const PipelineResult o = run_pipeline(cloud, off);
  EXPECT_LT(r.eval.accuracy.p2m_mean, 0.5 * o.eval.accuracy.p2m_mean);
  EXPECT_FALSE(o.report["scene"].contains("gable_halves"));
  const std::vector<double> without = north_tilts(o.mesh);
  EXPECT_FALSE(std::any_of(without.begin(), without.end(), [](double t) { return t < 25.0; }))
      << "the test no longer shows the cause";
}

// BuildingParams::split_where_left_far (DECISIONS #228; off by default, on here): step 7 runs only where the model
// kept so far leaves a plane's worth (the detection's smallest plane) of a candidate's halves' points farther than
// 1 r, and bringing them onto their halves would lower p2m by finer_outline_min_gain. AHN3_08596's flatter north
// surface is left far by the one-plane model: the run is made and kept as without the gate. Vaihingen_00004's
// gable (#215; r = 0.87 m): the shed model leaves none of its points farther than 1 r, so the gate refuses the
// run that would split it (the cost of the gate, recorded in #228). Both counted on the kept model only (#239).
TEST(BuildingRoofs, Step7RunsOnlyWhereTheKeptModelLeavesACandidatesPointsFar) {
  const std::string ahn3 = airborne_more("AHN3_08596.ply"), vaihingen = airborne_more("Vaihingen_00004.ply");
  if (ahn3.empty() || vaihingen.empty()) GTEST_SKIP() << "../shared/airborne_more not found";
  {
    const PointCloud cloud = read_points(ahn3);
    PipelineParams params;
    params.scene.building.tighter_planes_distance = 0.0;
    params.scene.building.two_surface_planes = true;
    params.scene.building.split_where_left_far = true;
    const PipelineResult r = run_pipeline(cloud, params);
    ASSERT_NO_FATAL_FAILURE(step7_split_one_candidate_and_kept(r));
    // the report's gate is the one that let step 7 run, the model before it (counted on the kept model, #239),
    // not the split run's own; what the count needed is not left in the result
    ASSERT_TRUE(r.report["scene"].contains("split_gate")) << r.report["scene"].dump();
    EXPECT_TRUE(r.report["scene"]["split_gate"]["run"].get<bool>());
    EXPECT_GE(r.report["counts"]["gable_half_candidates_far"].get<int>(), 1);
    EXPECT_FALSE(r.split_input.has_value());
  }
  {
    const PointCloud cloud = read_points(vaihingen);
    PipelineParams params;
    params.scene.mode = SceneMode::Building;
    params.scene.building.ground_z = 265.0 - cloud.origin.z();  // City3D's ground
    params.scene.building.gable_halves = true;
    params.scene.building.split_where_left_far = true;
    const PipelineResult r = run_pipeline(cloud, params);
    ASSERT_TRUE(r.report["scene"].contains("split_gate")) << r.report["scene"].dump();
    EXPECT_FALSE(r.report["scene"]["split_gate"]["run"].get<bool>());
    EXPECT_EQ(r.report["counts"]["gable_half_candidates"], 1);
    EXPECT_FALSE(r.report["scene"].contains("gable_halves")) << "step 7 did not run";
  }
}
