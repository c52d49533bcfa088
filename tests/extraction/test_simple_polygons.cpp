// The exact proof that output polygons are simple (extraction.h, prove_simple_polygons): known simple and
// non-simple loops on exact vertices, and the thin strip that is simple exactly but not once rounded
// (the polygon class of issue 15's eval crash).
#include "extraction/extraction.h"

#include "core/error.h"

#include <gtest/gtest.h>

#include <numeric>

namespace hsr {
namespace {

/// A complex holding only `corners` (exact) as its vertices, and a mesh with the single face through
/// them in order, its vertices the doubles of the corners (as run_extraction writes them).
struct OneFace {
  CellComplex cx;
  PolygonMesh mesh;
  std::vector<std::int64_t> index;
};

OneFace one_face(const std::vector<ExactPoint>& corners) {
  OneFace f;
  std::vector<std::uint32_t> face;
  for (const ExactPoint& p : corners) {
    f.index.push_back(static_cast<std::int64_t>(f.cx.vertices.size()));
    face.push_back(static_cast<std::uint32_t>(f.cx.vertices.size()));
    f.cx.vertices.push_back(p);
    f.cx.vertices_approx.emplace_back(p.x.get_d(), p.y.get_d(), p.z.get_d());
  }
  f.mesh.vertices = f.cx.vertices_approx;
  f.mesh.faces = {face};
  return f;
}

/// Corners (u, v) of the plane z = u / 3 + v / 7 + 1/11 (rational, tilted), lifted exactly.
std::vector<ExactPoint> tilted(const std::vector<std::pair<Rational, Rational>>& uv) {
  std::vector<ExactPoint> out;
  for (const auto& [u, v] : uv) out.push_back({u, v, u / 3 + v / 7 + Rational(1, 11)});
  return out;
}

std::size_t prove(const std::vector<ExactPoint>& corners) {
  const OneFace f = one_face(corners);
  return prove_simple_polygons(f.cx, f.mesh, f.index);
}

Status status_of_proof(const std::vector<ExactPoint>& corners) {
  try {
    prove(corners);
  } catch (const Error& e) {
    EXPECT_EQ(e.stage(), "extraction");
    return e.status();
  }
  return Status::Ok;
}

TEST(SimplePolygons, ConvexAndNonConvexLoopsWithFlatCornersAreSimple) {
  EXPECT_EQ(prove(tilted({{0, 0}, {1, 0}, {2, 0}, {2, 2}, {0, 2}})), 0u);
  // An L with a flat corner on its notch.
  EXPECT_EQ(prove(tilted({{0, 0}, {2, 0}, {2, 1}, {Rational(3, 2), 1}, {1, 1}, {1, 2}, {0, 2}})), 0u);
  // Clockwise about +z: simple all the same (orientation is eval's business).
  EXPECT_EQ(prove(tilted({{0, 0}, {0, 2}, {2, 2}, {2, 0}})), 0u);
  // A vertical face (the projection drops x).
  EXPECT_EQ(prove({{1, 0, 0}, {1, 2, 0}, {1, 2, 2}, {1, 0, 2}}), 0u);
}

TEST(SimplePolygons, TouchingCrossingAndDegenerateLoopsAreRejected) {
  EXPECT_EQ(status_of_proof(tilted({{0, 0}, {2, 2}, {2, 0}, {0, 2}})), Status::Internal) << "bow tie";
  EXPECT_EQ(status_of_proof(tilted({{0, 0}, {2, 0}, {2, 2}, {1, 2}, {1, 3}, {Rational(1), Rational(5, 2)}, {0, 2}})),
            Status::Internal)
      << "spike going back along its edge";
  // A corner lying on a non-adjacent edge (the loop touches itself there).
  EXPECT_EQ(status_of_proof(tilted({{0, 0}, {4, 0}, {4, 4}, {2, 4}, {2, 0}, {1, 4}, {0, 4}})), Status::Internal);
  EXPECT_EQ(status_of_proof(tilted({{0, 0}, {1, 0}, {2, 0}})), Status::Internal) << "zero area";
  std::vector<ExactPoint> off = tilted({{0, 0}, {2, 0}, {2, 2}, {0, 2}});
  off[2].z += Rational(1, 1000000);
  EXPECT_EQ(status_of_proof(off), Status::Internal) << "a corner off the plane";
}

TEST(SimplePolygons, ThinStripIsSimpleExactlyButNotOnceRounded) {
  // The U-shaped strip of the eval crash (tests/eval/thin_polygons.h): width t, around u = v = 500.
  auto u_strip = [](const Rational& t) {
    const Rational o = 500, w = 30, h = 60;
    return tilted({{o, o}, {o + w, o}, {o + w, o + h}, {o + w - t, o + h}, {o + w - t, o + t}, {o + t, o + t},
                   {o + t, o + h}, {o, o + h}});
  };
  EXPECT_EQ(prove(u_strip(Rational(1, 1000))), 0u);
  // 1e-15 is below the doubles' spacing at 500 (1.1e-13): the rounded legs collapse onto the outline.
  EXPECT_EQ(prove(u_strip(Rational(1, 1000000000000000))), 1u);
}

TEST(SimplePolygons, CornersCloserThanThePrecisionAreReported) {
  // A flat corner 1e-20 from the corner before it: simple exactly, and once rounded it is 1e-20 from the
  // edge that ends there (the doubles cannot keep the two apart).
  EXPECT_EQ(prove(tilted({{0, 0}, {Rational(1, 100000000000000000000_mpz), 0}, {1, 0}, {1, 1}, {0, 1}})), 1u);
  EXPECT_EQ(prove(tilted({{0, 0}, {Rational(1, 1000), 0}, {1, 0}, {1, 1}, {0, 1}})), 0u);
}

}  // namespace
}  // namespace hsr
