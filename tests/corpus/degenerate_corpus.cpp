#include "degenerate_corpus.h"

#include <array>
#include <cmath>
#include <limits>
#include <random>

namespace hsr::corpus {

namespace {

double uniform01(std::mt19937_64& rng) { return static_cast<double>(rng() >> 11) * 0x1.0p-53; }

Vec3 polygon_normal(const Polygon3& p) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 1; i + 1 < p.size(); ++i) n += (p[i] - p[0]).cross(p[i + 1] - p[0]);
  return n;  // twice the area, along the normal
}

PointCloud transformed(PointCloud c, double scale, const Vec3& offset) {
  for (auto& p : c.points) p = p * scale + offset;
  return c;
}

const Vec3 kBoxLo(0, 0, 0), kBoxHi(4, 3, 2);
constexpr double kDensity = 120.0;  // points per unit area on the 4 x 3 x 2 box: about 6000 points

PointCloud box_cloud() { return sample_polygons(box_faces(kBoxLo, kBoxHi), kDensity, 11); }

}  // namespace

PointCloud sample_polygons(const std::vector<Polygon3>& polygons, double density, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  PointCloud cloud;
  for (const Polygon3& poly : polygons) {
    const Vec3 n2 = polygon_normal(poly);
    const double area = 0.5 * n2.norm();
    if (!(area > 0)) continue;
    const Vec3 normal = n2.normalized();
    const auto count = static_cast<std::size_t>(std::max(1.0, std::round(area * density)));
    // Fan triangles, chosen by area.
    std::vector<double> cumulative;
    double total = 0;
    for (std::size_t i = 1; i + 1 < poly.size(); ++i) {
      total += 0.5 * (poly[i] - poly[0]).cross(poly[i + 1] - poly[0]).norm();
      cumulative.push_back(total);
    }
    for (std::size_t k = 0; k < count; ++k) {
      const double pick = uniform01(rng) * total;
      std::size_t t = 0;
      while (t + 1 < cumulative.size() && cumulative[t] < pick) ++t;
      double u = uniform01(rng), v = uniform01(rng);
      if (u + v > 1) { u = 1 - u; v = 1 - v; }
      cloud.points.push_back(poly[0] + u * (poly[t + 1] - poly[0]) + v * (poly[t + 2] - poly[0]));
      cloud.normals.push_back(normal);
    }
  }
  return cloud;
}

std::vector<Polygon3> hip_roof_house() {
  const Vec3 q0(0, 0, 2), q1(4, 0, 2), q2(4, 4, 2), q3(0, 4, 2), apex(2, 2, 4);
  return {{Vec3(0, 0, 0), Vec3(0, 4, 0), Vec3(4, 4, 0), Vec3(4, 0, 0)},
          {Vec3(0, 0, 0), Vec3(4, 0, 0), q1, q0},
          {Vec3(4, 0, 0), Vec3(4, 4, 0), q2, q1},
          {Vec3(4, 4, 0), Vec3(0, 4, 0), q3, q2},
          {Vec3(0, 4, 0), Vec3(0, 0, 0), q0, q3},
          {q0, q1, apex},
          {q1, q2, apex},
          {q2, q3, apex},
          {q3, q0, apex}};
}

double total_area(const std::vector<Polygon3>& polygons) {
  double area = 0;
  for (const Polygon3& p : polygons) area += 0.5 * polygon_normal(p).norm();
  return area;
}

std::vector<Polygon3> box_faces(const Vec3& lo, const Vec3& hi) {
  auto P = [&](int x, int y, int z) { return Vec3(x ? hi.x() : lo.x(), y ? hi.y() : lo.y(), z ? hi.z() : lo.z()); };
  return {
      {P(0, 0, 0), P(0, 0, 1), P(0, 1, 1), P(0, 1, 0)},  // -x
      {P(1, 0, 0), P(1, 1, 0), P(1, 1, 1), P(1, 0, 1)},  // +x
      {P(0, 0, 0), P(1, 0, 0), P(1, 0, 1), P(0, 0, 1)},  // -y
      {P(0, 1, 0), P(0, 1, 1), P(1, 1, 1), P(1, 1, 0)},  // +y
      {P(0, 0, 0), P(0, 1, 0), P(1, 1, 0), P(1, 0, 0)},  // -z
      {P(0, 0, 1), P(1, 0, 1), P(1, 1, 1), P(0, 1, 1)},  // +z
  };
}

std::vector<CorpusCase> degenerate_corpus() {
  std::vector<CorpusCase> cases;
  // Exact face / vertex counts only where the true vertices have three planes each (axis-aligned boxes).
  auto add = [&](std::string name, PointCloud cloud, Status expected, std::size_t faces, std::size_t vertices,
                 std::string why) {
    const bool exact = vertices > 0;
    cases.push_back({std::move(name), std::move(cloud), expected, faces, vertices, exact, std::move(why)});
  };

  add("box_faces_on_bbox", box_cloud(), Status::Ok, 6, 8,
      "every polygon lies exactly on a side of the (tight) partition box");

  {
    PointCloud c = box_cloud();
    const std::size_t n = c.size();
    for (int copy = 0; copy < 2; ++copy)
      for (std::size_t i = 0; i < n; ++i) {
        c.points.push_back(c.points[i]);
        c.normals.push_back(c.normals[i]);
      }
    add("duplicate_points", std::move(c), Status::Ok, 6, 8,
        "every point three times: zero neighbour distances must not break spacing, normals or planes");
  }
  {
    PointCloud c;
    c.points.assign(100, Vec3(1, 2, 3));
    add("all_points_identical", std::move(c), Status::BadInput, 0, 0, "no extent: nothing can be fitted");
  }
  add("empty_cloud", PointCloud{}, Status::BadInput, 0, 0, "zero points");
  {
    PointCloud c = box_cloud();
    c.points[17].y() = std::numeric_limits<double>::quiet_NaN();
    add("nan_coordinate", std::move(c), Status::BadInput, 0, 0, "a NaN coordinate is rejected, not propagated");
  }
  {
    PointCloud c;
    for (int i = 0; i < 500; ++i) c.points.emplace_back(0.01 * i, 0.02 * i, -0.005 * i);
    add("collinear_points", std::move(c), Status::BadInput, 0, 0,
        "points on one line: no normal, no plane is defined");
  }
  // Upright: a level plane seen from above is a roof-only scan, a building (`auto`) whose prism is the model.
  add("single_plane", sample_polygons({{Vec3(0, 0, 0), Vec3(4, 0, 0), Vec3(4, 0, 3), Vec3(0, 0, 3)}}, 200, 3),
      Status::DegenerateInput, 0, 0, "one upright plane cannot enclose a volume");
  add("two_parallel_planes",
      sample_polygons({{Vec3(0, 0, 0), Vec3(0, 3, 0), Vec3(4, 3, 0), Vec3(4, 0, 0)},
                       {Vec3(0, 0, 1), Vec3(4, 0, 1), Vec3(4, 3, 1), Vec3(0, 3, 1)}},
                      200, 4),
      Status::DegenerateInput, 0, 0, "parallel planes only: no volume can be enclosed");
  {
    // Box whose top is two halves meeting at x = 2, the right one tilted down by 0.01 degree.
    const double d = 2.0 * std::tan(0.01 * M_PI / 180.0);
    const Vec3 a(0, 0, 2), b(2, 0, 2), c(4, 0, 2 - d), a1(0, 3, 2), b1(2, 3, 2), c1(4, 3, 2 - d);
    std::vector<Polygon3> polys = {
        {Vec3(0, 0, 0), Vec3(0, 0, 2), Vec3(0, 3, 2), Vec3(0, 3, 0)},                  // -x
        {Vec3(4, 0, 0), Vec3(4, 3, 0), c1, c},                                         // +x
        {Vec3(0, 0, 0), Vec3(4, 0, 0), c, b, a},                                       // -y
        {Vec3(0, 3, 0), a1, b1, c1, Vec3(4, 3, 0)},                                    // +y
        {Vec3(0, 0, 0), Vec3(0, 3, 0), Vec3(4, 3, 0), Vec3(4, 0, 0)},                  // -z
        {a, b, b1, a1},                                                                // top left
        {b, c, c1, b1},                                                                // top right
    };
    add("nearly_coplanar_0.01deg", sample_polygons(polys, kDensity, 5), Status::Ok, 6, 0,
        "two top planes 0.01 degree apart: exact partition, merged or kept, the mesh must stay valid");
  }
  {
    // Square pyramid: its four sides meet in the apex.
    const Vec3 p0(0, 0, 0), p1(4, 0, 0), p2(4, 4, 0), p3(0, 4, 0), apex(2, 2, 3);
    add("pyramid_four_planes_one_point",
        sample_polygons({{p0, p3, p2, p1}, {p0, p1, apex}, {p1, p2, apex}, {p2, p3, apex}, {p3, p0, apex}}, kDensity,
                        6),
        Status::Ok, 5, 0, "four planes through the apex");
  }
  {
    // Regular octahedron: four faces through each of its six vertices; no face on the bbox.
    const Vec3 X(2, 0, 0), Y(0, 2, 0), Z(0, 0, 2);
    std::vector<Polygon3> faces;
    for (int sx : {-1, 1})
      for (int sy : {-1, 1})
        for (int sz : {-1, 1}) {
          Polygon3 f = {sx * X, sy * Y, sz * Z};
          if (sx * sy * sz < 0) std::swap(f[1], f[2]);  // outward orientation
          faces.push_back(f);
        }
    add("octahedron_four_planes_per_vertex", sample_polygons(faces, kDensity, 7), Status::Ok, 8, 0,
        "four planes through each vertex, planes not aligned with the axes");
  }
  add("hip_roof_house", sample_polygons(hip_roof_house(), kDensity, 8), Status::Ok, 9, 0,
      "four roof planes through the apex above four walls");
  {
    // Two triangular prisms touching along the z axis only ("bow tie"): four distinct planes through that
    // line (each prism contributes two sides through it).
    auto prism = [](std::vector<Polygon3>& out, const std::array<Vec3, 3>& t, double z0, double z1) {
      const Vec3 dz0(0, 0, z0), dz1(0, 0, z1);  // t counter-clockwise seen from +z
      out.push_back({t[0] + dz0, t[2] + dz0, t[1] + dz0});
      out.push_back({t[0] + dz1, t[1] + dz1, t[2] + dz1});
      for (int i = 0; i < 3; ++i) {
        const Vec3 a = t[i], b = t[(i + 1) % 3];
        out.push_back({a + dz0, b + dz0, b + dz1, a + dz1});
      }
    };
    std::vector<Polygon3> polys;
    prism(polys, {Vec3(0, 0, 0), Vec3(2, -1, 0), Vec3(2, 1, 0)}, 0, 2);
    prism(polys, {Vec3(0, 0, 0), Vec3(-1, -2, 0), Vec3(1, -2, 0)}, 0, 2);
    add("bowtie_four_planes_one_line", sample_polygons(polys, kDensity, 9), Status::Ok, 6, 0,
        "two prisms sharing only an edge: four planes through one line (the truth is not a manifold: a valid "
        "mesh may keep each cap as one face or fill the wedge between the prisms, so at least 6 faces)");
  }
  add("offset_1e6", transformed(box_cloud(), 1.0, Vec3(1e6, -2e6, 1e6)), Status::Ok, 6, 8,
      "coordinates around 1e6 given directly to the pipeline (no local origin shift)");
  add("size_1e6", transformed(box_cloud(), 1e6, Vec3::Zero()), Status::Ok, 6, 8, "a box 4e6 wide");
  add("size_1e-3", transformed(box_cloud(), 1e-3, Vec3::Zero()), Status::Ok, 6, 8, "a box 4 mm wide");
  {
    PointCloud c = box_cloud();
    c.points.resize(10);
    c.normals.resize(10);
    add("ten_points", std::move(c), Status::NoPlanes, 0, 0, "too few points for any plane");
  }
  return cases;
}

}  // namespace hsr::corpus
