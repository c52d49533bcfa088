// Face classes of an output mesh (roof / wall / ground / closure; DESIGN.md §4) and the geometry they
// are judged by. Plain Eigen, no CGAL.
#pragma once

#include "core/types.h"

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

/// Threshold of the classification by normal: a face whose unit normal has |n_z| below this is a wall
/// (about 11.5 degrees from vertical).
constexpr double kVerticalFaceNz = 0.2;

/// Classes from the face normals alone, up = +z: |n_z| < kVerticalFaceNz -> Wall; n_z > 0 -> Roof;
/// n_z < 0 -> Ground (faces facing down). Degenerate faces (zero area) -> Unknown.
std::vector<FaceClass> classify_faces_by_normal(const PolygonMesh& mesh);

/// mesh.face_class where it is set (and known), else the classification by normal, one entry per face.
std::vector<FaceClass> face_classes_or_by_normal(const PolygonMesh& mesh);

}  // namespace hsr
