#include "core/face_class.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <set>

namespace hsr {

const char* face_class_name(FaceClass c) {
  switch (c) {
    case FaceClass::Roof: return "roof";
    case FaceClass::Wall: return "wall";
    case FaceClass::Ground: return "ground";
    case FaceClass::Closure: return "closure";
    case FaceClass::Unknown: break;
  }
  return "unknown";
}

bool parse_face_class(const std::string& name, FaceClass& out) {
  for (FaceClass c : {FaceClass::Unknown, FaceClass::Roof, FaceClass::Wall, FaceClass::Ground, FaceClass::Closure})
    if (name == face_class_name(c)) {
      out = c;
      return true;
    }
  return false;
}

Vec3 newell_vector(const std::vector<Vec3>& vertices, const std::vector<std::uint32_t>& loop) {
  Vec3 n = Vec3::Zero();
  const std::size_t k = loop.size();
  for (std::size_t i = 0; i < k; ++i) n += vertices[loop[i]].cross(vertices[loop[(i + 1) % k]]);
  return n;
}

namespace {
/// A face's plane: its unit Newell normal, through the mean of its vertices.
Plane face_plane(const PolygonMesh& mesh, const std::vector<std::uint32_t>& loop) {
  Vec3 centroid = Vec3::Zero();
  for (std::uint32_t v : loop) centroid += mesh.vertices[v];
  centroid /= static_cast<double>(loop.size());
  Plane p;
  p.normal = newell_vector(mesh.vertices, loop).normalized();
  p.offset = -p.normal.dot(centroid);
  return p;
}

/// Whether two faces' planes agree: normals within 1e-9, offsets within 1e-9 of the diagonal `diag`.
bool same_plane(const Plane& a, const Plane& b, double diag) {
  return a.normal.dot(b.normal) > 1.0 - 1e-9 && std::abs(a.offset - b.offset) < 1e-9 * diag;
}
}  // namespace

CoplanarGroups coplanar_groups(const PolygonMesh& mesh) {
  CoplanarGroups g;
  const double diag = bounding_box(mesh.vertices).diagonal();
  for (const auto& loop : mesh.faces) {
    const Plane p = face_plane(mesh, loop);
    g.face_planes.push_back(p);
    int id = -1;
    for (std::size_t k = 0; k < g.planes.size() && id < 0; ++k)
      if (same_plane(g.planes[k], p, diag)) id = static_cast<int>(k);
    if (id < 0) {
      id = static_cast<int>(g.planes.size());
      g.planes.push_back(p);
    }
    g.face_group.push_back(id);
  }
  return g;
}

std::size_t polygon_regions(const PolygonMesh& mesh, const std::function<bool(std::size_t, std::size_t)>& one_surface) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::size_t> edge_face;  // directed edge -> face
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& l = mesh.faces[f];
    for (std::size_t i = 0; i < l.size(); ++i) edge_face[{l[i], l[(i + 1) % l.size()]}] = f;
  }
  std::vector<std::size_t> parent(mesh.faces.size());
  for (std::size_t f = 0; f < parent.size(); ++f) parent[f] = f;
  auto find = [&](std::size_t f) {
    while (parent[f] != f) f = parent[f] = parent[parent[f]];
    return f;
  };
  for (const auto& [e, f] : edge_face) {
    const auto it = edge_face.find({e.second, e.first});
    if (it != edge_face.end() && one_surface(it->second, f)) parent[find(f)] = find(it->second);
  }
  std::map<std::size_t, std::set<std::uint32_t>> vertices;
  std::map<std::size_t, std::set<std::pair<std::uint32_t, std::uint32_t>>> edges;
  std::map<std::size_t, long> faces;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const std::size_t r = find(f);
    const auto& l = mesh.faces[f];
    ++faces[r];
    for (std::size_t i = 0; i < l.size(); ++i) {
      vertices[r].insert(l[i]);
      edges[r].insert({std::min(l[i], l[(i + 1) % l.size()]), std::max(l[i], l[(i + 1) % l.size()])});
    }
  }
  std::size_t total = 0;
  for (const auto& [r, n] : faces) {
    const long euler = static_cast<long>(vertices[r].size()) - static_cast<long>(edges[r].size()) + n;
    total += static_cast<std::size_t>(std::max(1L, 2 - euler));
  }
  return total;
}

std::size_t polygon_regions(const PolygonMesh& mesh, const std::vector<int>& face_group) {
  return polygon_regions(mesh, [&](std::size_t a, std::size_t b) { return face_group[a] == face_group[b]; });
}

std::size_t surface_regions(const PolygonMesh& mesh) {
  const double diag = bounding_box(mesh.vertices).diagonal();
  std::vector<Plane> planes;
  planes.reserve(mesh.faces.size());
  for (const auto& loop : mesh.faces) planes.push_back(face_plane(mesh, loop));
  return polygon_regions(mesh, [&](std::size_t a, std::size_t b) { return same_plane(planes[a], planes[b], diag); });
}

std::vector<FaceClass> classify_faces_by_normal(const PolygonMesh& mesh) {
  std::vector<FaceClass> out(mesh.faces.size(), FaceClass::Unknown);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    const Vec3 n = newell_vector(mesh.vertices, mesh.faces[f]);
    const double len = n.stableNorm();
    if (!(len > 0) || !std::isfinite(len)) continue;
    const double nz = n.z() / len;
    out[f] = std::abs(nz) < kVerticalFaceNz ? FaceClass::Wall : nz > 0 ? FaceClass::Roof : FaceClass::Ground;
  }
  return out;
}

std::vector<FaceClass> face_classes_or_by_normal(const PolygonMesh& mesh) {
  std::vector<FaceClass> out = classify_faces_by_normal(mesh);
  if (mesh.face_class.size() == mesh.faces.size())
    for (std::size_t f = 0; f < out.size(); ++f)
      if (mesh.face_class[f] != FaceClass::Unknown) out[f] = mesh.face_class[f];
  return out;
}

}  // namespace hsr
