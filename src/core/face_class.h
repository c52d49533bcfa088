// Face classes of an output mesh (roof / wall / ground / closure; DESIGN.md §4) and the geometry they
// are judged by. Plain Eigen, no CGAL.
#pragma once

#include "core/types.h"

#include <functional>
#include <string>
#include <vector>

namespace hsr {

/// "unknown", "roof", "wall", "ground", "closure".
const char* face_class_name(FaceClass c);
/// Inverse of face_class_name(); returns false for an unknown name.
bool parse_face_class(const std::string& name, FaceClass& out);

/// Newell vector of the polygon `loop` over `vertices`: normal direction (right-hand rule), length twice
/// the polygon's area. Robust for non-convex and slightly non-planar loops.
Vec3 newell_vector(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& loop);

/// Each face's plane (unit Newell normal, through the mean of its vertices) and its group: faces whose planes
/// agree (normals within 1e-9, offsets within 1e-9 of the bounding-box diagonal) share one, numbered in order of
/// first appearance; `planes[g]` is the plane of group g's first face.
struct CoplanarGroups {
  std::vector<Plane> face_planes;
  std::vector<int> face_group;
  std::vector<Plane> planes;
};
CoplanarGroups coplanar_groups(const PolygonMesh& mesh);

/// The faces of `mesh` counted as surface regions: per connected region of faces sharing edges that
/// `one_surface(f, g)` puts on one surface, 2 - V + E - F, at least 1 (one per region plus one per hole), so a
/// region counts the same however it is cut into simple polygons.
std::size_t polygon_regions(const PolygonMesh& mesh, const std::function<bool(std::size_t, std::size_t)>& one_surface);
/// The same with the faces of one group (`face_group`, one per face) on one surface: a synth truth's polygon_faces.
std::size_t polygon_regions(const PolygonMesh& mesh, const std::vector<int>& face_group);
/// The same with two faces sharing an edge on one surface when their planes agree as coplanar_groups' do: `hsr
/// eval`'s regions, n log n in the faces (only neighbours are compared; coplanar_groups compares each face with
/// every group).
std::size_t surface_regions(const PolygonMesh& mesh);

/// Threshold of the classification by normal: a face whose unit normal has |n_z| below this is a wall
/// (about 11.5 degrees from vertical).
constexpr double kVerticalFaceNz = 0.2;

/// Classes from the face normals alone, up = +z: |n_z| < kVerticalFaceNz -> Wall; n_z > 0 -> Roof;
/// n_z < 0 -> Ground (faces facing down). Degenerate faces (zero area) -> Unknown.
std::vector<FaceClass> classify_faces_by_normal(const PolygonMesh& mesh);

/// mesh.face_class where it is set (and known), else the classification by normal, one entry per face.
std::vector<FaceClass> face_classes_or_by_normal(const PolygonMesh& mesh);

}  // namespace hsr
