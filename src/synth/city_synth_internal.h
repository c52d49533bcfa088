// Internal pieces of `hsr synth city` (not part of the public API), shared by the one tile (city_synth.cpp) and
// the survey written tile by tile (city_survey_synth.cpp): the terrain, the plots and their buildings, the trees
// and the scene a ray is cast into. Both draw the layout in the same order from one seeded generator.
#pragma once

#include "synth/city_synth.h"
#include "synth/synth_internal.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <random>
#include <vector>

namespace hsr::synth_detail {

/// The ground before the plots are levelled: a plane rising by `gradient` plus a gentle undulation (0.5 m,
/// wavelengths 90 and 130 m).
struct CityTerrain {
  Vec2 gradient = Vec2::Zero();
  double natural(double x, double y) const {
    return gradient.dot(Vec2(x, y)) + 0.5 * std::sin(x / 90.0 * 2 * M_PI) * std::cos(y / 130.0 * 2 * M_PI);
  }
};

/// Throws Error(BadInput, "synth") for parameters run_synth_city refuses (city_synth.h).
void check_city_params(const SynthCityParams& p);

/// The terrain: params.slope in a direction drawn from `rng` (the layout's first draw).
CityTerrain draw_city_terrain(const SynthCityParams& p, std::mt19937_64& rng);

/// The buildings: building i on plot centre `centres[i]` (family i mod 6, seed p.seed * 1000 + i, moved up to
/// 2 m off the centre), then p.terraced blocks each attached to a building before it (city_synth.h). Ids B0001,
/// ... in that order. Throws Error(BadInput) when a terraced block finds no room.
std::vector<SynthCityBuilding> place_city_buildings(const SynthCityParams& p, const std::vector<Vec2>& centres,
                                                    const CityTerrain& terrain, std::mt19937_64& rng);

/// The plan box of a footprint's outer rings.
BBox plan_box_of(const Footprint& f);

/// Tree crowns placed uniformly over `area` (plan), each clear of every building's box by 2 m, on the
/// levelled ground; `count` tried, 100 draws each.
std::vector<Crown> place_city_trees(int count, const BBox& area, const std::vector<SynthCityBuilding>& buildings,
                                    const CityTerrain& terrain, double flat, std::mt19937_64& rng);

/// What the scanner sees: the buildings' truth faces and the terrain, each face's plane and building.
struct CityScanScene {
  PolygonMesh mesh;
  std::vector<Plane> planes;
  std::vector<int> face_building;  ///< the index of the face's building in the survey; -1: terrain
};

/// Appends building `buildings[k]`'s faces with face_building = `index[k]` (its index in the survey).
void add_city_buildings(CityScanScene& scene, const std::vector<SynthCityBuilding>& buildings, const std::vector<int>& index);

/// Appends the terrain over `box` as a height field of 1 m cells from box.min (levelled under the plots of
/// `buildings`, which must hold every building within flat + 5 m of the box, in the survey's order: the
/// heights are then the same at a vertex whatever the box).
void append_city_terrain(CityScanScene& scene, const BBox& box, const CityTerrain& terrain,
                         const std::vector<SynthCityBuilding>& buildings, double flat);

/// Plots per side of a survey (SynthCityParams::survey_size): as many as fit.
inline int survey_plots_per_side(const SynthCityParams& p) { return static_cast<int>(std::floor(p.survey_size / p.plot)); }

/// DIR/footprints.geojson, DIR/truth/ID.obj and DIR/truth.json of `buildings` (city_synth.h write_synth_city),
/// `extra` keys added to truth.json.
void write_city_truth(const SynthCityParams& params, const std::vector<SynthCityBuilding>& buildings, std::size_t points,
                      const std::filesystem::path& root, const nlohmann::json& extra);

/// Creates `dir` (and its parents); throws Error(FileNotFound, "synth") when it cannot.
void create_folder(const std::filesystem::path& dir);

/// The ground is levelled this far past plot_flat (blending into the terrain), m.
inline constexpr double kCityPlotBlend = 5.0;

}  // namespace hsr::synth_detail
