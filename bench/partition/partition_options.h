// Shared by the partition benchmarks: PartitionParams overrides given as key=value (issue 17's ablation).
#pragma once

#include "core/error.h"
#include "partition/partition.h"

#include <string>

namespace hsr::bench {

/// Applies one override; false if `key` is not a PartitionParams switch. Keys: k, max-per-domain,
/// max-crossings, bsp-extend, cross-to-bounds, meet-at-point, restrict-bounds, corner-wait (0/1 for switches).
inline bool apply_partition_option(PartitionParams& p, const std::string& key, int value) {
  if (key == "k") p.kinetic_k = value;
  else if (key == "max-per-domain") p.max_polygons_per_domain = value;
  else if (key == "max-crossings") p.max_crossings = value;
  else if (key == "bsp-extend") p.bsp_extend = value != 0;
  else if (key == "cross-to-bounds") p.cross_to_bounds = value != 0;
  else if (key == "meet-at-point") p.meet_at_point = value != 0;
  else if (key == "restrict-bounds") p.restrict_bounds = value != 0;
  else if (key == "corner-wait") p.corner_wait = value != 0;
  else if (key == "trim") p.trim = value != 0;
  else if (key == "phased") p.phased = value != 0;
  else if (key == "swalls") p.structural_walls = value != 0;
  else if (key == "later") p.later_on_the_way = value != 0;
  else if (key == "top100") p.cross_top = value / 100.0;
  else if (key == "global") p.fraction_of_global = value != 0;
  else if (key == "minfrac100") p.cross_min_fraction = value / 100.0;
  else if (key == "one-domain") p.one_domain_levels = value != 0;
  else if (key == "xlevel") p.cross_level_adjacency = value != 0;
  else if (key == "smaller10") p.cross_smaller = value / 10.0;
  else if (key == "ext") p.cross_only_extensions = value != 0;
  else if (key == "useful") { p.useful_crossings = value != 0; p.useful_mode = value; }
  else if (key == "trim-keep") p.trim_keep = value;
  else if (key == "second-order-stops") p.second_order_stops = value != 0;
  else if (key == "max-cross-gauge10") p.max_cross_gauge = value / 10.0;
  else return false;
  return true;
}

}  // namespace hsr::bench
