// A building's own frame (BuildingParams::own_frame, pipeline.cpp run_in_own_frame): what the chain is given,
// turned about z, and the model turned back.
#include "pipeline/pipeline_internal.h"

#include <cmath>

namespace hsr::pipeline_detail {

namespace {

Vec3 turn_about_z(const Vec3& p, double c, double s) { return Vec3(c * p.x() - s * p.y(), s * p.x() + c * p.y(), p.z()); }

}  // namespace

double own_frame_turn(double main_direction) {
  // Main directions are modulo 90 degrees: turning by -a or by 90 - a both put the building on the axes; the
  // remainder is the smaller (in [-45, 45] degrees).
  return -std::remainder(main_direction, M_PI / 2.0);
}

std::vector<Vec3> turned_points(const std::vector<Vec3>& points, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  std::vector<Vec3> out;
  out.reserve(points.size());
  for (const Vec3& p : points) out.push_back(turn_about_z(p, c, s));
  return out;
}

PointCloud turned_cloud(const PointCloud& cloud, double angle) {
  PointCloud out = cloud;
  out.points = turned_points(cloud.points, angle);
  out.normals = turned_points(cloud.normals, angle);
  return out;
}

PipelineParams turned_params(const PipelineParams& params, double angle, PolygonMesh& truth) {
  PipelineParams out = params;
  const double c = std::cos(angle), s = std::sin(angle);
  for (FootprintPolygon& f : out.footprint) {
    const auto turn2 = [&](std::vector<Vec2>& ring) {
      for (Vec2& q : ring) q = turn_about_z(Vec3(q.x(), q.y(), 0.0), c, s).head<2>();
    };
    turn2(f.outer);
    for (auto& hole : f.holes) turn2(hole);
  }
  out.structure.scanners = turned_points(params.structure.scanners, angle);
  if (params.truth) {
    truth = *params.truth;
    turn_mesh(truth, angle);
    out.truth = &truth;
  }
  return out;
}

void turn_mesh(PolygonMesh& mesh, double angle) { mesh.vertices = turned_points(mesh.vertices, angle); }

}  // namespace hsr::pipeline_detail
