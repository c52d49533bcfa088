// Shared by the partition benchmarks: PartitionParams overrides given as key=value (issue 17's ablation).
#pragma once

#include "core/error.h"
#include "partition/partition.h"

#include <string>

namespace hsr::bench {

/// Applies one override; false if `key` is not a PartitionParams switch. Keys: k, max-per-domain,
/// max-crossings, bsp-extend, cross-to-bounds, meet-at-point, wait-at-bounds, trim (0/1 for switches).
inline bool apply_partition_option(PartitionParams& p, const std::string& key, int value) {
  if (key == "k") p.kinetic_k = value;
  else if (key == "max-per-domain") p.max_polygons_per_domain = value;
  else if (key == "max-crossings") p.max_crossings = value;
  else if (key == "bsp-extend") p.bsp_extend = value != 0;
  else if (key == "cross-to-bounds") p.cross_to_bounds = value != 0;
  else if (key == "meet-at-point") p.meet_at_point = value != 0;
  else if (key == "wait-at-bounds") p.wait_at_bounds = value != 0;
  else if (key == "trim") p.trim = value != 0;
  else return false;
  return true;
}

}  // namespace hsr::bench
