// Tests of stage 6 (surface extraction) on hand-built exact complexes (tests/extraction/box_complex.h).
#include "extraction/extraction.h"

#include "core/error.h"
#include "extraction/box_complex.h"
#include "test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <random>
#include <sstream>

namespace hsr {
namespace {

using test::BoxComplex;
using test::IBox;
using test::VoxelSet;

constexpr double kPi = 3.14159265358979323846;

struct Extracted {
  BoxComplex bc;
  test::Samples samples;
  std::vector<bool> truth;
  ExtractionResult result;
};

ExtractionInput make_input(const BoxComplex& bc, const test::Samples& s, double spacing) {
  ExtractionInput in;
  in.complex = &bc.cx;
  in.cloud = &s.cloud;
  in.point_plane = &s.plane;
  in.spacing = spacing;
  return in;
}

std::vector<bool> truth_of(const BoxComplex& bc, const VoxelSet& solid) {
  std::vector<bool> t(bc.boxes.size());
  for (std::size_t c = 0; c < bc.boxes.size(); ++c) t[c] = test::box_in_solid(bc.boxes[c], solid);
  return t;
}

/// Samples m x m points per unit square of the true surface (spacing 1/m) and extracts.
Extracted extract_solid(const std::vector<IBox>& boxes, const VoxelSet& solid, bool flat_vertices = false,
                  ExtractionParams params = {}, int m = 8) {
  Extracted run;
  run.bc = test::build_box_complex(boxes, flat_vertices);
  run.truth = truth_of(run.bc, solid);
  run.samples = test::sample_boundary(run.bc, run.truth, m);
  run.result = run_extraction(make_input(run.bc, run.samples, 1.0 / m), params);
  return run;
}

long solid_volume(const VoxelSet& s) { return static_cast<long>(s.size()); }

void expect_valid_surface(const ExtractionResult& r) {
  EXPECT_TRUE(test::closed_and_oriented(r.mesh));
  EXPECT_TRUE(test::vertices_are_manifold(r.mesh));
  EXPECT_EQ(r.non_manifold_edges, 0u);
  EXPECT_EQ(r.non_manifold_vertices, 0u);
  EXPECT_EQ(r.output_faces, r.mesh.faces.size());
  for (const auto& f : r.mesh.faces) EXPECT_TRUE(test::face_is_simple(r.mesh, f));
  EXPECT_TRUE(test::t_junction_free(r.mesh));
  std::vector<int> used(r.mesh.vertices.size(), 0);
  for (const auto& f : r.mesh.faces)
    for (auto v : f) used[v] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0) << "unused vertices in the output";
}

VoxelSet voxels(std::initializer_list<std::array<int, 3>> list) { return VoxelSet(list); }

// ------------------------------------------------------------------------------------------------------------

TEST(Extraction, CentralCellOfGridIsTheOnlyInsideCell) {
  const auto boxes = test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3});
  const VoxelSet solid = voxels({{1, 1, 1}});
  for (bool merge : {true, false}) {
    ExtractionParams params;
    params.merge_coplanar = merge;
    const Extracted run = extract_solid(boxes, solid, false, params);
    EXPECT_EQ(run.result.inside, run.truth);
    EXPECT_EQ(std::count(run.result.inside.begin(), run.result.inside.end(), true), 1);
    EXPECT_EQ(run.result.surface_facets, 6u);
    EXPECT_EQ(run.result.mesh.faces.size(), 6u);
    EXPECT_EQ(run.result.mesh.vertices.size(), 8u);
    EXPECT_EQ(run.result.voting_points, run.samples.cloud.size());
    EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 1.0, 1e-12);
    expect_valid_surface(run.result);
  }
}

TEST(Extraction, BlockOfCellsMergesIntoSixFaces) {
  const auto boxes = test::grid_boxes(test::iota_coords(4), test::iota_coords(4), test::iota_coords(4));
  VoxelSet solid;
  for (int x = 1; x <= 2; ++x)
    for (int y = 1; y <= 2; ++y)
      for (int z = 1; z <= 2; ++z) solid.insert({x, y, z});
  const Extracted run = extract_solid(boxes, solid);
  EXPECT_EQ(run.result.inside, run.truth);
  EXPECT_EQ(run.result.surface_facets, 24u);
  EXPECT_EQ(run.result.mesh.faces.size(), 6u);
  EXPECT_EQ(run.result.mesh.vertices.size(), 8u);  // mid-edge and mid-face vertices dropped
  EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 8.0, 1e-12);
  expect_valid_surface(run.result);

  ExtractionParams unmerged;
  unmerged.merge_coplanar = false;
  const Extracted raw = extract_solid(boxes, solid, false, unmerged);
  EXPECT_EQ(raw.result.mesh.faces.size(), 24u);
  EXPECT_NEAR(test::enclosed_volume(raw.result.mesh), 8.0, 1e-12);
  expect_valid_surface(raw.result);
}

TEST(Extraction, ExtrudedLHasEightFaces) {
  const auto boxes = test::grid_boxes(test::iota_coords(4), test::iota_coords(4), test::iota_coords(3));
  const VoxelSet solid = voxels({{1, 1, 1}, {2, 1, 1}, {1, 2, 1}});
  const Extracted run = extract_solid(boxes, solid);
  EXPECT_EQ(run.result.inside, run.truth);
  EXPECT_EQ(run.result.mesh.faces.size(), 8u);
  EXPECT_EQ(run.result.mesh.vertices.size(), 12u);
  EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 3.0, 1e-12);
  expect_valid_surface(run.result);
}

// A step (an L extruded along y), on a grid and on a kd-tree tiling: 8 faces, 12 corners.
TEST(Extraction, StepHasEightFaces) {
  const VoxelSet solid = voxels({{1, 1, 1}, {2, 1, 1}, {1, 1, 2}});
  for (bool kd : {false, true}) {
    const auto boxes = kd ? test::kd_boxes({4, 3, 4}, solid, 7)
                          : test::grid_boxes(test::iota_coords(4), test::iota_coords(3), test::iota_coords(4));
    const Extracted run = extract_solid(boxes, solid);
    EXPECT_EQ(run.result.inside, run.truth);
    EXPECT_EQ(run.result.mesh.faces.size(), 8u);
    EXPECT_EQ(run.result.mesh.vertices.size(), 12u);
    EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 3.0, 1e-12);
    expect_valid_surface(run.result);
  }
}

// Without merging, the facets of a non-conforming tiling meet in T-junctions: a corner of one facet lies
// inside an edge of its neighbour. Those vertices must be inserted into the neighbour's loop (so some faces
// get more than 4 vertices although every facet is a rectangle), and the mesh must be closed.
TEST(Extraction, UnmergedFacetsGetTJunctionVertices) {
  const VoxelSet solid = voxels({{1, 1, 1}, {2, 1, 1}, {1, 2, 1}, {2, 2, 1}, {1, 1, 2}, {2, 1, 2}, {1, 1, 3}});
  ExtractionParams params;
  params.merge_coplanar = false;
  std::size_t faces_with_t_vertices = 0;
  for (std::uint64_t seed = 1; seed <= 8; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    const Extracted run = extract_solid(test::kd_boxes({4, 4, 5}, solid, seed), solid, false, params);
    EXPECT_EQ(run.result.inside, run.truth);
    EXPECT_EQ(run.result.mesh.faces.size(), run.result.surface_facets);
    EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 7.0, 1e-12);
    expect_valid_surface(run.result);
    for (const auto& f : run.result.mesh.faces) faces_with_t_vertices += f.size() > 4;
  }
  EXPECT_GT(faces_with_t_vertices, 0u);
}

// Non-conforming kd-tree tilings: facets of neighbouring cells meet in T-junctions inside the complex.
TEST(Extraction, NonConformingTilingsGiveTheExpectedClosedSurface) {
  const std::vector<VoxelSet> solids = {
      voxels({{2, 2, 2}}),
      voxels({{1, 1, 1}, {2, 1, 1}, {1, 2, 1}}),
      // a plus sign, two voxels thick
      voxels({{2, 1, 1}, {1, 2, 1}, {2, 2, 1}, {3, 2, 1}, {2, 3, 1}, {2, 1, 2}, {1, 2, 2}, {2, 2, 2}, {3, 2, 2}, {2, 3, 2}}),
      // a staircase
      voxels({{1, 1, 1}, {2, 1, 1}, {3, 1, 1}, {1, 1, 2}, {2, 1, 2}, {1, 1, 3}, {1, 2, 1}, {2, 2, 1}, {3, 2, 1}}),
  };
  for (std::size_t s = 0; s < solids.size(); ++s)
    for (std::uint64_t seed = 1; seed <= 6; ++seed)
      for (bool flat : {false, true}) {
        SCOPED_TRACE("solid " + std::to_string(s) + " seed " + std::to_string(seed) + (flat ? " flat" : " bare"));
        const auto boxes = test::kd_boxes({5, 5, 5}, solids[s], seed);
        const Extracted run = extract_solid(boxes, solids[s], flat);
        EXPECT_EQ(run.result.inside, run.truth);
        EXPECT_EQ(run.result.mesh.faces.size(), test::expected_face_count(solids[s]));
        EXPECT_NEAR(test::enclosed_volume(run.result.mesh), double(solid_volume(solids[s])), 1e-9);
        expect_valid_surface(run.result);
      }
}

// A ring of 8 cells around an outside cell: the top and bottom regions have a hole. They must not become
// keyhole polygons: each is split into several simple polygons, and the surface stays closed.
TEST(Extraction, RegionWithHoleIsSplitIntoSimplePolygons) {
  VoxelSet ring;
  for (int x = 1; x <= 3; ++x)
    for (int y = 1; y <= 3; ++y)
      if (x != 2 || y != 2) ring.insert({x, y, 1});
  for (bool kd : {false, true}) {
    const auto boxes = kd ? test::kd_boxes({5, 5, 3}, ring, 3)
                          : test::grid_boxes(test::iota_coords(5), test::iota_coords(5), test::iota_coords(3));
    const Extracted run = extract_solid(boxes, ring);
    EXPECT_EQ(run.result.inside, run.truth);
    EXPECT_NEAR(test::enclosed_volume(run.result.mesh), 8.0, 1e-12);
    expect_valid_surface(run.result);
    int top = 0, bottom = 0;
    for (const auto& f : run.result.mesh.faces) {
      EXPECT_FALSE(test::has_repeated_vertex(f));
      bool all_top = true, all_bottom = true;
      for (auto v : f) {
        all_top = all_top && run.result.mesh.vertices[v].z() == 2.0;
        all_bottom = all_bottom && run.result.mesh.vertices[v].z() == 1.0;
      }
      top += all_top;
      bottom += all_bottom;
    }
    EXPECT_GE(top, 2);
    EXPECT_GE(bottom, 2);
    // 8 outer/inner walls (4 outside, 4 facing the hole), each one merged rectangle.
    EXPECT_EQ(run.result.mesh.faces.size() - top - bottom, 8u);
  }
}

// λ trades the area of the surface against point support. A bump cell on top of a block, supported by k
// points on its top only: labelling it inside saves k point votes (k π r² / A) and costs the area of its 4
// unsupported sides plus its top's unsupported area minus the unsupported facet below it,
// λ (4 + (1 − k π r²) − 1) / A. So it stays iff λ < λ* = k π r² / (3 + 1 − k π r²).
TEST(Extraction, LargeLambdaRemovesAWeaklySupportedBump) {
  const auto boxes = test::grid_boxes(test::iota_coords(5), test::iota_coords(5), test::iota_coords(4));
  VoxelSet block;
  for (int x = 1; x <= 3; ++x)
    for (int y = 1; y <= 3; ++y) block.insert({x, y, 1});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> block_truth = truth_of(bc, block);
  const int m = 10;
  const double r = 1.0 / m;
  test::Samples samples;
  int bump = -1, under = -1;
  for (std::size_t c = 0; c < bc.boxes.size(); ++c) {
    if (bc.boxes[c].lo == std::array<int, 3>{2, 2, 2}) bump = int(c);
    if (bc.boxes[c].lo == std::array<int, 3>{2, 2, 1}) under = int(c);
  }
  ASSERT_GE(bump, 0);
  ASSERT_GE(under, 0);
  const int k = 5;
  for (std::size_t f = 0; f < bc.cx.facets.size(); ++f) {
    const auto& cells = bc.cx.facets[f].cells;
    const bool pos_in = cells[0] >= 0 && block_truth[cells[0]], neg_in = cells[1] >= 0 && block_truth[cells[1]];
    if (cells[0] == bump && cells[1] == under) continue;  // occluded by the bump: no points
    if (cells[1] == bump && bc.facet_axis[f] == 2) {       // bump top: k points
      test::Samples few;
      test::sample_facet(bc, f, 1, Vec3::UnitZ(), few);
      for (int i = 0; i < k; ++i) {
        samples.cloud.points.push_back(few.cloud.points[0] + Vec3(0.1 * (i - 2), 0.05, 0));
        samples.cloud.normals.push_back(Vec3::UnitZ());
        samples.plane.push_back(few.plane[0]);
      }
      continue;
    }
    if (pos_in == neg_in) continue;
    const Vec3 axis_dir = Vec3::Unit(bc.facet_axis[f]);
    test::sample_facet(bc, f, m, pos_in ? Vec3(-axis_dir) : axis_dir, samples);
  }
  const double kpr2 = k * kPi * r * r;
  const double lambda_star = kpr2 / (4.0 - kpr2);
  ASSERT_LT(lambda_star, 0.5);
  const ExtractionInput in = make_input(bc, samples, r);
  for (double lambda : {0.0, 0.5 * lambda_star, 2.0 * lambda_star, 0.5, 1.0}) {
    SCOPED_TRACE("lambda " + std::to_string(lambda));
    ExtractionParams params;
    params.lambda = lambda;
    const ExtractionResult res = run_extraction(in, params);
    std::vector<bool> expected = block_truth;
    expected[bump] = lambda < lambda_star;
    EXPECT_EQ(res.inside, expected);
    expect_valid_surface(res);
    EXPECT_NEAR(test::enclosed_volume(res.mesh), lambda < lambda_star ? 10.0 : 9.0, 1e-12);
  }
}

// The energy of eqs. 2–4, computed here from the test's own knowledge of which facet each point lies on.
struct TinyProblem {
  BoxComplex bc;
  test::Samples samples;
  std::vector<int> point_facet;
  double spacing = 0;
  double lambda = 0;
};

double independent_energy(const TinyProblem& p, const std::vector<bool>& inside) {
  const CellComplex& cx = p.bc.cx;
  double total_area = 0;
  for (double a : p.bc.facet_area) total_area += a;
  const double pr2 = kPi * p.spacing * p.spacing;
  std::vector<int> agree(cx.facets.size(), 0), oppose(cx.facets.size(), 0);
  for (std::size_t i = 0; i < p.point_facet.size(); ++i) {
    const int f = p.point_facet[i];
    const double d = p.samples.cloud.normals[i].dot(Vec3::Unit(p.bc.facet_axis[f]));
    (d > 0 ? agree : oppose)[f] += 1;
  }
  auto label = [&](int c) { return c >= 0 && inside[c]; };
  double point_term = 0, area_term = 0;
  for (std::size_t f = 0; f < cx.facets.size(); ++f) {
    const bool pos_in = label(cx.facets[f].cells[0]), neg_in = label(cx.facets[f].cells[1]);
    // each point counted once per end cell whose label contradicts it (normal points inside -> outside)
    point_term += agree[f] * (int(pos_in) + int(!neg_in)) + oppose[f] * (int(!pos_in) + int(neg_in));
    if (pos_in != neg_in) area_term += std::max(0.0, p.bc.facet_area[f] - pr2 * (agree[f] + oppose[f]));
  }
  return pr2 / total_area * point_term + p.lambda * area_term / total_area;
}

TEST(Extraction, MaxFlowMatchesBruteForceMinimum) {
  std::mt19937_64 rng(12345);
  auto uniform = [&](double lo, double hi) { return lo + (hi - lo) * double(rng() >> 11) * 0x1.0p-53; };
  const std::vector<std::vector<IBox>> complexes = {
      test::grid_boxes({0, 1, 2}, {0, 1, 2}, {0, 1, 2}),           // 8 cells
      test::grid_boxes({0, 1, 3, 4}, {0, 2, 3, 4}, {0, 1}),        // 9 cells, unequal areas
      test::grid_boxes({0, 2, 3}, {0, 1, 2, 3}, {0, 1}),           // 6 cells
  };
  int solved = 0, degenerate = 0, repaired_trials = 0;
  for (int trial = 0; trial < 60; ++trial) {
    TinyProblem p;
    p.bc = test::build_box_complex(complexes[trial % complexes.size()]);
    // Every cell of these small complexes touches the box, whose walls carry no points and cost area:
    // keep λ small and r large enough that inside cells occur.
    p.spacing = uniform(0.15, 0.5);
    p.lambda = uniform(0.0, 0.3);
    std::vector<std::size_t> interior;
    for (std::size_t f = 0; f < p.bc.cx.facets.size(); ++f)
      if (p.bc.cx.facets[f].cells[0] >= 0 && p.bc.cx.facets[f].cells[1] >= 0) interior.push_back(f);
    // Points mostly tell the truth about a random labelling (normal from its inside cell to its outside
    // cell), with some noise points anywhere, so that optima are neither trivial nor always empty.
    const std::size_t ncells = p.bc.cx.cells.size();
    std::vector<bool> truth(ncells);
    for (std::size_t c = 0; c < ncells; ++c) truth[c] = rng() % 3 == 0;
    const int npoints = 5 + static_cast<int>(rng() % 60);
    for (int i = 0; i < npoints; ++i) {
      const std::size_t f = interior[rng() % interior.size()];
      const int axis = p.bc.facet_axis[f], u = (axis + 1) % 3, v = (axis + 2) % 3;
      const bool pos_in = truth[p.bc.cx.facets[f].cells[0]], neg_in = truth[p.bc.cx.facets[f].cells[1]];
      double side = (rng() & 1) ? 1.0 : -1.0;
      if (pos_in != neg_in && rng() % 5 != 0) side = pos_in ? -1.0 : 1.0;
      Vec3 q;
      q[axis] = p.bc.facet_lo[f][axis];
      q[u] = uniform(p.bc.facet_lo[f][u] + 0.01, p.bc.facet_hi[f][u] - 0.01);
      q[v] = uniform(p.bc.facet_lo[f][v] + 0.01, p.bc.facet_hi[f][v] - 0.01);
      // normals tilted a little (only their side of the plane matters)
      Vec3 n = Vec3::Unit(axis) * side + Vec3(uniform(-0.3, 0.3), uniform(-0.3, 0.3), uniform(-0.3, 0.3));
      p.samples.cloud.points.push_back(q);
      p.samples.cloud.normals.push_back(n.normalized());
      p.samples.plane.push_back(p.bc.input_id.at({axis, p.bc.facet_lo[f][axis]}));
      p.point_facet.push_back(int(f));
    }
    const std::size_t n = p.bc.cx.cells.size();
    double best = std::numeric_limits<double>::infinity();
    for (std::uint32_t mask = 0; mask < (1u << n); ++mask) {
      std::vector<bool> x(n);
      for (std::size_t c = 0; c < n; ++c) x[c] = (mask >> c) & 1;
      best = std::min(best, independent_energy(p, x));
    }
    const ExtractionInput in = make_input(p.bc, p.samples, p.spacing);
    ExtractionParams params;
    params.lambda = p.lambda;
    // The public energy agrees with the independent one on random labellings.
    for (int k = 0; k < 4; ++k) {
      std::vector<bool> x(n);
      for (std::size_t c = 0; c < n; ++c) x[c] = rng() & 1;
      EXPECT_NEAR(extraction_energy(in, params, x), independent_energy(p, x), 1e-12);
    }
    params.repair_non_manifold = false;  // the exact optimum, whatever its topology
    try {
      const ExtractionResult res = run_extraction(in, params);
      ++solved;
      EXPECT_EQ(res.repaired_cells, 0u);
      EXPECT_NEAR(res.energy, best, 1e-12) << "trial " << trial;
      EXPECT_NEAR(independent_energy(p, res.inside), best, 1e-12) << "trial " << trial;
      EXPECT_TRUE(test::closed_and_oriented(res.mesh) || res.non_manifold_edges > 0) << "trial " << trial;
      // With the repair, the labelling may cost more but the surface is a closed 2-manifold.
      ExtractionParams repaired = params;
      repaired.repair_non_manifold = true;
      const ExtractionResult rep = run_extraction(in, repaired);
      EXPECT_GE(rep.energy, best - 1e-12);
      EXPECT_EQ(rep.repaired_cells == 0, rep.inside == res.inside);
      EXPECT_TRUE(test::closed_and_oriented(rep.mesh)) << "trial " << trial;
      EXPECT_TRUE(test::vertices_are_manifold(rep.mesh)) << "trial " << trial;
      repaired_trials += rep.repaired_cells > 0;
    } catch (const Error& e) {
      ++degenerate;
      EXPECT_EQ(e.status(), Status::DegenerateInput);
      EXPECT_NEAR(independent_energy(p, std::vector<bool>(n, false)), best, 1e-12) << "trial " << trial;
    }
  }
  EXPECT_GT(repaired_trials, 0);  // the repair was exercised
  EXPECT_GT(solved, 30);  // the instances are not all trivial
}

// Two cubes touching along an edge (or at a corner) are the optimum for their points, but their union is
// not a 2-manifold. Without the repair the defect is reported; with it, cells are flipped until the surface
// is a closed 2-manifold.
TEST(Extraction, RepairsCellsTouchingAlongAnEdgeOrAtAVertex) {
  const auto boxes = test::grid_boxes(test::iota_coords(4), test::iota_coords(4), test::iota_coords(4));
  for (bool corner : {false, true}) {
    SCOPED_TRACE(corner ? "vertex contact" : "edge contact");
    const VoxelSet solid = corner ? voxels({{1, 1, 1}, {2, 2, 2}}) : voxels({{1, 1, 1}, {2, 2, 1}});
    ExtractionParams raw_params;
    raw_params.repair_non_manifold = false;
    const Extracted raw = extract_solid(boxes, solid, false, raw_params);
    EXPECT_EQ(raw.result.inside, raw.truth);
    EXPECT_EQ(raw.result.repaired_cells, 0u);
    EXPECT_EQ(raw.result.non_manifold_edges, corner ? 0u : 1u);
    EXPECT_EQ(raw.result.non_manifold_vertices, corner ? 1u : 0u);
    if (corner) EXPECT_FALSE(test::vertices_are_manifold(raw.result.mesh));
    else EXPECT_FALSE(test::closed_and_oriented(raw.result.mesh));

    const Extracted fixed = extract_solid(boxes, solid);
    EXPECT_GT(fixed.result.repaired_cells, 0u);
    EXPECT_GT(fixed.result.energy, raw.result.energy);
    EXPECT_EQ(fixed.result.non_manifold_edges, 0u);
    EXPECT_EQ(fixed.result.non_manifold_vertices, 0u);
    EXPECT_TRUE(test::closed_and_oriented(fixed.result.mesh));
    EXPECT_TRUE(test::vertices_are_manifold(fixed.result.mesh));
    for (const auto& f : fixed.result.mesh.faces) EXPECT_TRUE(test::face_is_simple(fixed.result.mesh, f));
    const long inside = std::count(fixed.result.inside.begin(), fixed.result.inside.end(), true);
    EXPECT_NEAR(test::enclosed_volume(fixed.result.mesh), double(inside), 1e-12);
  }
}

// Random solids (with holes, tunnels, diagonal contacts) on random non-conforming tilings, with and without
// flat vertices in the facet loops: whatever the labels end up being, the output is a closed, oriented
// 2-manifold of simple, T-junction-free polygons enclosing exactly the inside cells.
TEST(Extraction, RandomSolidsGiveValidSurfaces) {
  std::size_t repaired = 0, holed_faces = 0;
  for (std::uint64_t seed = 1; seed <= 100; ++seed) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    std::mt19937_64 rng(seed);
    VoxelSet solid;
    for (int x = 1; x < 5; ++x)
      for (int y = 1; y < 5; ++y)
        for (int z = 1; z < 4; ++z)
          if (rng() % 100 < 45) solid.insert({x, y, z});
    if (solid.empty()) continue;
    const auto boxes = test::kd_boxes({6, 6, 5}, solid, seed);
    ExtractionParams params;
    params.merge_coplanar = seed % 5 != 0;
    const Extracted run = extract_solid(boxes, solid, seed % 2 == 0, params, 4);
    expect_valid_surface(run.result);
    double inside_volume = 0;
    for (std::size_t c = 0; c < run.bc.boxes.size(); ++c)
      if (run.result.inside[c]) inside_volume += double(run.bc.boxes[c].volume());
    EXPECT_NEAR(test::enclosed_volume(run.result.mesh), inside_volume, 1e-9);
    if (run.result.repaired_cells == 0) EXPECT_EQ(run.result.inside, run.truth);
    repaired += run.result.repaired_cells > 0;
    holed_faces += run.result.mesh.faces.size() > test::expected_face_count(solid);
  }
  EXPECT_GT(repaired, 0u);
}

TEST(Extraction, IsDeterministic) {
  const VoxelSet solid = voxels({{1, 1, 1}, {2, 1, 1}, {1, 2, 1}, {1, 1, 2}, {3, 3, 3}, {3, 3, 2}});
  const auto boxes = test::kd_boxes({5, 5, 5}, solid, 11);
  const Extracted a = extract_solid(boxes, solid), b = extract_solid(boxes, solid);
  EXPECT_EQ(a.result.inside, b.result.inside);
  EXPECT_EQ(a.result.mesh.faces, b.result.mesh.faces);
  ASSERT_EQ(a.result.mesh.vertices.size(), b.result.mesh.vertices.size());
  for (std::size_t i = 0; i < a.result.mesh.vertices.size(); ++i) EXPECT_EQ(a.result.mesh.vertices[i], b.result.mesh.vertices[i]);
  EXPECT_EQ(a.result.energy, b.result.energy);
}

TEST(Extraction, ReportsBadAndDegenerateInput) {
  const BoxComplex bc = test::build_box_complex(test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3}));
  test::Samples none;
  auto status_of = [](const ExtractionInput& in) {
    try {
      run_extraction(in, {});
    } catch (const Error& e) {
      return e.status();
    }
    return Status::Ok;
  };
  EXPECT_EQ(status_of(make_input(bc, none, 0.1)), Status::DegenerateInput);  // no support: all outside
  EXPECT_EQ(status_of(make_input(bc, none, 0.0)), Status::BadInput);
  test::Samples no_normals;
  no_normals.cloud.points.push_back(Vec3(1.5, 1.5, 1));
  no_normals.plane.push_back(-1);
  EXPECT_EQ(status_of(make_input(bc, no_normals, 0.1)), Status::BadInput);
  test::Samples mismatch;
  mismatch.cloud.points.push_back(Vec3(1.5, 1.5, 1));
  mismatch.cloud.normals.push_back(Vec3::UnitZ());
  EXPECT_EQ(status_of(make_input(bc, mismatch, 0.1)), Status::BadInput);
}

// Two cells split by x = 1; points on it with normals +x say "cell x<1 inside, cell x>1 outside". The
// surface is then the unit cube made of the split facet and five box-side facets (walls of the outside node).
TEST(Extraction, TwoCellsSplitByOnePlane) {
  const BoxComplex bc = test::build_box_complex(test::grid_boxes({0, 1, 2}, {0, 1}, {0, 1}));
  test::Samples s;
  for (std::size_t f = 0; f < bc.cx.facets.size(); ++f)
    if (bc.cx.facets[f].cells[0] >= 0 && bc.cx.facets[f].cells[1] >= 0) test::sample_facet(bc, f, 4, Vec3::UnitX(), s);
  ASSERT_EQ(s.cloud.size(), 16u);
  const ExtractionResult res = run_extraction(make_input(bc, s, 0.25), {});
  EXPECT_EQ(res.inside, (std::vector<bool>{true, false}));
  EXPECT_EQ(res.surface_facets, 6u);
  EXPECT_EQ(res.mesh.faces.size(), 6u);
  EXPECT_NEAR(test::enclosed_volume(res.mesh), 1.0, 1e-12);
  expect_valid_surface(res);
  // Reversed normals flip the labels.
  for (auto& n : s.cloud.normals) n = -n;
  const ExtractionResult flipped = run_extraction(make_input(bc, s, 0.25), {});
  EXPECT_EQ(flipped.inside, (std::vector<bool>{false, true}));
  EXPECT_NEAR(test::enclosed_volume(flipped.mesh), 1.0, 1e-12);
}

TEST(Extraction, LabelsDumpListsEveryCellFacet) {
  const auto boxes = test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3});
  const Extracted run = extract_solid(boxes, voxels({{1, 1, 1}}));
  std::filesystem::create_directories(HSR_TEST_TMP_DIR);
  const std::string path = std::string(HSR_TEST_TMP_DIR) + "/labels.ply";
  write_labels_dump(run.bc.cx, run.result.inside, path);
  std::ifstream in(path);
  ASSERT_TRUE(in.good());
  std::string line;
  std::size_t vertices = 0, faces = 0;
  while (std::getline(in, line) && line != "end_header") {
    std::istringstream ls(line);
    std::string a, b;
    std::size_t n = 0;
    ls >> a >> b >> n;
    if (a == "element" && b == "vertex") vertices = n;
    if (a == "element" && b == "face") faces = n;
  }
  std::size_t expected_faces = 0, expected_vertices = 0;
  for (const auto& c : run.bc.cx.cells) {
    expected_faces += c.facets.size();
    for (auto f : c.facets) expected_vertices += run.bc.cx.facets[f].vertices.size();
  }
  EXPECT_EQ(faces, expected_faces);
  EXPECT_EQ(vertices, expected_vertices);
  for (std::size_t i = 0; i < vertices; ++i) std::getline(in, line);
  std::size_t red = 0, read_faces = 0;
  while (std::getline(in, line)) {
    std::istringstream ls(line);
    std::size_t n;
    ls >> n;
    std::size_t idx;
    for (std::size_t i = 0; i < n; ++i) ls >> idx;
    int r, g, b, cell, inside;
    ls >> r >> g >> b >> cell >> inside;
    ++read_faces;
    EXPECT_EQ(inside != 0, bool(run.result.inside[cell]));
    red += inside != 0;
  }
  EXPECT_EQ(read_faces, faces);
  EXPECT_EQ(red, 6u);  // the central cell's 6 facets
}


// ------------------------------------------------------------------------------------------------------------
// Building mode (DESIGN.md §4): the solid is what lies under the roofs, down to the ground.

/// Points only on the up-facing boundary facets of `truth` (an aerial scan: roofs, no walls, no bottom).
test::Samples roof_samples(const BoxComplex& bc, const std::vector<bool>& truth, int m) {
  test::Samples all = test::sample_boundary(bc, truth, m), roofs;
  for (std::size_t i = 0; i < all.cloud.size(); ++i)
    if (all.cloud.normals[i].z() > 0.5) {
      roofs.cloud.points.push_back(all.cloud.points[i]);
      roofs.cloud.normals.push_back(all.cloud.normals[i]);
      roofs.plane.push_back(all.plane[i]);
    }
  return roofs;
}

/// No inside cell above a non-vertical facet whose lower cell is outside (the building orders hold).
bool nothing_floats(const CellComplex& cx, const std::vector<bool>& inside) {
  for (const Facet& f : cx.facets) {
    if (f.cells[0] < 0 || f.cells[1] < 0) continue;
    const Vec3 n = cx.planes[static_cast<std::size_t>(f.plane)].approx.normal;
    if (std::abs(n.z()) < 0.5) continue;
    const int upper = n.z() > 0 ? f.cells[0] : f.cells[1], lower = n.z() > 0 ? f.cells[1] : f.cells[0];
    if (inside[upper] && !inside[lower]) return false;
  }
  return true;
}

TEST(Extraction, AFaceARuleVouchesForPaysItsShareOfTheAreaTerm) {
  // Two unit crates seen from above only (their tops sampled, their sides and bottoms unseen), at lambda 1: keeping
  // one costs its five unseen faces' area (5), dropping it its top's votes (pi). A's five faces lie on planes a
  // recovery rule vouches for (x = 1, 2; y = 1, 2; z = 1), B's on no such plane. At vouched_area_weight 0.25 A
  // costs 1.25 and stays, B is air; at 1 both are air and nothing is left.
  const auto boxes = test::grid_boxes({0, 1, 2, 3, 4, 5}, {0, 1, 2, 3, 4, 5}, {0, 1, 2, 3, 4});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> both = truth_of(bc, voxels({{1, 1, 1}, {3, 3, 2}}));
  const std::vector<bool> a_only = truth_of(bc, voxels({{1, 1, 1}}));
  const test::Samples tops = roof_samples(bc, both, 8);
  std::vector<char> vouched(static_cast<std::size_t>(test::input_plane_id_base() + 64), 0);
  for (const auto& [axis, coord] : std::vector<std::pair<int, int>>{{0, 1}, {0, 2}, {1, 1}, {1, 2}, {2, 1}})
    vouched[static_cast<std::size_t>(bc.input_id.at({axis, coord}))] = 1;
  ExtractionInput in = make_input(bc, tops, 1.0 / 8);
  in.vouched = &vouched;
  ExtractionParams params;
  params.lambda = 1.0;
  EXPECT_EQ(test::status_of([&] { run_extraction(in, params); }), Status::DegenerateInput)
      << "at the full area term both crates are air";
  params.vouched_area_weight = 0.25;
  const ExtractionResult r = run_extraction(in, params);
  EXPECT_EQ(r.inside, a_only) << "A, whose faces are vouched for, stays; B does not";
  expect_valid_surface(r);
  ExtractionInput without = make_input(bc, tops, 1.0 / 8);
  EXPECT_EQ(test::status_of([&] { run_extraction(without, params); }), Status::DegenerateInput)
      << "no plane vouched for: the weight applies to none";
  params.vouched_area_weight = -1;
  EXPECT_EQ(test::status_of([&] { run_extraction(in, params); }), Status::BadInput);
}

TEST(ExtractionBuilding, RoofOnlyScanFillsTheColumnDownToTheGround) {
  // A 3x3x3 grid; the building is the central column (two cells high) whose roof alone is scanned.
  const auto boxes = test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> truth = truth_of(bc, voxels({{1, 1, 0}, {1, 1, 1}}));
  const test::Samples roofs = roof_samples(bc, truth, 8);
  ASSERT_GT(roofs.cloud.size(), 0u);

  ExtractionParams object;
  const ExtractionResult floating = run_extraction(make_input(bc, roofs, 1.0 / 8), object);
  // Object mode keeps the cheapest closure: the slab under the roof alone, floating above the ground.
  EXPECT_EQ(std::count(floating.inside.begin(), floating.inside.end(), true), 1);
  EXPECT_FALSE(nothing_floats(bc.cx, floating.inside));

  ExtractionParams building;
  building.building = true;
  const ExtractionResult r = run_extraction(make_input(bc, roofs, 1.0 / 8), building);
  EXPECT_EQ(r.inside, truth);
  EXPECT_TRUE(nothing_floats(bc.cx, r.inside));
  expect_valid_surface(r);
  EXPECT_NEAR(test::enclosed_volume(r.mesh), 2.0, 1e-12);
  // Classes: the roof on top, four walls, the ground at the box's bottom.
  ASSERT_EQ(r.mesh.face_class.size(), r.mesh.faces.size());
  std::map<FaceClass, int> count;
  for (FaceClass c : r.mesh.face_class) ++count[c];
  EXPECT_EQ(count[FaceClass::Roof], 1);
  EXPECT_EQ(count[FaceClass::Wall], 4);
  EXPECT_EQ(count[FaceClass::Ground], 1);
}

TEST(ExtractionBuilding, AStepInTheRoofKeepsBothPartsOnTheGround) {
  // Two columns side by side, 3 and 1 cells high: a tall block and a low annex (roofs only).
  const auto boxes = test::grid_boxes({0, 1, 2, 3, 4}, {0, 1, 2}, {0, 1, 2, 3, 4});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> truth = truth_of(bc, voxels({{1, 0, 0}, {1, 0, 1}, {1, 0, 2}, {2, 0, 0}}));
  ExtractionParams building;
  building.building = true;
  const ExtractionResult r = run_extraction(make_input(bc, roof_samples(bc, truth, 8), 1.0 / 8), building);
  EXPECT_EQ(r.inside, truth);
  EXPECT_NEAR(test::enclosed_volume(r.mesh), 4.0, 1e-12);
  expect_valid_surface(r);
}

TEST(ExtractionBuilding, NeverNothingToEncloseWhenARoofHasPoints) {
  // An area weight so large that the optimum keeps nothing: object mode fails, building mode keeps the best
  // supported cell with what lies under it.
  const auto boxes = test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> truth = truth_of(bc, voxels({{1, 1, 0}, {1, 1, 1}}));
  const test::Samples roofs = roof_samples(bc, truth, 2);
  ExtractionParams object;
  object.lambda = 1000;
  EXPECT_EQ(test::status_of([&] { run_extraction(make_input(bc, roofs, 1.0 / 2), object); }), Status::DegenerateInput);
  ExtractionParams building = object;
  building.building = true;
  const ExtractionResult r = run_extraction(make_input(bc, roofs, 1.0 / 2), building);
  EXPECT_EQ(r.forced_cells, 1u);
  EXPECT_EQ(r.inside, truth);
  EXPECT_TRUE(nothing_floats(bc.cx, r.inside));
  expect_valid_surface(r);
}

TEST(ExtractionBuilding, ATallTowerIsKeptThoughItsWallsWereNotScanned) {
  // A 1 x 1 tower five cells high in a 3 x 3 x 6 grid, roof only. Dropping it costs its roof points' votes,
  // about pi * roof area = 3.1 (units of area / A); keeping it its unscanned walls, lambda * weight * 20:
  // 10 at the full area weight, 2.5 at the wall discount (towers up to ~6 times as tall as wide stand).
  const auto boxes = test::grid_boxes({0, 1, 2, 3}, {0, 1, 2, 3}, {0, 1, 2, 3, 4, 5, 6});
  const BoxComplex bc = test::build_box_complex(boxes);
  const std::vector<bool> truth = truth_of(bc, voxels({{1, 1, 0}, {1, 1, 1}, {1, 1, 2}, {1, 1, 3}, {1, 1, 4}}));
  const test::Samples roofs = roof_samples(bc, truth, 4);
  ExtractionParams building;
  building.building = true;
  building.wall_area_weight = 1.0;
  const ExtractionResult full = run_extraction(make_input(bc, roofs, 1.0 / 4), building);
  EXPECT_EQ(full.forced_cells, 1u) << "at full wall weight the optimum drops the tower (only the fallback keeps it)";
  building.wall_area_weight = ExtractionParams{}.wall_area_weight;
  const ExtractionResult r = run_extraction(make_input(bc, roofs, 1.0 / 4), building);
  EXPECT_EQ(r.forced_cells, 0u) << "at the discount the optimum itself keeps it";
  EXPECT_EQ(r.inside, truth);
  EXPECT_NEAR(test::enclosed_volume(r.mesh), 5.0, 1e-12);
  building.wall_area_weight = -1;
  EXPECT_EQ(test::status_of([&] { run_extraction(make_input(bc, roofs, 1.0 / 4), building); }), Status::BadInput);
}

}  // namespace
}  // namespace hsr
