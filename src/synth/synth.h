// Synthetic scans with ground truth (DESIGN.md §3): procedural CAD- and building-like models, scanned by a
// simulated terrestrial/aerial LiDAR (ray casting, range noise, occlusion), so tests can assert accuracy
// against truth and the missing-plane protocol can be measured.
#pragma once

#include "core/types.h"

#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace hsr {

/// The office model (`hsr synth office`, synth_indoor_model_names()): rooms behind thin partitions with
/// doorways, furniture turned at any angle, round pillars. Counts are per room unless said otherwise.
struct SynthOfficeParams {
  int rooms = 4;                     ///< rooms, 1-6 (one row of up to 3, two rows from 4 on)
  double partition = 0.12;           ///< thickness of the partitions between rooms, metres
  double door_width = 0.9;           ///< width of each doorway, metres
  double door_height = 2.1;          ///< height of each doorway, metres (below the ceiling: a lintel above it)
  int tables = 2;                    ///< tables on four legs, per room
  int chairs = 4;                    ///< chairs on one post (a cross-shaped base), per room
  int desks = 1;                     ///< L-shaped desks (two panel legs and a drawer pedestal), per room
  int cabinets = 1;                  ///< closed cabinets (boxes), per room
  int shelves = 1;                   ///< open shelves (sides, back, boards), per room
  int pillars = 1;                   ///< round pillars, floor to ceiling, per room
  int pillar_sides = 24;             ///< sides of the polygonal prism that is a round pillar's truth
  double turned_share = 1.0;         ///< share of the furniture turned by a random angle in [0, 360 degrees);
                                     ///< the rest stands along x or y
  /// When finite, every piece other than a pillar is turned by this angle, degrees (the random draws are
  /// still made, so the rest of the seed's layout stays as it was); NaN: turned_share decides. For tests
  /// that ask for a piece at a known angle (issue 41: "a desk at 37 degrees gets its box at 37 degrees").
  double angle_deg = std::numeric_limits<double>::quiet_NaN();
  int scanners = 2;                  ///< scanner stations per room
  double scanner_height = 1.5;       ///< height of the stations above the floor, metres
  double clearance = 0.15;           ///< least gap between the bounding boxes of two pieces, metres
  double wall_margin = 0.3;          ///< least gap between a piece and a wall or partition, metres
};

struct SynthParams {
  std::uint64_t seed = 1;       ///< all randomness (noise, ray jitter) derives from it
  /// Range noise: standard deviation along the ray, as a fraction of the model's bbox diagonal (indoor
  /// models: of 10 m, so a larger hall is not scanned noisier; 1 cm at the default). Default 0.001 ("the
  /// default noise" of the tests); 0 gives exact points on the model. SynthScan::noise is always the
  /// fraction of the diagonal.
  double noise = 0.001;
  /// Scanner positions (model coordinates). Empty: the model's own default positions.
  std::vector<Vec3> scanners;
  /// Approximate total number of points over all scanners (terrestrial models; the aerial ones use
  /// aerial_density instead, the indoor ones density).
  std::size_t target_points = 40000;
  /// Terrestrial and indoor models: points per m² of the truth's surface; the scan then aims at
  /// density x (truth area) points instead of target_points. 0: the model's own default (hall 60,
  /// meeting_room 400; none for the other models, which use target_points).
  double density = 0.0;

  // --- the indoor models (hall, meeting_room)
  /// hall: furniture blocks (desks, cabinets, shelves, crates, pillars); meeting_room: chairs.
  /// 0: the model's default (hall 120, meeting_room 16). Ignored when `planes` is set.
  int blocks = 0;
  /// hall: blocks are added until the truth has at least this many planes (about 4.4 per block); the
  /// hall grows with the block count (see synth_indoor_model_names()). 0: `blocks` decides.
  int planes = 0;

  /// The office model's layout and furniture (its density: `density`, default 80 points/m²).
  SynthOfficeParams office;

  // --- the airborne scanner (models aerial_*; metres)
  double aerial_density = 10.0;      ///< points per m² on horizontal surfaces (a typical national survey)
  double aerial_range_noise = 0.03;  ///< range noise, standard deviation along the ray, in metres
  /// Ground points around the building (a horizontal plane at z = 0 reaching 4-8 m beyond the footprint):
  /// -1 decided by the seed (odd seeds have ground), 0 none, 1 always.
  int aerial_ground = -1;
  /// Trees (crowns near the building that partly return echoes and occlude): -1 decided by the seed
  /// (0-2), else exactly this many.
  int aerial_trees = -1;
};

/// A true plane of the model: equation and the area of the model's surface lying on it.
struct SynthPlane {
  Plane plane;                ///< normal = outward normal of the truth faces on it
  double area = 0.0;          ///< total area of the truth faces on this plane
  std::size_t points = 0;     ///< number of scan points sampled on it (0: the plane is missing in the scan)
};

/// A piece of furniture of an indoor model (written to planes.json, so a benchmark can ask for each one).
struct SynthBlock {
  /// desk, cabinet, shelf, crate, pillar (hall); table, chair, cabinet (meeting_room); table, chair, desk,
  /// cabinet, shelf, pillar and also partition (the slab between two rooms, doorways included) and doorway
  /// (the opening through a partition) (office)
  std::string kind;
  BBox box;              ///< axis-aligned bounds (metres)
  double angle = 0.0;    ///< turn about z of its own frame, radians (0: axis-aligned)
  /// office only (else invalid): the bounds in the piece's own frame, whose origin is `origin` in the
  /// world (a world point w lies in the piece's frame at R(-angle) (w - origin)).
  BBox own;
  Vec3 origin = Vec3::Zero();
};

/// The models (metres, z up; all built by exact CSG of boxes and gable prisms in models.cpp):
///   box          4 x 3 x 2 box.
///   house        cross-gable L house: two 6 m wide wings (10 m along x, 11 m along y), eaves 3 m, ridges
///                6 m, meeting in two roof valleys; 11 planes.
///   dormer_house 12 x 8 gable house (eaves 3 m, ridge 7 m), one gabled dormer on the south slope, one
///                chimney through the north slope.
///   bracket      stepped bracket (base plate, step, upright) extruded 4 units along y, with a rectangular
///                slot through the base plate (units arbitrary, think cm).
///   room         8 x 6 x 3 room holding a table (top + 4 legs) and a floor-to-ceiling pillar; 2 scanners inside.
///   courtyard    two buildings around a 12 x 12 courtyard: a flat-roofed L block and a gable block with a
///                lower flat-roofed wing; scanners inside the courtyard, around, and one aerial.
/// The outdoor models and the bracket stand on z = 0; their bottom faces are in the truth but all scanners
/// are above z = 0, so they get no points (realistic, intended: a missing plane for the recovery stage).
/// Default scanners: terrestrial at 1.7 m around the building plus one aerial position above it.
///
/// Orientation convention everywhere: truth faces have normals pointing out of the truth solid. For the
/// room, the truth solid is the room's interior *air* (room box minus table minus pillar; genus > 0),
/// scanned from inside, so its face normals point into the walls, the furniture and the pillar, i.e. away
/// from the scanners, and the point normals (towards the scanner) are the opposite of the truth normals.
/// Truth faces are convex planar polygons (possibly with collinear vertices where a neighbouring face has a
/// corner), vertex 0 a strict corner, so fan triangulation is valid; vertex and face order are canonical.
///
/// Scanner: one fixed angular resolution for all scanners (chosen from a pilot pass so the total is about
/// target_points), Fibonacci ray directions randomly rotated per scanner (seeded); only the cone around the
/// model's bounding sphere is cast (other rays cannot hit; the full sphere when the scanner is inside it);
/// first hit along the ray (occlusion); hits at grazing incidence (|cos| < 0.02) dropped; range noise
/// N(0, noise * diagonal) along the ray (indoor models: noise * 10 m). Points are ordered by scanner, then by ray.
struct SynthScan {
  std::string model;
  std::uint64_t seed = 1;           ///< the parameters it was made with (written to planes.json)
  double noise = 0.0;
  std::size_t target_points = 0;
  PointCloud cloud;                 ///< points with unit normals oriented towards the scanner that saw them
  std::vector<int> point_plane;     ///< index into `planes` of the face each point was sampled on; -1 for
                                    ///< ground and tree points of the aerial models (not in the truth)
  PolygonMesh truth;                ///< closed, 2-manifold, outward oriented model
  std::vector<SynthPlane> planes;   ///< distinct planes of the model (coplanar faces share one)
  std::vector<Vec3> scanners;       ///< positions actually used
  std::vector<int> point_scanner;   ///< index into `scanners` of the scanner that saw each point
  std::vector<int> face_plane;      ///< index into `planes` of each truth face
  /// True for indoor models (the room): the scanners are inside the truth solid, which is the interior
  /// air volume, so truth normals point away from the scanners and point normals are opposite to them.
  /// False: the truth is the building/part volume and point normals agree with the truth normals.
  bool indoor = false;
  bool aerial = false;              ///< scanned by the airborne scanner (scanners = flight-line start points)
  std::vector<SynthBlock> blocks;   ///< indoor models: the furniture (empty for the other models)
  /// The truth's faces counted as extraction counts output faces: per connected planar region (coplanar
  /// truth faces sharing edges), one face plus one per hole (2 - its Euler characteristic). The truth's
  /// convex pieces (truth.faces) are more.
  std::size_t polygon_faces = 0;
};

/// Model names, in a fixed order: box, house, dormer_house, bracket, room, courtyard (terrestrial scans).
std::vector<std::string> synth_model_names();

/// Aerial building models, in a fixed order: aerial_flat, aerial_gable, aerial_hip, aerial_shed,
/// aerial_dormer, aerial_mixed, aerial_steep. Each is a family: the seed draws its dimensions, its orientation about z
/// and its position, and the flight line. Metres, z up, the building standing on z = 0:
///   aerial_flat    flat-roofed blocks of different heights, overlapping, sometimes a low annex touching it;
///   aerial_gable   gable block with a perpendicular, lower gable wing (T or L);
///   aerial_hip     hip-roofed block with a flat-roofed garage beside it;
///   aerial_shed    two shed-roofed blocks at different heights (a step edge between them);
///   aerial_dormer  gable house with one or two gabled dormers;
///   aerial_mixed   L of a flat-roofed wing, a gable wing and a hip-roofed corner block;
///   aerial_steep   small house with a steep (45-60 degree) gable or hip roof, sometimes a flat-roofed shed.
/// The airborne scanner: one or two straight flight lines at 500 m (seeded direction), a line scanner
/// sweeping across track (the ray to each ground sample leaves the line at its along-track position, with a
/// few degrees of pitch), ground samples on a jittered grid of aerial_density points/m², off-nadir angles
/// of 2-15 degrees over the building, first hit, range noise aerial_range_noise. Roofs get about
/// aerial_density points/m², walls facing a flight line tan(off-nadir) of it, walls facing away none.
/// Ground and trees (SynthParams::aerial_ground / aerial_trees) are in the points, not in the truth: their
/// points have point_plane = -1.
std::vector<std::string> synth_aerial_model_names();


/// Indoor models, in a fixed order: hall, meeting_room. Scanned from inside, the truth is the interior air
/// (as for the room: SynthScan::indoor), every piece of furniture a solid standing on the floor, never
/// touching a wall or another piece (clear of them by 0.4 m in the hall, 0.1 m in the meeting room), so
/// every face of it can be seen. Coordinates on a 1 cm grid; the seed draws everything. Metres, z up:
///   hall          40 x 30 x 3.5 m (scaled by sqrt(blocks / 250) when more blocks are asked for) with
///                 SynthParams::blocks pieces (default 120): desks 35 % (1.2-1.8 x 0.6-0.9 m, 0.70-0.78 m
///                 high), cabinets 20 % (0.4-1.2 x 0.4-0.6, 0.8-2 m), shelves 15 % (0.8-2.4 x 0.3-0.45,
///                 1.2-2.4 m), crates 20 % (0.3-0.7 square-ish, 0.3-0.6 m) and pillars 10 % (0.3-0.8 m
///                 square, floor to ceiling); 15 % of the pieces other than pillars turned by a random
///                 angle, the others along x or y. Scanners at 1.6 m on a grid of about 10 m (12 in the
///                 40 x 30 hall). Default density 60 points/m² of the truth's surface.
///   meeting_room  a room (at least 10 x 7 x 2.8 m) with a long table (top 6 cm thick on two panel legs),
///                 SynthParams::blocks chairs (default 16; seat block and back panel, turned up to
///                 +-12 degrees, pulled out at random) around it, cabinets along one wall; 3 scanners at
///                 1.5 m. Default density 400 points/m².
///   office        SynthParams::office.rooms rooms (default 4; 5.5-8.5 x 5-7 m each, one height of 2.7-3.1 m),
///                 in one row (up to 3) or two rows, behind partitions SynthOfficeParams::partition thick
///                 (12 cm) with a doorway (0.9 x 2.1 m) to each neighbour in its row and from each room of
///                 the second row to the first; per room (SynthOfficeParams): tables on four legs (2),
///                 chairs on one post with a cross base (4), L-shaped desks (1), cabinets (1), open shelves
///                 (1), round pillars (1, a prism of 24 sides), each piece turned by a random angle; clear
///                 of walls by 0.3 m, of each other by 0.15 m, of the doorways and the stations. 2 stations
///                 per room at 1.5 m. Default density 80 points/m². Its blocks also list the partitions and
///                 the doorways.
/// About 5 planes per hall block, 7 per chair.
/// Their scan is the stations' scans registered and thinned to one density, as surveys deliver them: points
/// drawn uniformly on the truth's faces at SynthParams::density, each kept when a scanner sees it (first
/// hit on its face, incidence at least 6 degrees off grazing) and measured from the nearest such scanner
/// (range noise along that ray, normal towards it). Faces no scanner sees (tops above the scanners' height,
/// sides facing a nearby wall) get no points.
std::vector<std::string> synth_indoor_model_names();

/// Builds the model and scans it. Deterministic for given params. Throws hsr::Error(BadInput) for an unknown
/// model name (the message lists the valid ones) and for a bad parameter. Terrestrial models ignore the
/// aerial_* parameters; aerial models ignore noise, scanners, target_points and density; only the indoor
/// models read blocks and planes.
SynthScan run_synth(const std::string& model, const SynthParams& params = {});

/// Writes DIR/points.ply (binary, with normals), DIR/truth.obj and DIR/planes.json (model, seed, noise,
/// noise_sigma, target_points, points, diagonal, solid convention, scanners, polygon_faces, per plane: id,
/// normal, offset, area, points; indoor models also blocks: kind, min, max, angle); creates DIR. Each file is written atomically. Byte-identical for equal scans.
void write_synth(const SynthScan& scan, const std::string& dir);

}  // namespace hsr
