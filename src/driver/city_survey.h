// The points a tile of a survey is planned with (issue 40 item 1; src/city/survey.h): its own and its
// neighbours' within the tile margin.
#pragma once

#include "city/survey.h"
#include "core/types.h"

#include <string>
#include <vector>

namespace hsr::city {

/// Every tile's extent in file coordinates (io.h read_extent: a LAS/LAZ/COPC header; other formats read
/// whole), in the given order.
std::vector<BBox> survey_extents(const std::vector<std::string>& tiles);

/// The cloud tile `self` is planned with: its own points (read_points(tiles[self]), `own`), then, tile by tile
/// in the given order, the points of every other tile whose extent meets the tile's extent grown by `margin`
/// (file units) that lie inside that rectangle and outside the tile's own extent, each once (from the tile
/// that owns it, survey.h owning_tile, where neighbours overlap), in the own cloud's local coordinates. A per-point attribute
/// is kept when every tile read has it (else dropped, with a warning). Fills `region` (survey.h).
PointCloud read_survey_region(const std::vector<std::string>& tiles, const std::vector<BBox>& extents, int self,
                              PointCloud own, double margin, SurveyRegion& region);

}  // namespace hsr::city
