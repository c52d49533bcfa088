// Stage 1 against the ground truth of the simulated scans (src/synth) and on real scans (shared data).
#include "structure/structure.h"

#include "core/error.h"
#include "core/log.h"
#include "io/io.h"
#include "synth/synth.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <set>
#include <tuple>

namespace hsr {
namespace {

constexpr double kDeg = 3.14159265358979323846 / 180.0;

double angle_deg(const Vec3& a, const Vec3& b) {
  return std::acos(std::clamp(std::abs(a.normalized().dot(b.normalized())), 0.0, 1.0)) / kDeg;
}

// True plane matching a detected plane (normal within max_deg either sign, offset within max_off), or -1.
// The truth lists the two sides of a thin wall as two planes with opposite normals: prefer the same side.
int match(const Plane& p, const std::vector<SynthPlane>& truth, double max_deg, double max_off) {
  int best = -1;
  double best_cost = 1e300;
  for (std::size_t t = 0; t < truth.size(); ++t) {
    const Plane& q = truth[t].plane;
    const double sign = p.normal.dot(q.normal) < 0 ? -1.0 : 1.0;
    const double off = std::abs(sign * p.offset - q.offset);
    if (angle_deg(p.normal, q.normal) > max_deg || off > max_off) continue;
    const double cost = off + (sign < 0 ? max_off : 0.0);
    if (cost < best_cost) { best = static_cast<int>(t); best_cost = cost; }
  }
  return best;
}

struct Case {
  std::string model;
  double noise;
  double max_deg, max_off_r;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.model << " noise " << c.noise; }

class SynthStructure : public ::testing::TestWithParam<Case> {};

// Every true plane holding > 1% of the points is found, and every detected plane is a true one. Planes under
// 0.3 % of the points (the floor before issue 25; the smallest plane is now absolute, 20 points) are at the
// scan's resolution: the room's 8 cm table legs stand 5 cm inside the 6 cm table edge (r = 8 cm), so one
// region takes both and tilts a few degrees; they must be true planes within 10 degrees and 2 r.
TEST_P(SynthStructure, FindsTheTruePlanesAndNoSpuriousOne) {
  const Case c = GetParam();
  SynthParams sp;
  sp.noise = c.noise;
  sp.target_points = 30000;
  const SynthScan scan = run_synth(c.model, sp);
  const SceneStructure s = run_structure(scan.cloud);
  const double tol = c.max_off_r * s.spacing;
  std::vector<std::size_t> count(scan.planes.size(), 0);
  for (int t : scan.point_plane) if (t >= 0) ++count[t];
  std::set<int> found;
  for (std::size_t p = 0; p < s.planes.size(); ++p) {
    const bool small = s.planes[p].inliers.size() < 0.003 * scan.cloud.size();
    const int t = small ? match(s.planes[p].plane, scan.planes, 10.0, 2.0 * s.spacing)
                        : match(s.planes[p].plane, scan.planes, c.max_deg, tol);
    EXPECT_GE(t, 0) << c.model << ": spurious plane " << p << " n=" << s.planes[p].plane.normal.transpose()
                    << " d=" << s.planes[p].plane.offset << " inliers=" << s.planes[p].inliers.size();
    if (t >= 0) found.insert(t);
  }
  for (std::size_t t = 0; t < scan.planes.size(); ++t)
    if (count[t] > 0.01 * scan.cloud.size())
      EXPECT_TRUE(found.count(static_cast<int>(t)))
          << c.model << ": true plane " << t << " (" << count[t] << " points) n=" << scan.planes[t].plane.normal.transpose()
          << " d=" << scan.planes[t].plane.offset << " not found";
  // Inliers agree with the truth labels: a plane's inliers come from its true plane (allow 10% near edges,
  // where faces below the detection size join their neighbour).
  for (const auto& pl : s.planes) {
    const int t = match(pl.plane, scan.planes, c.max_deg, tol);
    if (t < 0 || count[t] <= 0.01 * scan.cloud.size()) continue;
    std::size_t agree = 0;
    for (int i : pl.inliers) agree += scan.point_plane[i] == t;
    EXPECT_GT(agree, 0.9 * pl.inliers.size()) << c.model;
  }
}

// Planes of the truth mesh that touch (two faces, one on each plane, share a vertex).
std::set<std::pair<int, int>> truth_touching(const SynthScan& scan) {
  std::map<std::tuple<double, double, double>, std::set<int>> planes_at_vertex;
  for (const auto& f : scan.truth.faces) {
    Vec3 n = Vec3::Zero();  // Newell normal
    for (std::size_t i = 0; i < f.size(); ++i) n += scan.truth.vertices[f[i]].cross(scan.truth.vertices[f[(i + 1) % f.size()]]);
    n.normalize();
    const double d = -n.dot(scan.truth.vertices[f[0]]);
    int plane = -1;
    for (std::size_t t = 0; t < scan.planes.size(); ++t)
      if (scan.planes[t].plane.normal.dot(n) > 1 - 1e-9 && std::abs(scan.planes[t].plane.offset - d) < 1e-6) plane = static_cast<int>(t);
    if (plane < 0) continue;
    for (auto v : f) {
      const Vec3& p = scan.truth.vertices[v];
      planes_at_vertex[{p.x(), p.y(), p.z()}].insert(plane);
    }
  }
  std::set<std::pair<int, int>> out;
  for (const auto& [v, ps] : planes_at_vertex)
    for (int a : ps) for (int b : ps) if (a < b) out.insert({a, b});
  return out;
}

// Adjacent detected planes are planes whose true faces touch in the model.
TEST_P(SynthStructure, AdjacentPlanesTouchInTheModel) {
  const Case c = GetParam();
  SynthParams sp;
  sp.noise = c.noise;
  sp.target_points = 30000;
  const SynthScan scan = run_synth(c.model, sp);
  const SceneStructure s = run_structure(scan.cloud);
  const auto touching = truth_touching(scan);
  ASSERT_FALSE(touching.empty());
  std::size_t pairs = 0;
  for (std::size_t i = 0; i < s.planes.size(); ++i) {
    const int ti = match(s.planes[i].plane, scan.planes, c.max_deg, c.max_off_r * s.spacing);
    for (int j : s.adjacency[i]) {
      if (j < static_cast<int>(i)) continue;
      const int tj = match(s.planes[j].plane, scan.planes, c.max_deg, c.max_off_r * s.spacing);
      if (ti < 0 || tj < 0) continue;
      ++pairs;
      EXPECT_TRUE(touching.count({std::min(ti, tj), std::max(ti, tj)}))
          << c.model << ": planes " << i << " (true " << ti << ") and " << j << " (true " << tj << ") adjacent";
    }
  }
  EXPECT_GT(pairs, 0u);
}

TEST_P(SynthStructure, Deterministic) {
  const Case c = GetParam();
  SynthParams sp;
  sp.noise = c.noise;
  sp.target_points = 30000;
  const SynthScan scan = run_synth(c.model, sp);
  const SceneStructure a = run_structure(scan.cloud), b = run_structure(scan.cloud);
  EXPECT_EQ(a.point_plane, b.point_plane);
  EXPECT_EQ(a.adjacency, b.adjacency);
  ASSERT_EQ(a.lines.size(), b.lines.size());
  for (std::size_t i = 0; i < a.lines.size(); ++i) EXPECT_EQ(a.lines[i].point, b.lines[i].point);
  for (std::size_t p = 0; p < a.planes.size(); ++p) {
    ASSERT_EQ(a.planes[p].segments.size(), b.planes[p].segments.size());
    for (std::size_t k = 0; k < a.planes[p].segments.size(); ++k) EXPECT_EQ(a.planes[p].segments[k].b, b.planes[p].segments[k].b);
  }
}

std::vector<Case> cases() {
  std::vector<Case> out;
  for (const auto& m : synth_model_names()) {
    out.push_back({m, 0.0, 2.0, 1.0});
    out.push_back({m, SynthParams{}.noise, 5.0, 2.0});
  }
  return out;
}

INSTANTIATE_TEST_SUITE_P(Models, SynthStructure, ::testing::ValuesIn(cases()), [](const auto& info) {
  return info.param.model + (info.param.noise == 0 ? "_exact" : "_noisy");
});

// Box: the adjacency graph equals the true face adjacency; every boundary segment lies within 2r of an edge.
TEST(SynthStructureBox, AdjacencyAndSegmentsMatchTheBox) {
  const SynthScan scan = run_synth("box");
  const SceneStructure s = run_structure(scan.cloud);
  std::size_t seen = 0;  // true planes the scanners saw
  std::vector<std::size_t> count(scan.planes.size(), 0);
  for (int t : scan.point_plane) if (t >= 0) ++count[t];
  for (auto c : count) seen += c > 0;
  ASSERT_EQ(s.planes.size(), seen);
  std::vector<int> truth_of(s.planes.size());
  for (std::size_t p = 0; p < s.planes.size(); ++p) {
    truth_of[p] = match(s.planes[p].plane, scan.planes, 5.0, 2 * s.spacing);
    ASSERT_GE(truth_of[p], 0);
  }
  for (std::size_t i = 0; i < s.planes.size(); ++i)
    for (std::size_t j = i + 1; j < s.planes.size(); ++j) {
      const bool truth = angle_deg(scan.planes[truth_of[i]].plane.normal, scan.planes[truth_of[j]].plane.normal) > 45;
      EXPECT_EQ(s.adjacent(static_cast<int>(i), static_cast<int>(j)), truth) << i << " " << j;
    }
  // A box edge is where the face's plane meets a non-parallel true plane; segments lie on such lines within
  // 2r (the segment's end points, measured to the nearest edge line of the face).
  for (std::size_t p = 0; p < s.planes.size(); ++p) {
    const Plane& face = scan.planes[truth_of[p]].plane;
    for (const auto& seg : s.planes[p].segments) {
      for (const Vec3& e : {seg.a, seg.b}) {
        double best = 1e300;
        for (const auto& other : scan.planes) {
          if (angle_deg(other.plane.normal, face.normal) < 45) continue;
          best = std::min(best, std::abs(other.plane.signed_distance(e)));
        }
        EXPECT_LT(best, 2 * s.spacing) << "plane " << p;
      }
    }
  }
}

// Real scans: runs and reports planes (skips when the shared data is absent).
TEST(RealStructure, ManhattanExample) {
  const std::string path = std::string(HSR_SHARED_DATA_DIR) + "/manhattan_example1.ply";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "shared data absent: " << path;
  const PointCloud cloud = read_points(path);
  const SceneStructure s = run_structure(cloud);
  EXPECT_GE(s.planes.size(), 10u);
  std::size_t assigned = 0;
  for (const auto& p : s.planes) assigned += p.inliers.size();
  EXPECT_GT(assigned, cloud.size() / 2);
  std::size_t edges = 0;
  for (const auto& a : s.adjacency) edges += a.size();
  EXPECT_GT(edges, 0u);
  std::cout << "manhattan_example1: " << s.planes.size() << " planes, " << assigned << "/" << cloud.size()
            << " points assigned, " << edges / 2 << " adjacent pairs, " << s.lines.size() << " lines\n";
}

}  // namespace
}  // namespace hsr
