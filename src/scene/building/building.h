// The building scene kind (DESIGN.md §4): an aerial scan of a building. Up is +z, the building stands on the
// ground, ground and vegetation are no building surface. These are the rules the scene stage applies once the
// kind is `building` (scene.h decides the kind): the ground height and its source (ground.cpp), every detected
// plane's role and the building's main direction (roles.cpp), and the building's own structure handed to the
// later stages (structure.cpp). Every threshold is a field of BuildingParams, with its unit and where it was
// measured; the rules cite their docs/DECISIONS.md entries.
//
// Ground, the height the solid stands on, from the first source that has one (SceneResult::ground_source):
//   1. given: BuildingParams::ground_z (the CLI's --ground-z);
//   2. raster: a terrain model (SceneGround::raster, the CLI's --ground DTM.tif) sampled under the building's
//      roof and wall points, the median of the samples;
//   3. classified points: the points the file classes as ground (LAS class 2, SceneGround::points) within a
//      ring around the building's footprint (xy within ground_ring r of a roof or wall inlier, not under one),
//      their median height (at least ground_min_points of them);
//   4. a ground plane: the near-horizontal planes (normal within ground_max_angle_deg of +z) lying at the
//      bottom of the data (mean height within max(ground_band r, ground_band_share of the z extent) of the
//      ground_low_quantile of the points' heights), whose inliers reach around the rest (at least
//      ground_min_sectors of 16 angular sectors about the other planes' centre) while a plane that is not
//      foliage rises clearly above them (its median height at least building_min_height r above), and a roof is
//      left once they are ground; then one rising building_min_height r or more above the lowest of them is a
//      low roof standing on the ground, not a second ground (DECISIONS #78); the ground is the remaining ones'
//      inliers' median height. (A flat roof under a tree, or a flat roof with a few small things on it and
//      nothing else, is a roof, not the ground.) A detected ground plane's points are ground whatever the
//      source of the height;
//   5. the lowest building point: the lowest inlier of a roof or wall, or of the points on no plane that stand
//      on the building's footprint (xy within one footprint_cell r cell of a roof or wall inlier: walls too
//      sparse to be a plane, ground at their foot), so terrain further out does not pull the building down —
//      when it lies at least under_roof_gap r below the lowest roof point;
//   6. assumed: nothing in the scan lies under its roofs (a roof-only scan, a flat roof alone) and no ground is
//      known: the walls are assumed_wall_height (one storey) tall under the lowest roof point, and a warning
//      names --ground-z and --ground.
// Roles: ground planes; walls (within wall_max_angle_deg of vertical); roofs (the rest); clutter: planes
// not part of the building: foliage (a loose layer: RMS distance to the plane >= vegetation_rms r and the
// inliers' normals >= vegetation_normal_deg off the plane's on average; measured: roofs of the 12 airborne
// scans have RMS 0.04-0.99 r and normals 0-28 degrees off, never both above 0.6 r and 20 degrees except one
// 46-point plane of Vaihingen_00010), below building_min_height over the ground (cars, hedges, terrain; not
// a low roof adjacent to a roof that is not low, nor one wider than car_max_width that meets such a roof in
// plan: a lean-to, a garage or an annex whose wall the scan missed, DECISIONS #53, #77), or
// in a connected group of planes (structure adjacency) that is far from the main group (the one with the
// most inliers; "far": their xy boxes, grown by far_group_margin r, do not overlap) and small (fewer inliers
// than min_building_share of the main group's; a large one is another building and is kept). The clutter
// rules never take the last roof: a scan of a building holds one, so when every roof would be low or far, the
// low and far ones stay roofs (a shed lower than 4 r over its ground is still the building of its scan).
#pragma once

#include "core/kd_tree.h"
#include "core/raster.h"
#include "core/types.h"
#include "structure/structure.h"

#include <nlohmann/json.hpp>

#include <array>
#include <limits>
#include <string>
#include <vector>

namespace hsr {

enum class PlaneRole { Object, Roof, Wall, Ground, Clutter };
const char* plane_role_name(PlaneRole r);  ///< "object", "roof", "wall", "ground", "clutter"

enum class GroundSource { None, Plane, Given, LowestPoints, Raster, ClassifiedPoints, Assumed };
/// "none", "plane", "given", "lowest building point", "raster", "classified ground points", "assumed storey"
const char* ground_source_name(GroundSource g);

/// The building kind's rules (see the file comment). r is the scan's point spacing (SceneStructure::spacing).
struct BuildingParams {
  /// A given ground height (local coordinates; the CLI's --ground-z is in file coordinates and is shifted).
  /// Wins over every other source of the ground. NaN: none given.
  double ground_z = std::numeric_limits<double>::quiet_NaN();
  /// With ground_z given: it is the ground, and no detected plane is taken for the ground (`hsr city` sets it:
  /// a building's points there hold no ground, and a low roof beside a higher block is a roof, not ground).
  bool given_ground_wins = false;
  /// Ground source 3: the classified ground points within this distance of the building's footprint, in r.
  double ground_ring = 10.0;
  /// Ground source 3: the fewest classified ground points in the ring whose median is the ground.
  int ground_min_points = 3;
  /// Ground source 6: with no ground known and nothing under the roofs, the walls are this tall under the
  /// lowest roof point, in the file's length unit (one storey in metres, the unit of survey data).
  double assumed_wall_height = 3.0;
  double ground_max_angle_deg = 10.0;  ///< a ground plane's normal is within this of +z, degrees
  int ground_min_sectors = 8;          ///< of 16 sectors about the building's centre, reached by the ground
  /// Ground source 4: "the bottom of the data" is this quantile of the points' heights (the 1st percentile:
  /// a few stray low returns do not move it).
  double ground_low_quantile = 0.01;
  /// Ground source 4: a ground plane's centroid lies within max(ground_band r, ground_band_share × the z
  /// extent) of the bottom of the data (sloping terrain is a plane whose centroid is above its lowest point).
  double ground_band = 6.0;
  double ground_band_share = 0.05;
  /// Ground source 5: the footprint's plan cells, in r (twice the inlier distance: a wall's foot is in the
  /// cell next to its inliers').
  double footprint_cell = 2.0;
  /// Ground source 5: the lowest building point is the ground when it lies this far below the lowest roof
  /// point, in r (the inlier distance: nearer, the lowest point is a roof point, nothing lies under the roofs).
  double under_roof_gap = 2.0;
  double building_min_height = 4.0;    ///< roofs rise at least this far above the ground, in r
  /// A roof's height for "low" is this quantile of its inliers' heights (the 90th percentile: a roof sloping
  /// down to its eave is as tall as its upper part).
  double roof_height_quantile = 0.9;
  /// A low roof narrower than this (across its smallest-area rectangle in plan) may be a car; a wider one that
  /// meets a roof that is not low is a wing of the building. File length unit (metres: cars are at most 2.5 m
  /// wide, a garage is wider). DECISIONS #77.
  double car_max_width = 2.5;
  /// A low roof standing higher than this over the ground is no car, however narrow: a wing when it meets a
  /// roof that is not low in plan. File length unit (metres: cars are at most about 2 m tall; a lean-to or a
  /// storey's flat strip along a house stands higher). At half density "low" (building_min_height r) reaches
  /// 2.8 m, a storey. DECISIONS #233.
  double car_max_height = 2.0;
  /// A low wing rises at least this far off the ground, in r (the inlier distance: nearer, it cannot be told
  /// from the ground; at half density a terrain patch beside the walls became a ramp, DECISIONS #77).
  double wing_min_rise = 2.0;
  /// A low wing meets a tall roof in plan: one of its inliers within this of one of the tall roof's, in r
  /// (the inlier distance: the two meet along an eave).
  double wing_reach = 2.0;
  double wall_max_angle_deg = 10.0;    ///< a plane within this of vertical is a wall (made exactly vertical)
  double vegetation_rms = 0.6;         ///< foliage: RMS distance of the inliers to their plane at least this, in r
  double vegetation_normal_deg = 20.0; ///< ... and their normals this far off the plane's on average, degrees
  double min_building_share = 0.1;     ///< a far group of planes with fewer inliers than this share of the
                                       ///< main group's is clutter; more, another building
  /// Two groups of planes are far apart when their xy boxes grown by this do not overlap, in r.
  double far_group_margin = 4.0;
  /// The building is reconstructed in its own frame: the chain runs again on the points turned about z so that
  /// the main direction lies along x, and the model is turned back (pipeline.cpp run_in_own_frame). Why: the
  /// partition's box is axis-aligned; a building turned 30-60 degrees to the axes leaves wedges between its
  /// walls and the box's corners, and a roof part whose wall no segment recovers (a hip end) bounds a cell
  /// that reaches out to them, which the min-cut leaves outside (DECISIONS #94: Dales3d_00281 turned 37
  /// degrees lost a 38-point roof slope, 19 % of its points unexplained). Not with a ground raster (it is
  /// sampled where the points are in the file). OFF by default: with it on, city3d_bldg94 keeps a wall sliver
  /// of 4e-5 of the area at a hip that no clean-up flip removes (test Faces.TheSharedScansSliversThat...);
  /// turn it on with --config (parameters.scene.building.own_frame).
  bool own_frame = false;
  /// Walls whose direction is within this of the building's main directions (the mode of its roof
  /// outlines' directions, modulo 90°) are turned onto them, degrees; 0: no snapping.
  double main_direction_snap_deg = 5.0;
  /// The main direction's histogram (1-degree bins) is smoothed over ± this many degrees before its peak is
  /// taken (a building's outline is rarely within one degree of straight).
  int main_direction_smoothing_deg = 3;
  /// The main direction is the circular mean of the directions within this of the histogram's peak, degrees.
  double main_direction_window_deg = 5.0;
  /// The main direction is the side of the smallest-area rectangle around all the roofs' and walls' inliers
  /// in plan (the points' own extent, not a footprint) when that lies within main_direction_window_deg of the
  /// direction the outlines give; false: the outlines' direction alone. OFF by default (DECISIONS #195: on, the half-density
  /// City3D -> hsr median of issue 42 is met on three draws, but a sparse synthetic hip house (aerial_steep seed 4
  /// at 4 points/m²) gets a roof part added and aerial_hip_2's Chamfer doubles); turn it on with --config
  /// (parameters.scene.building.main_direction_from_rectangle).
  bool main_direction_from_rectangle = false;
  /// ...unless a side of that rectangle runs through three or more of those points to within this, in r: the
  /// points lie on the rows of a raster (Vaihingen's 0.5 m grid), and the smallest rectangle follows the rows,
  /// not the building (DECISIONS #195). A rounding error, not a distance a scan's points keep by chance;
  /// negative: no such check.
  double main_direction_raster_tolerance = 1e-6;
  /// ...and unless the roofs' area in plan (their alpha shapes') is under this share of that rectangle's: a
  /// bent or L-shaped building's rectangle follows none of its wings (city3d_bldg94: two wings 4 degrees apart,
  /// its rectangle 4 degrees off the main wing; DECISIONS #195).
  double main_direction_min_fill = 0.8;
  /// Upright walls facing the same way (or opposite) whose offsets differ by less than this are one wall
  /// (a sparse facade detected in pieces), in r.
  double wall_merge_distance = 2.0;
  /// A roof's outline completed along the main directions (complete_outline): a side of its rectangle gets a
  /// segment when at least outline_min_points inliers lie within outline_band r of it, spanning
  /// outline_min_span of the side's length, and no segment already follows it (parallel within
  /// outline_parallel_deg, facing out, within outline_covered_distance r).
  int outline_min_points = 6;
  double outline_band = 1.5;
  double outline_min_span = 0.5;
  double outline_parallel_deg = 10.0;
  double outline_covered_distance = 5.0;
  /// Small planes (issue 42 item 3; DECISIONS #99, on by default since #107 with 13; 0: off): once the scene is decided on the planes
  /// of the detection's smallest size (StructureParams::min_region_points, 30), the points on no plane are
  /// searched again for planes of at least small_plane_points points and small_plane_width r across
  /// (structure.h add_small_planes); such a plane that is no foliage and touches a roof or wall of the building
  /// (SceneStructure::adjacency; a low one, under building_min_height r, a roof that is not low) is a roof or a
  /// wall of it, by its normal; the others are clutter. Why: the smallest plane is a count, so a roof part or a
  /// scanned wall holds half as many points at half the density and falls under it (AHN3_09896 at 2 points/m²:
  /// one roof half of 23 points, the model a lean-to), while the scene's decisions (ground, clutter, `auto`) keep
  /// resting on planes of the full size (detected with 15-point planes, flat roofs with a few small planes on
  /// them became ground). Measured with 13 (region_k + 1: a plane holds more than one neighbourhood, the room's
  /// smallest plane, #69): half density p2m medians AHN3 0.66 -> 0.60 %, Vaihingen 0.84 -> 0.82 %, still above
  /// City3D's 0.57 and 0.74 %, and City3D's eave-line walls are farther from a model whose walls stand where the
  /// scan saw them. #107 keeps them out of the two cases that made it worse (the fields below) and turns it on.
  int small_plane_points = 13;
  double small_plane_width = 0.0;
  /// What a small plane may become (DECISIONS #107). small_plane_walls: an upright one (wall_max_angle_deg) may
  /// be a wall; false: small planes are roofs only. small_wall_max_overhang (r): a small wall is kept only
  /// where the roofs above its top reach at most this far beyond it on the side where they reach the least
  /// (roles.cpp roof_overhang): a scanned wall under an eave would explain the roof's side, the eave's wall is
  /// not recovered and the model's wall moves inside the eave line (AHN3_01218); negative: not tested.
  /// small_roof_max_slope_deg (degrees from level): a small plane that is no wall is a roof only up to this
  /// slope: a few noisy points on a chimney's side, 73 degrees steep, cut the main roof's corner as a roof
  /// (AHN3_00989); 90: not tested.
  bool small_plane_walls = true;
  double small_wall_max_overhang = 0.5;
  double small_roof_max_slope_deg = 60.0;
  /// A small roof plane that is not low and lies under the eave of a roof of the building (one of its inliers
  /// within wing_reach r in plan of an inlier of that roof standing higher; roles.cpp small_roof_under_an_eave)
  /// is a roof of it, as a first-size plane is: the adjacency test alone needs the two planes' inliers among
  /// each other's neighbours, and a lower part whose eave lies a storey under the main roof's has none
  /// (AHN3_03746 at half density: a 24-point annex roof left out as clutter, a roof at full density with 46).
  /// Under, not over: a tree's crown over a flat roof is no roof (AHN3_15708). false: adjacency only
  /// (DECISIONS #140).
  bool small_roof_meets_in_plan = true;
  /// "Higher" in small_roof_under_an_eave: the roof's inlier stands above the small roof's inlier by more than
  /// this, in r. Why: a patch of the roof itself, tilted a few degrees by the scan's noise and left off the roof's
  /// plane, has roof inliers a hair above it within reach; it is no lower roof (Vaihingen_00021 with 3 cm noise:
  /// 13-point planes at the flat roof's height taken for roofs under its eave, the model's east end sloped pieces,
  /// City3D -> hsr 3.4 %). 2: the inlier distance (StructureParams::max_distance), as wing_min_rise's: nearer,
  /// two heights are one plane's. 0: any amount (#140's rule). DECISIONS #176.
  double small_roof_eave_drop = 2.0;
  /// A finer outline, decided by the result (issue 42 item 3; DECISIONS #116): a building scan of at most
  /// SceneParams::auto_choice_max_points points is reconstructed again with roof outline segments of one
  /// boundary point fewer at a time (StructureParams::min_segment_points, 6, is the first run's), down to
  /// finer_outline_points, and each model is kept over the one kept so far when its solid is valid and its p2m
  /// is lower by at least finer_outline_min_gain of it (keep_finer_outline). Why: a segment needs a count of
  /// boundary points, so a roof's short side holds half as many at half the density and falls under it; no
  /// wall is recovered there and the roof part beyond the long side's wall is cut off (Vaihingen_00048 at half
  /// density: a 2 m wide strip of roof along 7.5 m, p2m 1.19 %, 0.55 % with 5-point segments). Fewer points
  /// per segment everywhere helps some buildings and hurts others (AHN3 at half density with 5: 14 better, 12
  /// worse, e.g. AHN3_05537 0.20 -> 0.47 %), so the result decides per building. A run stops after the scene
  /// stage when its building has as many outline segments as the run before (report: scene.finer_outline).
  /// 3 (tries 5, 4, 3; #131): some short sides hold 3 or 4 boundary points at the density of the scan as
  /// shared (AHN3_09495: a shallow 84-point slope's side, on the model only with 3-point segments, p2m 1.11 ->
  /// 0.75 %); 5 was #116's. 0: off. finer_outline_min_gain (share of the kept model's p2m): a smaller gain is
  /// noise, not taken.
  /// finer_outline_runs: how many of those counts are tried, the finest first in the count
  /// (finer_outline_points + runs - 1 down to finer_outline_points); each is a run of the chain after the
  /// detection. 3 tries 5, 4, 3 (#131); 1 tries 3 alone: 1.3-1.45 x faster on a city tile, but half the
  /// density's p2m median 0.58 -> 0.60 % on the 112 (DECISIONS #132).
  /// finer_outline_runs_on_footprint: finer_outline_runs for a building given its footprint
  /// (PipelineParams::footprint, `hsr city --footprints`). Why: the footprint's own walls take the place of the
  /// walls standing for its edges (pipeline.cpp walls_left_to_footprint), so a short outer side's wall, step 5's
  /// reason, is there without a finer outline, which adds only walls inside the footprint; the finest count alone
  /// keeps what the three kept on the city tiles (AHN3 RMS median unchanged, synth Chamfer medians unchanged) at
  /// about half step 5's time (DECISIONS #172). 1: the finest count (finer_outline_points) alone. Used only
  /// when one_second_run_on_footprint is off: by default step 6's run takes the finest count (#189).
  int finer_outline_points = 3;
  double finer_outline_min_gain = 0.05;
  int finer_outline_runs = 3;
  int finer_outline_runs_on_footprint = 1;
  /// The outline prism (issue 42 "valid for all"; DECISIONS #135): when detection finds no plane of its smallest
  /// size, not even with the small-scan rule's smaller planes (scene.h small_scan_*), in a scan that is a
  /// building (`--scene building`, LAS class 6, or `auto` on a small scan, fewer than small_scan_size x the
  /// smallest plane's points, whose given normals face up as rule (a) asks of planes: pipeline_prism.cpp
  /// normals_face_up), the model is the prism over the convex hull in plan of its roof
  /// points, standing on its ground and reaching up to outline_prism_roof_quantile of their heights (outline_prism
  /// below; the report's scene.fallback, quality.fallback and the CityJSON attribute hsr_fallback say so). Why:
  /// a user of a city expects every building modelled; a scan of a few tens of points (Vaihingen_00026: 21
  /// points, 10 at half density; Vaihingen_00029 at half density: 9) holds no plane of 15 points, and a block
  /// over its points explains them as roofer's LoD 1.2 does where it has no roof planes. 0.7: the roof height of
  /// roofer's and 3DBAG's LoD 1.2 blocks (their `h_70p`): above most of a sloped roof's points, below a chimney.
  /// false: no model, as before (`structure: no plane found`).
  bool outline_prism = true;
  double outline_prism_roof_quantile = 0.7;
  /// The outline prism's outline stands this far outside the convex hull of its roof points, in their spacing in
  /// plan (core/spacing.h plan_spacing: sqrt(hull area / points), not r; without a footprint; edge_beyond_
  /// outermost_points, DECISIONS #219): the roof's edge lies half a spacing beyond its outermost points on average.
  /// 0: at the hull (#135).
  double outline_prism_beyond_hull = 0.5;
  /// Tighter planes, decided by the result (issue 42 item 3, half density; DECISIONS #137): a building scan of at
  /// most SceneParams::auto_choice_max_points points is reconstructed once more with the detection's inlier
  /// distance (StructureParams::max_distance, 2 r) set to tighter_planes_distance r, after step 5 and with the
  /// outline segments it kept, and the model is kept when keep_finer_outline says so (valid, p2m lower by
  /// finer_outline_min_gain, no more slivers unless it explains points the first left off every plane:
/// keep_tighter_planes; report: scene.tighter_planes). Why: the inlier distance is in r, and
  /// at half the density r is 1.4 times longer, so 2 r (1 m on AHN3 at 2 points/m²) is more than a roof's step: a
  /// lower roof's region grows over the step into the higher roof beside it, its refit tilts between the two, and
  /// the model has a ridge where the scan has a step (AHN3_04196: the top of a 20° lean-to 1 m above the model,
  /// p2m 2.16 %, 0.89 % with 1 r; City3D 0.91 %). A tighter distance everywhere splits noisy roofs into strips, so
  /// the result decides per building. 1: the points of a plane within one spacing of it (the scan's own noise is
  /// under it: a plane of the 3 cm noise variant still grows). 0: off.
  double tighter_planes_distance = 1.0;
  /// Step 6's second distance, decided by the result (issue 43 item 4; DECISIONS #246): where step 6's run was not
  /// kept and the model still leaves at least the detection's smallest plane (StructureParams::min_region_points as
  /// resolved) of points farther than its detection's inlier distance, the building is reconstructed once more with
  /// its planes' inliers within tighter_planes_second_distance r, and kept as step 6's run is (keep_tighter_planes;
  /// report: scene.tighter_planes_second), after the turn is given up (beside the next building at `-j 1`). Why:
  /// at 1 r (0.36 m on the AHN3 tile) a region still grows over a crease between two slopes whose normals lie
  /// within StructureParams::max_angle_deg of each other (AHN3_08596 in the city: 38° and 15° in one plane, RMS
  /// 0.249 m against roofer's 0.138; 0.120 m with 0.5 r), while 0.5 r in place of 1 r splits noisy roofs into
  /// strips where 1 r is kept (AHN3_15708 p2m 3.5 -> 13.5 %): as a second chance it makes no building's p2m worse.
  /// A model that explains its points leaves none to gain. In r, unitless; tighter than tighter_planes_distance,
  /// else no run. 0: off.
  double tighter_planes_second_distance = 0.5;
  /// Step 6's second distance runs on building scans of at most this many points (0: any size). Why: its run is a
  /// whole run of the chain, whose cost grows with the points, and by turns it is wall time (DECISIONS #246): on the
  /// AHN3 tile uncapped it cost 1.14 x the defaults' `-j 1` wall, the runs on the three scans over 5,000 points
  /// (8,831, 8,314 and 11,969: 9,200-25,400 points) half of it, none kept; capped 1.06 x with every RMS gain kept.
  /// Over 5,000 points it was kept on 7 of its 26 runs on the 112 as shared and at half density (Dales3d, AHN3_09417
  /// at half density), which took 45 of the two sets' 55 second-run seconds.
  int tighter_planes_second_max_points = 5000;
  /// One second run with a footprint (issue 43; DECISIONS #189): for a building given its footprint
  /// (PipelineParams::footprint, `hsr city --footprints`) steps 5 and 6 are one run, step 6's with outline
  /// segments of finer_outline_points points (the finer outline and the tighter planes together), kept by the
  /// result against the first run as step 6's is (keep_tighter_planes); step 5 makes no run of its own. Why: the
  /// two second runs were two thirds of hsr's time on a city tile; one run with both keeps as many buildings
  /// closer to their points than roofer's (AHN3 tile: 39 of 56 either way) at 0.77-0.85 x the CPU. false: steps
  /// 5 and 6 each make their run (finer_outline_runs_on_footprint).
  bool one_second_run_on_footprint = true;
  /// A roof part left out of the model gets walls, decided by the result (issue 42 item 1, issue 43 item 4;
  /// DECISIONS #159): where the model of a building scan of at most SceneParams::auto_choice_max_points points
  /// leaves out a roof plane of at least left_out_roof_min_points inliers (left_out_roofs: more than half of its
  /// inliers farther from the model than the detection's inlier distance, and nothing seen under it:
  /// left_out_roof_max_under), stages 3 to 7 run again with four
  /// walls around each such roof (recovery.h run_recovery's walls_around_roofs: its inliers' rectangle in plan), and that model
  /// is kept when keep_tighter_planes says so against the first (valid; p2m lower by finer_outline_min_gain;
  /// no more slivers unless fewer points are far). Report: scene.left_out_roofs. Why: a roof part standing on
  /// another roof, inside the building's outline, whose own outline holds no segment gets no wall under it, and
  /// the min-cut leaves it out (AHN3_11936: a 5 m² sloped structure of 56 points on a flat roof, RMS of the
  /// building's points to the model 0.297 m against roofer's 0.063 m). Only where a roof is left out: no second
  /// pass for the other buildings (issue 43: time). 30: the detection's smallest plane
  /// (StructureParams::min_region_points): a roof part found on its own, not one of the small planes (#99).
  /// false: off.
  bool left_out_roof_walls = true;
  int left_out_roof_min_points = 30;
  /// A roof hides what is under it: a left-out roof plane gets walls only when the scan holds at most this share
  /// of its inliers' count of points under it (points_under_roof: inside its inliers' rectangle in plan, a spacing
  /// in from its sides, more than the inlier distance under the plane). A plane in a tree's crown over a roof has
  /// the crown's lower points and the roof under it, and with walls it became a pillar up into the tree, which
  /// explains the tree's points better (AHN3_15708 on the AHN3 tile: RMS 2.62 -> 0.89 m, the tree modelled).
  /// Measured on the AHN3 tile's left-out roofs: the raised parts 0 to 0.04 (AHN3_11936 0 of 56, AHN3_16207 2 of
  /// 47, AHN3_08831 4 of 204), the planes in trees 0.43 to 1.03 (AHN3_15708 36 of 35, AHN3_09219 24 of 56 and 37
  /// of 37) and a large plane of AHN3_08831 with 812 points under its 653; a tenth lies between. A share, not a
  /// count: a larger roof has more points at its edges that the spacing in does not remove.
  double left_out_roof_max_under = 0.1;
  /// What a roof hides, counted among what the model leaves unexplained (DECISIONS #236): points_under_roof
  /// counts only the points under the roof that lie farther than the inlier distance from the first model. Why:
  /// a crown's lower branches under a plane in a tree are on no part of the model, but a roof that the scanner
  /// sees through (glass, a lattice, a canopy over a lower roof) has under it the lower roof, the floor and the
  /// ground the model already holds: AHN3_08831's 656-inlier plane at 9 m over its 6.8 m roof, 813 points under
  /// it, was left out (RMS of its points to the model 0.40 m, roofer's 0.28). false: every point under counts
  /// (#159).
  bool left_out_roof_under_unexplained = true;
  /// The walls #159 gave the first run's left-out roofs hold in every later run of the building (steps 5 and 6:
  /// finer outlines, tighter planes): where the first run kept its walled model, each later run gives walls
  /// (the same rectangle rule) to its roof plane holding half or more of such a roof's inliers (carried_roofs),
  /// without a second pass of its own. Report: scene.left_out_roofs_carried (the planes, in the run kept). Why:
  /// the later runs are measured against the walled model, and without the walls they lack the roof the first
  /// run's walls gave back, so a finer outline that beat the first model no longer beats it (AHN3_16207 turned
  /// 37°: walled first model p2m 0.513 %, the 4-point outline without the walls 0.494 %, not 5 % lower; the
  /// building's p2m 0.494 -> 0.513 % with #159, DECISIONS #166). No extra run: the walls are four more planes in
  /// runs that are made anyway (issue 43's time). false: off (#159 as first landed).
  bool left_out_roof_walls_carried = true;
  /// When the model of stages 3 to 7 leaves no roof out but runs to the partition's box (a face of it lies on
  /// a side of the box, model_reaches_the_box: where a wall is missing, nothing but the box stops the cells
  /// that hold a roof's points), #159's second pass runs with four walls around every roof of the building
  /// (its inliers' rectangle in plan), kept as #159's is (keep_tighter_planes: valid, p2m lower by
  /// finer_outline_min_gain of it). Report: scene.left_out_roofs with `"why": "box"`. Why: at half density a
  /// short side of a roof (an annex's end, a step in the outline, a gable end) holds two or three outline
  /// points, too few for a segment, so no wall is recovered there and the model runs out to the box (47 of the
  /// 112 half-density models have faces on it: AHN3_19114's 2 x 2.5 m annex, 10 % of the model's area;
  /// DECISIONS #183). The box is no evidence: a roof's rectangle is its points' extent. Only where the model
  /// reaches the box (a second pass, issue 43's time), and the result decides. false: off.
  bool box_face_roof_walls = true;
  /// The runs decided by the result (#159's and #183's walls around roofs, step 5's finer outlines, step 6's
  /// tighter planes) are judged both ways (issue 42 item 1: the model explains its points, and its points its
  /// model): besides p2m (keep_tighter_planes, keep_finer_outline), a run is kept only when the sum of its
  /// points' distances to its model and of the distances of the points its unseen surface would have had is no
  /// larger than the model's it would replace (no_more_unseen_roof). The unseen surface (pipeline_judge.cpp
  /// unseen_roof_area): the model's surface farther than unseen_roof_distance r from every point, facing up or
  /// standing higher than the points near it in plan (a scan from above sees it; not the walls under the roof);
  /// each piece counted as the points the scan's density (1 / r²) would have put there, at its distance to the
  /// nearest point. Why: p2m is measured from the points, and a model that fills volume where no point lies (a
  /// gable's end filled up to the ridge: DECISIONS #195's seed-4 house; a fin over a flat roof) loses nothing by
  /// it; both sums are in the same units, so a run that explains many points better may add a little unseen
  /// surface, and one that adds much may not (DECISIONS #205). 2 (`--config` turns it on): the detection's
  /// inlier distance (StructureParams::max_distance): nearer, the surface is a plane's own. **Off by default**
  /// (0; <= 0: p2m alone, as before): on the 112 airborne buildings it moved as many models away from City3D's
  /// as towards them, and it refuses repairs on real scans whose unseen surface is a gap in the scan (a dense
  /// scan's 1 / r² weighs every gap heavily: Vaihingen_00048's finer outline at half density, p2m 0.55 -> 1.16 %).
  double unseen_roof_distance = 0.0;
  /// With a footprint (`hsr city`, `--footprint`): a point whose plane has no facet in the partition (on no plane, or
  /// on a wall that gave way to the footprint, DECISIONS #128), standing within the detection's inlier distance of a
  /// footprint edge in plan (its projection on the edge) and more than that distance above the ground, votes in the
  /// min-cut as an inlier of that edge's wall, its normal the edge's outward side (pipeline.cpp
  /// footprint_wall_points). Why: the min-cut weighs the points of data planes only; a facade on the footprint that
  /// no plane holds (a narrow part of the footprint, a wall too short for a plane) had no say, and the model's plan
  /// left the footprint where roofer's extrusion follows it (AHN3_03689: a 0.2 m wide spike of the footprint over
  /// a facade of 30 points 1.5 m from the model; issue 43 item 4, DECISIONS #170). false: off.
  bool footprint_wall_points = true;
  /// A gable's two halves, decided by the result (issue 42 item 3, the sparse and the small; DECISIONS #215): in a
  /// building scan of at most SceneParams::auto_choice_max_points points, a roof plane of the detection's size
  /// that holds both slopes of a gable is split in two by step 7 (pipeline_later_runs.cpp try_gable_halves). A candidate
  /// (roof_split.cpp gable_halves_of; report counts.gable_half_candidates): its inliers and the points on no plane
  /// beside it (within wing_reach r in plan, not lower than its eave by more than gable_half_distance r), split
  /// across one of their two axes in plan where the two sides' least-squares planes fit them best, with at least
  /// small_plane_points on either side, the two planes meeting at a ridge (each tilted more than
  /// gable_half_min_pitch_deg, each one's uphill side facing the other); each half keeps its side's points within
  /// gable_half_distance r of its plane. Step 7 runs the chain again with every candidate split so and keeps
  /// that model when keep_tighter_planes says so against the model kept so far (valid; p2m lower by
  /// finer_outline_min_gain of it; no more slivers unless fewer points are far; the same ground): the result
  /// decides, no ratio of the halves' sizes or fits. Report: scene.gable_halves. Why: the smallest plane is a
  /// count (StructureParams::min_region_points, 30); a gable's smaller half in a sparse scan holds fewer, and the
  /// larger half's plane, with its 2 r inlier distance and its leftover points, grows over the ridge and takes
  /// the smaller half's upper points, so no small plane is left to find there, and region growing over the same
  /// points grows over the ridge again (the normals there lean both ways). Vaihingen_00004: 58 points at 4 per
  /// m², one plane of 42 over both slopes, the west slope's lower points on no plane, the model a shed.
  /// **Off by default** (false; `--config` turns it on): on the 112 airborne buildings and their variants it
  /// lowers p2m wherever it changes a model, but moves as many models away from City3D's as towards them and no
  /// median or count of issue 42 (DECISIONS #215). gable_half_distance (r): the halves' inlier distance, step 6's tighter one
  /// (tighter_planes_distance): at 2 r a plane takes the other slope's points near the ridge. gable_half_min_pitch_deg:
  /// SceneParams::auto_level_deg's 10 degrees: flatter, a face is level and has no downhill side.
  bool gable_halves = false;
  double gable_half_distance = 1.0;
  double gable_half_min_pitch_deg = 10.0;
  /// Two surfaces in one roof plane, decided by the result (issue 43 item 4, closer than roofer; DECISIONS #223):
  /// step 7 also splits a roof plane of the detection's size whose points (as gable_halves_of gathers them) lie on
  /// two surfaces of any kind, not only a gable's two halves: a crease between a steep and a flatter slope, a hip
  /// grown into the slope beside it. The split (roof_split.cpp two_surfaces_of): the least-squares split of
  /// gable_halves_of across either axis in plan, its two planes then refined by taking each point to the nearer
  /// of them and fitting both again (the line between two surfaces meeting at a crease runs where they meet, at
  /// any angle to the axes); a candidate when the two planes hold at least small_plane_points more of the points
  /// within gable_half_distance r than the one plane does (what one plane leaves far and two explain: a plane's
  /// worth; one flat roof's noise gains a few). Each half keeps its points within gable_half_distance r of its
  /// plane; step 7 runs with every candidate (and every gable's halves, when gable_halves is on) split and keeps the
  /// model by the result (keep_tighter_planes). Why: the detection grows a region over a crease when the two
  /// surfaces' normals lie within StructureParams::max_angle_deg (25°) of each other and their points within its
  /// 2 r: AHN3_08596's north side, a 38° slope and a 15° one, one plane of 621 points whose points stand up to
  /// 0.6 m off it (RMS of its points 0.24 m, 0.04 m to the two). **Off by default** (false; `--config` turns it
  /// on; DECISIONS #223).
  bool two_surface_planes = false;
  /// Step 7 runs only where the model kept so far leaves a candidate's points far (DECISIONS #228): a candidate
  /// plane (gable_halves, two_surface_planes) counts when its two halves hold at least the detection's smallest
  /// plane (StructureParams::min_region_points as resolved) of points farther than gable_half_distance r from
  /// that model (its evaluation's distances; report counts.gable_half_candidates_far), and step 7's run is made
  /// only when one does and bringing those candidates' far points onto their halves' planes would lower the
  /// model's p2m by finer_outline_min_gain (the share the keep rule asks; SplitGate; report scene.split_gate),
  /// unless that model is invalid (a valid one may then be kept by validity alone). Why: a candidate is found on the detection's planes alone, before any model; where the
  /// model already explains most of the candidate's points (a small plane, step 6's tighter planes or a wall took
  /// them), what is left far is no plane of the detection's size, the size of the planes step 7 splits; and step
  /// 7's run (a whole run of the chain) was kept on 7 of the 28 AHN3 buildings that ran it (DECISIONS #223). At
  /// the halves' inlier distance, as their own test. **Off by default** (false: step 7 runs wherever a candidate
  /// is found, #215, #223; `--config` turns it on): on the AHN3 tile with two_surface_planes it halves step 7's
  /// runs (28 -> 14) with every RMS gain kept, but step 7 stays 1.3 x the tile's one-job wall, and it refuses
  /// #215's Vaihingen_00004 (r = 0.87 m: the shed model leaves none of the gable's points farther than 1 r).
  bool split_where_left_far = false;
  /// Step 7's candidates (gable_halves, two_surface_planes) gather no point on no plane higher than the roof plane's
  /// ridge (its highest height over its inliers in plan) by more than gable_half_distance r, as none lower than its
  /// eave (roof_split.cpp split_candidates_points; DECISIONS #242). Why: a surface grown into one plane spans that
  /// plane's heights; a crown over a flat roof, gathered with it, was split off as a steep surface and modelled
  /// (AHN3_11729 at half density). **Off by default** (false: no bound above): on the AHN3 tile with two_surface_planes
  /// and the gate it trades as many RMS gains as it makes (AHN3_00065's upper part, 0.397 -> 2.049 m, is lost; 08314,
  /// 08831, 16056 and 16125 come closer), the median the same (DECISIONS #242).
  bool split_below_ridge = false;
};

/// Whether step 7 splits roof planes at all (gable_halves or two_surface_planes on): its candidates are counted
/// and its run made only then.
inline bool splits_roof_planes(const BuildingParams& p) { return p.gable_halves || p.two_surface_planes; }

/// Every field as JSON and back (scene_params.cpp; the run report's parameters.scene.building).
void to_json(nlohmann::json& j, const BuildingParams& p);
void from_json(const nlohmann::json& j, BuildingParams& p);

/// Throws Error(BadInput, "scene") naming the first field out of range.
void check_building_params(const BuildingParams& params);

/// What the scene stage may know of the ground besides the points it reconstructs (see the file comment).
struct SceneGround {
  std::vector<Vec3> points;       ///< points classed as ground (LAS class 2), local coordinates; may be empty
  const Raster* raster = nullptr;  ///< a terrain model, global coordinates; null: none
  Vec3 origin = Vec3::Zero();      ///< the cloud's local-to-global shift (to sample the raster)
  /// Points the file classes as building (LAS class 6) among those reconstructed: > 0 makes `auto` pick
  /// `building`.
  std::size_t building_class_points = 0;
};

struct SceneResult;  // scene.h

/// Per plane: foliage, not a surface (a loose layer of points whose normals scatter; see the file comment).
std::vector<bool> foliage_planes(const PointCloud& cloud, const SceneStructure& s, const BuildingParams& params);

/// Fills the building's ground, roles and main direction into `out` (the file comment's rules, in order).
/// Throws Error when no plane is left to be a roof: DegenerateInput with wall planes left, NoPlanes without.
void building_scene(const PointCloud& cloud, const SceneStructure& structure, const BuildingParams& params,
                    const SceneGround& ground, const std::vector<bool>& foliage, SceneResult& out);

/// The structure of the building alone: roof and wall planes (ground and clutter planes dropped, their points
/// unassigned), walls made exactly vertical and turned onto the main directions when within
/// main_direction_snap_deg, walls that became coplanar merged into one, and each roof's outline completed along
/// the main directions where its segments miss a side; adjacency, second order and intersection lines follow
/// (subset_planes).
SceneStructure building_planes(const PointCloud& cloud, const SceneStructure& structure, const SceneResult& scene,
                               const BuildingParams& params);

/// What step 7's count (split_candidates) needs of a run's scene: the roof planes of the detection's size that may
/// be split (role Roof after the small planes joined, no wall), each with its index, plane and inliers; the building's
/// points on no plane; the spacing and the smallest plane as detected. Plain data, about one index a point: a run
/// keeps it with its model (PipelineResult::split_input) and only the kept model's is counted (DECISIONS #239).
struct SplitInput {
  struct Roof {
    std::size_t plane = 0;     ///< its index in the structure (building_small_planes' result)
    Plane fit;                 ///< its plane
    std::vector<int> inliers;  ///< its inliers, as the structure lists them
  };
  std::vector<Roof> roofs;
  std::vector<int> free_points;       ///< the points on no plane, ascending
  double spacing = 0.0;               ///< the scan's spacing r (m)
  std::size_t min_region_points = 0;  ///< the detection's smallest plane as resolved (split_gate's plane's worth)
};

/// Step 7's candidates, each as its two halves' inlier lists: the roofs of `input` that hold a gable's two halves
/// (BuildingParams::gable_halves) or else two surfaces (two_surface_planes), in the order of `input.roofs`;
/// `*planes`, when given, gets their indices in the structure.
using SplitCandidates = std::vector<std::array<std::vector<int>, 2>>;
SplitCandidates split_candidates(const PointCloud& cloud, const SplitInput& input, const BuildingParams& params,
                                 std::vector<std::size_t>* planes = nullptr);

/// The building's small planes (BuildingParams::small_plane_points): `detected` with the planes found among the
/// building's points on no plane appended (structure.h add_small_planes, `structure` the detection's parameters),
/// and their roles appended to scene.roles: a roof or a wall by its normal when it is no foliage and touches a
/// roof or wall of the building (directly or through another small plane that does), clutter otherwise.
/// `detected` as it is when the scene is no building, the rule is off or no plane is found.
/// `graphs` (may be null): add_small_planes' kNN graph cache.
/// `gable_halves` (BuildingParams::gable_halves, two_surface_planes): Count: `*split_input` gets what step 7's
/// count needs (SplitInput; the count itself is made on the kept model only, split_candidates); Split: the roof
/// planes that are a gable's two halves or two surfaces in one are also replaced by their halves (step 7's run),
/// the halves' roles Roof, and `*planes_split` gets how many. Off: neither.
enum class GableHalves { Off, Count, Split };
SceneStructure building_small_planes(const PointCloud& cloud, const SceneStructure& detected,
                                     const StructureParams& structure, const BuildingParams& params,
                                     SceneResult& scene, KnnGraphCache* graphs = nullptr,
                                     GableHalves gable_halves = GableHalves::Off, SplitInput* split_input = nullptr,
                                     std::size_t* planes_split = nullptr);

/// Step 7's gate (BuildingParams::split_where_left_far, DECISIONS #228) on a model, `point_distance` being every
/// point's distance to it (EvalResult::point_distance): `far_candidates`, how many of `candidates`
/// (building_small_planes' list) have at least `min_points` (the detection's smallest plane) points of their two
/// halves farther than gable_half_distance x `spacing` from the model; `gain`, over those candidates, the sum of
/// those points' distances beyond their half's least-squares plane (what the split would take off the model's
/// distances, were the points on their halves); `distance_sum`, the sum of every point's distance (p2m's sum).
struct SplitGate {
  std::size_t far_candidates = 0;
  double gain = 0.0;
  double distance_sum = 0.0;
  /// Whether step 7's run may be kept by its gain: a candidate left far, and its gain at least
  /// finer_outline_min_gain of the distances (the share keep_tighter_planes asks a later run's p2m to fall by).
  bool may_gain(const BuildingParams& params) const {
    return far_candidates > 0 && gain >= params.finer_outline_min_gain * distance_sum;
  }
};
SplitGate split_gate(const PointCloud& cloud, const SplitCandidates& candidates, const std::vector<double>& point_distance,
                     double spacing, std::size_t min_points, const BuildingParams& params);

/// Whether the finer outline's run is kept (BuildingParams::finer_outline_points): a valid solid over an invalid
/// or missing one; of two valid solids the finer one only when its p2m is below (1 - finer_outline_min_gain)
/// times the first's and it has no more faces under 0.1 % of the surface (EvalResult::face_sizes.small_faces:
/// a short segment's wall can leave a sliver, city3d_bldg94). The first run wins ties: it is the default's model.
bool keep_finer_outline(bool first_valid, double first_p2m, std::size_t first_small_faces, bool finer_valid,
                        double finer_p2m, std::size_t finer_small_faces, const BuildingParams& params);

/// Whether step 6's run with tighter planes is kept (BuildingParams::tighter_planes_distance, DECISIONS #137): as
/// keep_finer_outline (a valid solid over an invalid one; of two valid solids the tighter only when its p2m is
/// below (1 - finer_outline_min_gain) times the first's), except that more faces under 0.1 % of the surface are
/// taken when the tighter model leaves fewer of the scan's points farther than the detection's inlier distance
/// (StructureParams::max_distance r) from it (`*_far_points`). Why: a step between two roofs, found, has a short
/// wall whose end can leave a small face where it meets a recovered wall (AHN3_04196 at half density: 0.02 % of
/// the area), while the ridge the first model put there leaves points beyond any plane's inlier distance (6 of
/// 215, none with the step); a sliver alone, with no point it explains, is refused as before (city3d_bldg94).
bool keep_tighter_planes(bool first_valid, double first_p2m, std::size_t first_small_faces, std::size_t first_far_points,
                         bool tighter_valid, double tighter_p2m, std::size_t tighter_small_faces,
                         std::size_t tighter_far_points, const BuildingParams& params);

/// Whether a later run's model may replace the one kept so far, judged both ways (BuildingParams::
/// unseen_roof_distance): the sum of the scan's points' distances to it (`*_p2m_sum`) plus the sum of the
/// distances of the points its unseen surface would have had (`*_unseen`, pipeline_judge.cpp unseen_roof_area over r²),
/// all in the points' units, no larger than the first's. Always true with the rule off (unseen_roof_distance <= 0).
bool no_more_unseen_roof(double first_p2m_sum, double first_unseen, double other_p2m_sum, double other_unseen,
                         const BuildingParams& params);

/// The roof planes of `building` (the structure the later stages use: not upright, at least min_points inliers)
/// that a model leaves out: half of their inliers or more (the median) farther than `far` from it, with at most
/// max_under times their inliers' count of the scan's points under them (points_under_roof: a roof hides what is
/// under it, a plane in a tree's crown does not).
/// `point_distance`: every point's distance to the model (EvalResult::point_distance). Why the median: a roof on
/// the model has its inliers within the detection's inlier distance of its plane, so of the model, but for a
/// few at its edges; one left out has most of them off it (DECISIONS #159).
/// `under_unexplained` (BuildingParams::left_out_roof_under_unexplained): only the points under it farther than
/// `far` from the model count.
std::vector<int> left_out_roofs(const PointCloud& cloud, const SceneStructure& building,
                                const std::vector<double>& point_distance, double far, std::size_t min_points,
                                double max_under, bool under_unexplained = false);

/// The roof planes of `building` (not upright) that are the roofs a first run gave walls to (`walled`: each such
/// roof's inliers, sorted): for each, the plane holding half or more of its inliers, if any; sorted, each once.
/// Why: a later run of the same building (another outline, tighter planes) has its own planes and their own
/// indices; the roof is the plane that holds its points (BuildingParams::left_out_roof_walls_carried, DECISIONS #166).
std::vector<int> carried_roofs(const SceneStructure& building, const std::vector<std::vector<int>>& walled);

/// The scan's points under a roof plane: inside its inliers' smallest-area rectangle in plan shrunk by r on each
/// side, more than `far` under the plane. `point_distance` (may be null): only the points farther than `far` from
/// the model count (what it leaves unexplained).
std::size_t points_under_roof(const PointCloud& cloud, const DetectedPlane& roof, double r, double far,
                              const std::vector<double>* point_distance = nullptr);

/// The outline prism's model (BuildingParams::outline_prism) and how it was made. `mesh` is empty when the points
/// span no area in plan or the roof is not above the ground.
struct OutlinePrism {
  PolygonMesh mesh;  ///< local coordinates (the cloud's); faces: roof, walls, bottom (their FaceClass)
  double ground_z = 0.0, roof_z = 0.0;
  GroundSource ground_source = GroundSource::None;
  std::string ground_note;                  ///< when the ground was assumed
  /// Per point: a roof point, above the gap under the roof (the points the model must explain; those under the
  /// gap are the ground or a wall's foot, as the low rule's points on no plane are in building mode).
  std::vector<bool> roof;
  std::size_t under_roof_points = 0;  ///< points under the gap (not to explain)
  double beyond_hull = 0.0;  ///< how far the outline stands outside the roof points' hull, m (outline_prism_beyond_hull)
};

/// The outline prism of `cloud` (r = `spacing`; BuildingParams::outline_prism): its roof points are the points
/// above the lowest gap of at least under_roof_gap r in their sorted heights (all of them when there is no such
/// gap, or fewer than 3 lie above it: nothing is seen under the roof); the ground comes from the first source of
/// the file comment's list that has one, with the roof points standing for the roof and wall inliers (given, raster
/// under them, classified ground points within ground_ring r of them in plan, the lowest point when a gap was
/// found, else assumed_wall_height under the lowest roof point); the roof is outline_prism_roof_quantile of the
/// roof points' heights; the outline is the convex hull of the roof points in plan (a few tens of points hold no
/// concave outline worth the name), its edges moved out by outline_prism_beyond_hull spacings (#219). `outline` (local x, y; a ring of at least 3 vertices, either orientation, not
/// repeating the first): the prism's outline instead of the hull (a footprint's, PipelineParams::footprint_prism).
OutlinePrism outline_prism(const PointCloud& cloud, double spacing, const BuildingParams& params,
                           const SceneGround& ground, const std::vector<Vec2>* outline = nullptr);

/// Roofs are seen from above, so every non-vertical plane's outward normal points up (n_z > 0); `outward` is
/// one unit normal per plane of the building structure (visibility.h's outward_normal), turned where the vote
/// said otherwise. Returns how many were turned. Object mode (`scene` not a building): 0.
std::size_t orient_roofs_up(const SceneStructure& building, const SceneResult& scene, std::vector<Vec3>& outward);

}  // namespace hsr
