// Internal to src/partition: the kinetic and hierarchical partitioners (partition.h describes them; the
// growth model is in kinetic_growth.h).
#pragma once

#include "partition/complex_builder.h"
#include "partition/partition.h"

namespace hsr::partition_internal {

/// Statistics of one kinetic / hierarchical run (logged; also handy in tests).
struct KineticStats {
  int domains = 0;            ///< domains grown (all levels, after sub-domain splits)
  int subdomain_splits = 0;   ///< domains split in two by one of their polygons' planes
  long long faces = 0;        ///< arrangement faces in all grown regions
  long long stops = 0, crossings = 0;
  double seconds_domains = 0, seconds_growth = 0, seconds_cells = 0;  ///< wall time per step
};

/// Fills `builder` (fresh: the box only) with the kinetic (params.method == Kinetic) or hierarchical
/// partition of the input polygons.
KineticStats run_kinetic(const PartitionInput& input, const PartitionParams& params, ComplexBuilder& builder);

}  // namespace hsr::partition_internal
