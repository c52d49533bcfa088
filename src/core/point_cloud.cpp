// select_points (types.h).
#include "core/types.h"

namespace hsr {

namespace {

template <class T>
void select_field(const std::vector<T>& from, const std::vector<std::size_t>& ids, std::vector<T>& into) {
  if (from.empty()) return;
  into.reserve(ids.size());
  for (std::size_t i : ids) into.push_back(from[i]);
}

}  // namespace

PointCloud select_points(const PointCloud& cloud, const std::vector<std::size_t>& ids) {
  PointCloud out;
  out.origin = cloud.origin;
  out.crs = cloud.crs;
  out.source = cloud.source;
  select_field(cloud.points, ids, out.points);
  if (cloud.has_normals()) select_field(cloud.normals, ids, out.normals);
  const PointAttributes& a = cloud.attributes;
  PointAttributes& b = out.attributes;
  select_field(a.classification, ids, b.classification);
  select_field(a.return_number, ids, b.return_number);
  select_field(a.number_of_returns, ids, b.number_of_returns);
  select_field(a.intensity, ids, b.intensity);
  select_field(a.gps_time, ids, b.gps_time);
  select_field(a.rgb, ids, b.rgb);
  return out;
}

}  // namespace hsr
