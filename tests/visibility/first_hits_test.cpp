// Stage 2's ray casting (issue 16): rays against each plane's alpha-shape boundary must meet exactly what
// rays against the alpha triangles themselves meet (the AABB tree of every triangle that stage 2 used
// before), and the same with one thread or many.
#include "core/threads.h"
#include "structure/structure.h"
#include "synth/synth.h"
#include "visibility/visibility.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <gtest/gtest.h>

namespace hsr {
namespace {

using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Iterator>>>;

/// The reference: every Delaunay triangle of each plane's projected inliers with squared circumradius at
/// most radius^2, lifted onto the plane, in one AABB tree; the first triangle of another plane on each ray.
std::vector<std::vector<int>> reference_hits(const PointCloud& cloud, const SceneStructure& s, double radius, int directions,
                                             int keypoints) {
  std::vector<Triangle> triangles;
  std::vector<int> owner;
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    const DetectedPlane& dp = s.planes[i];
    std::vector<K::Point_2> q;
    for (int p : dp.inliers) {
      const Vec2 v = dp.to_2d(cloud.points[static_cast<std::size_t>(p)]);
      q.emplace_back(v.x(), v.y());
    }
    CGAL::Delaunay_triangulation_2<K> dt(q.begin(), q.end());
    for (auto f = dt.finite_faces_begin(); f != dt.finite_faces_end(); ++f) {
      const auto &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
      if (K().compute_squared_radius_2_object()(a, b, c) > radius * radius) continue;
      K::Point_3 lifted[3];
      for (int k = 0; k < 3; ++k) {
        const auto& p = f->vertex(k)->point();
        const Vec3 x = dp.to_3d(Vec2(p.x(), p.y()));
        lifted[k] = K::Point_3(x.x(), x.y(), x.z());
      }
      triangles.emplace_back(lifted[0], lifted[1], lifted[2]);
      owner.push_back(static_cast<int>(i));
    }
  }
  Tree tree(triangles.begin(), triangles.end());
  tree.build();
  const std::vector<Vec3> dirs = fibonacci_directions(directions);
  std::vector<std::vector<int>> hits(s.planes.size());
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    const DetectedPlane& dp = s.planes[i];
    std::vector<Vec3> pts;
    for (int p : dp.inliers) pts.push_back(cloud.points[static_cast<std::size_t>(p)]);
    auto skip = [&](const Iterator& id) { return owner[static_cast<std::size_t>(id - triangles.begin())] == static_cast<int>(i); };
    for (int k : farthest_point_samples(pts, keypoints)) {
      Vec3 o = pts[static_cast<std::size_t>(k)];
      o -= dp.plane.signed_distance(o) * dp.plane.normal;
      for (const Vec3& d : dirs) {
        const auto hit = tree.first_intersection(K::Ray_3(K::Point_3(o.x(), o.y(), o.z()), K::Vector_3(d.x(), d.y(), d.z())), skip);
        hits[i].push_back(hit ? owner[static_cast<std::size_t>(hit->second - triangles.begin())] : -1);
      }
    }
  }
  return hits;
}

TEST(FirstHits, SameAsRaysAgainstEveryAlphaTriangle) {
  for (const char* model : {"house", "room", "courtyard", "dormer_house"}) {
    SynthParams sp;
    sp.target_points = 30000;
    const SynthScan scan = run_synth(model, sp);
    const SceneStructure s = run_structure(scan.cloud, {});
    const VisibilityParams vp;
    const std::vector<std::vector<int>> hits = first_hits(scan.cloud, s, vp);
    const auto want = reference_hits(scan.cloud, s, s.alpha_radius, vp.directions, vp.keypoints);
    ASSERT_EQ(hits.size(), want.size());
    std::size_t rays = 0, met = 0, differ = 0;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      ASSERT_EQ(hits[i].size(), want[i].size()) << model << " plane " << i;
      for (std::size_t k = 0; k < hits[i].size(); ++k) {
        ++rays;
        met += want[i][k] >= 0;
        differ += hits[i][k] != want[i][k];
      }
    }
    EXPECT_EQ(differ, 0u) << model << ": " << differ << " of " << rays << " rays meet another plane than the triangles say";
    EXPECT_GT(met, rays / 10) << model;  // the scene blocks rays: not an empty test
  }
}

TEST(FirstHits, AnotherAlphaRadiusAndOneThread) {
  const SynthScan scan = run_synth("house", {});
  const SceneStructure s = run_structure(scan.cloud, {});
  VisibilityParams vp;
  vp.alpha_radius = 5.0;  // not the structure's: the shapes are rebuilt from the inliers
  const auto hits = first_hits(scan.cloud, s, vp);
  EXPECT_EQ(hits, reference_hits(scan.cloud, s, 5.0 * s.spacing, vp.directions, vp.keypoints));
  const ThreadLimit one(1);
  EXPECT_EQ(first_hits(scan.cloud, s, vp), hits);
}

}  // namespace
}  // namespace hsr
