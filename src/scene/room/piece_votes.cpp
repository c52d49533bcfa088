// A room's pieces' boxes vote in the extraction (room.h room_piece_votes, DECISIONS #70).
#include "scene/room/room.h"

#include <algorithm>

namespace hsr {

std::size_t room_piece_votes(const SceneStructure& structure, const VisibilityResult& visibility,
                             const RecoveryResult& recovery, double tolerance, double level_deg,
                             std::vector<int>& point_plane, std::vector<Vec3>& normals) {
  const int floor = room_ends(structure, visibility.highly, tolerance, level_deg).floor;
  const bool pieces = std::any_of(recovery.recovered.begin(), recovery.recovered.end(),
                                  [](const RecoveredPlane& rp) { return rp.piece >= 0; });
  if (floor < 0 || !pieces) return 0;
  // Under the floor is outside (its outward normal points down): the piece is outside, its points face in.
  const double side = visibility.outward_normal[static_cast<std::size_t>(floor)].z() < 0 ? -1.0 : 1.0;
  point_plane = structure.point_plane;
  std::size_t assigned = 0;
  for (std::size_t q = 0; q < recovery.recovered.size(); ++q) {
    const RecoveredPlane& face = recovery.recovered[q];
    if (face.piece < 0) continue;
    for (int p : face.support) {
      point_plane[static_cast<std::size_t>(p)] = static_cast<int>(structure.planes.size() + q);
      normals[static_cast<std::size_t>(p)] = side * face.plane.normal;
      ++assigned;
    }
  }
  return assigned;
}

}  // namespace hsr
