// Stage 3: missing plane recovery (paper §3.3, supplement §1.2; DESIGN.md §1 stage 3).
//
// Singular segments. A boundary segment of plane i is *not singular* when an intersection line of plane i
// with a plane k of its neighbourhood runs within r_a of the segment's direction and passes within r_d of
// the segment's centroid (the mean of its supporting points); it is then "contained by" planes i and k, and
// k is recorded as its partner (stage 4 adds the segment's supporting points to k's hull). Every other
// segment is singular. The neighbourhood is every plane within two hops of i in the adjacency graph, first-
// order neighbours included (all of SceneStructure::lines): the paper's "second-order adjacent" read
// literally (two hops exactly) would leave a box face's edges with its own neighbours singular.
// (The supplement's pseudo-code tests the negation per line; the text's rule is the one meant.)
//
// Missing planes. Region growing over singular segments, longest first: a seed segment defines a plane
// through its centroid with the segment's 3D normal (so the plane contains the segment and is
// perpendicular to the segment's plane); singular segments of planes within two hops of an admitted
// segment's plane join when their normal is within r_a of the plane's normal (unsigned) and their
// supporting points lie within r_d of it on average; the plane is refit after each admission (least
// squares over the supporting points, kept only while it stays within r_a of the seed normal). Regions with
// at least `min_segments` segments from at least two different planes become recovered planes.
// Deterministic: ties in length are broken by (plane, segment index).
//
// A room (RecoveryParams::split_regions and level_caps, set by the room rule: RoomParams::recovery;
// DECISIONS #66). Furniture stands on the floor, so the floor makes every two pieces of it second-order
// adjacent and a region grows across the room, joining edges of pieces metres apart: its hull spans the
// room and cuts every cell it crosses. split_regions: a region's segments whose supporting points come no
// nearer than r_d to each other, directly or through other segments of the region, are separate pieces,
// each a recovered plane of its own (the region's orientation, an offset through the piece's points; a piece
// may hold segments of one plane only), so each polygon is where its segments are. level_caps: an upright
// plane (|n_z| < sin r_a) whose top, the highest of its inliers, meets no adjacent level plane (|n_z| > cos r_a)
// within r_d is a piece of furniture whose top no scanner saw (or whose top's edges hold too few points for a
// segment); adjacent such planes with tops within r_d of each other share one level plane (normal +z) at the
// highest of their tops, supported by their inliers within r of their own tops (RecoveredPlane::caps).
// level_sides (DECISIONS #67), the dual: a singular segment at least min_wall_length long on a raised level plane
// facing up (a top: n_z > cos r_a, its centroid more than r_d above the room's lowest point) is the edge of a
// side no scanner saw (a desk's side facing a wall): an upright plane through the segment's line, facing the
// segment's outward normal in plan, supported by its points, reaching from the edge down to the lowest point
// (RecoveredPlane::reach). One segment suffices, as for a building's wall: up is +z, and in a room, what stands
// under a top stands on the floor -- unless the floor was seen under the top (free_under_tops, DECISIONS #100: a
// floor point under its inliers' hull in plan, more than r inside its edge; a table on legs, a chair's seat):
// then the side reaches down to the top's underside, top_thickness r under it, and so does its piece's box.
// piece_boxes (DECISIONS #70): a piece of furniture stands apart in the room. Points off the room's enclosure
// (its highly visible planes) closer than the alpha radius are one surface (the alpha shapes' own rule), so
// they group into connected pieces; a group then splits into the parts of it that are objects of their own, apart
// by more than piece_split_link r and each holding a plane (DECISIONS #209: a shelf and the table beside it, a
// desk and the chair tucked at it). A piece of at least min_piece_points points whose planes lie in it
// (fewer than min_piece_points of each plane's inliers elsewhere, DECISIONS #74: a stray inlier beyond the alpha
// radius is no surface there; a piece with no plane at all is a crate whose faces each hold fewer points than the
// room's smallest plane) is modelled as its box where no plane of it covers a face: the box's
// sides follow its largest upright plane (without one, its points' smallest-area rectangle in plan), it spans
// its points in plan, and reaches from its highest point down to the floor (the room's lowest point; what
// stands there stands on the floor, as for level_sides) or, when its lowest point is more than r_d above the
// floor, to that point. A face is covered by a plane of the piece, of the enclosure, or a cap or side already
// recovered from the piece's planes, that lies within r_a of its orientation and passes within a spacing r of
// its centre (a side covered by planes of the piece only from more than box_side_gap r above its bottom is kept
// below their lowest inlier, DECISIONS #120); every other face is a recovered plane whose polygon is the face (RecoveredPlane::reach: its
// corners) and whose support is the piece's points on no plane nearest to it (they vote on its facets in stage
// 6, as a plane's inliers do). The faces of a piece are adjacent to each other and to its planes (events C stop
// each at the others' lines). So a crate no plane holds gets all five faces, a cabinet whose top and back no
// scanner saw gets those two, and a piece whose every face was found gets none. The box stands for the planes
// the piece's own segments would recover: a plane grown from segments of a boxed piece's planes alone that faces
// along none of its box's faces (within r_a) is a corner's artefact (short boundary segments cutting across the
// corners of its alpha shapes) and is left out (DECISIONS #72).
// posts_under_top (DECISIONS #139): a piece whose box hangs under a raised top with free space under it (a table on
// legs) gets a post for each group in plan (post_link) of at least post_min_points of its points under the top's
// underside: four upright faces in the box's frame around the group, at least post_min_width across, from the floor
// up to the underside, listed after the box's faces with its number (adjacent to them), supported by the group's
// points on no plane. Those points are the legs' (no upright plane reaches under such a top, underside_of_top).
// seen_face_front (DECISIONS #206): a piece seen from one side only reaches min_piece_depth behind its seen face's
// front (its points' extreme within the face's span across) when something of it beside the face stands more than r
// further forward (depth_from_seen_face); else behind the piece's front.
// seat_step (DECISIONS #141): a piece whose highest raised top with points over it (more than r over it, at least
// step_min_points) has them over part of it only (at least step_min_free r less across along an axis of its box: a
// chair's back over its seat) gets a box that ends at that top and, over the rectangle of those points only (at
// least step_min_width r across), a second box up to its highest point; a plane of the piece covers a side of that
// upper part only from the side its inliers were seen from (a 4 cm back lies within r of both its sides). A piece
// with no plane on a raised top takes the most populous level of its points on no plane facing up (seat_level,
// seat_min_points; DECISIONS #194) for that top: a chair's seat too small for a plane; its free space as a seat's.
// A raised top that nothing of its piece stands on and under whose piece's edge no side was seen (lone_top,
// free_under_lone_tops; DECISIONS #211) has a seat's free space too: a chair whose back no scanner saw.
// edge_boards (DECISIONS #217, off): a row of points on no plane at one height along the front of a piece's box,
// facing the way an upright plane of it was seen from and a board's depth before it, is a board seen edge-on: a slab.
// one_plane_per_surface (DECISIONS #73): a surface is one plane. The extent of a plane is its points' convex
// hull in it (a detected plane's inliers; a recovered plane's support and reach: the polygon stage 4 starts
// from). A recovered plane whose centre (its extent's points' mean, on it) lies within a spacing r of a plane
// already there, parallel within r_a (either side), and within r of that plane's extent, stands for a surface
// that plane already stands for, and is left out: two planes nearer than the points' spacing cut a slab the
// points cannot decide, and the min-cut steps across it in slivers. Detected planes are there first; then the
// recovered ones by their evidence: level caps (the top rows of several planes, at their highest points), planes
// grown from two segments or more (through their boundary points' mean, a little inside the edge they stand
// for), upright sides last (one segment each); within a kind, in order.
// opening_heads (DECISIONS #97, #98): two upright planes parallel within r_a and nearer each other than
// slab_thickness are the two faces of a slab (a partition). An upright boundary segment of each face (within
// jamb_angle_deg of vertical, DECISIONS #112) at one place along the slab, facing the same way along it, is a
// jamb; a jamb facing +along and the next one facing back bound an opening, whose lintel is the faces' inliers
// between them hanging from the highest without a gap in height wider than lintel_gap (DECISIONS #111: the
// opening's edge rows, between the jambs by a few centimetres, are not the lintel): when its lowest point is more
// than r_d above the floor, each jamb becomes an upright plane across the slab (floor to head) at the opening's
// edge (jamb_at_edge, DECISIONS #138) and the head a level plane, so the doorway is a cell of its own.
//
// Building mode (RecoveryParams::vertical; DESIGN.md §4): a roof segment's partner line must lie no more than
// partner_max_behind r inside the roof, behind the segment (DECISIONS #177: r_d reaches across a small roof at low
// density, so its far side's line would explain the near edge). The missing planes are walls, and up is +z, so one
// singular segment and the vertical suffice to fit one: the wall through a singular segment of a roof
// (a non-vertical plane) is the vertical plane containing the segment's line, facing the segment's outward
// normal, its direction turned onto the building's main directions when within `snap_deg`. Singular roof
// segments of any roof join it (not only segments of planes within two hops: the two edges of a height
// jump belong to roofs that do not touch, and face opposite ways) when their direction is within r_a of
// the wall's, their supporting points lie within wall_join_distance of it on average, they reach to
// within 2 r_d of its extent along it, and they do not face a member of the same roof the other way (that is
// the roof's other side); the wall is refit to the joined points (its line in xy; its direction stays
// snapped). A wall is kept when its segments are at least min_wall_length long in total, or half as long as
// its first roof's extent along it (a small roof's sides). It spans its roofs' extent along its line
// (RecoveredPlane::reach): a sparse scan leaves few outline points along an eave, not a shorter eave. Both edges of a height jump between roof
// parts (step edges) and every roof outline without a scanned wall below it become walls this way. (Joining
// uses wall_join_distance instead of r_d: parallel walls of neighbouring roof parts are often closer than r_d.)
// Walls around a left-out roof (run_recovery's walls_around_roofs, DECISIONS #159): a roof plane the first pass's model left out
// gets four walls, the sides of its inliers' smallest-area rectangle in plan (turned onto the main direction when
// within snap_deg), each through the outermost inliers on its side, spanning the side and reaching from a spacing
// above the roof's highest corner down to the ground (as every wall does), adjacent to the roof (its `caps`).
// A side on the plane of a wall already there but for rounding takes that wall's plane (around_side_same_wall, #191).
#pragma once

#include "core/types.h"
#include "structure/structure.h"

#include <vector>

namespace hsr {

struct RecoveryParams {
  double angle_deg = 10.0;       ///< r_a, degrees
  double distance = 5.0;         ///< r_d, in r (average point spacing)
  int min_segments = 2;          ///< segments supporting a recovered plane, at least (not in vertical mode)
  // --- building mode (see the file comment)
  bool vertical = false;         ///< recovered planes are vertical walls through singular roof segments
  double main_direction = 0.0;   ///< the building's main direction in xy, radians (scene/building/building.h)
  double snap_deg = 5.0;         ///< walls within this of a main direction are turned onto it, degrees
  double min_wall_length = 4.0;  ///< total length of a wall's segments, at least, in r
  double wall_join_distance = 2.0;  ///< a segment joins a wall when its points are this close on average, in r
  /// A side of a roof's rectangle (walls_around_roofs, #159/#183) whose two ends lie within this of the plane of
  /// a wall already there (a recovered wall or an earlier roof's side, within angle_deg of parallel) takes that
  /// wall's plane, in r (DECISIONS #191); negative: never. Why: the side runs through the roof's outermost
  /// inlier, and so does a recovered wall shifted to the same edge (shift_to_the_edge) or a side of a roof part
  /// beside it: the same plane but for rounding (1e-15 to 5e-13 m apart on AHN3_03689 and Vaihingen_00048 at
  /// half density). The exact partition keeps both planes and the faces between them come out closer than the
  /// output's precision: the walled model was invalid and not kept. Coplanar, the partition puts
  /// them on one support plane. A millionth of a spacing: rounding, not geometry (the nearest sides that are not
  /// the same plane stand 2 mm to 6 cm off; taking those too, at 0.1 or 0.5 r, moved more buildings, #191).
  double around_side_same_wall = 1e-6;
  /// A roof segment's partner line (the one that makes it not singular) may lie at most this far behind the
  /// segment, against its outward normal, in r (DECISIONS #177); negative: not tested. The segment is the
  /// outline of the roof's inliers, so the roof reaches at least to it: a line farther inside is another edge of
  /// the roof (its opposite side, its far wall) that r_d, 5 r, reaches across a small roof at low density.
  /// Why: AHN3_03700 at half density (2.8 m wide, r = 0.54 m) had its north-east side explained by the line of
  /// the south-west wall 5 r behind it; no wall was recovered there and the model ran out to the partition's
  /// axis-aligned box. 2 r: the inlier distance (StructureParams::max_distance), within which a line is at the
  /// roof's edge.
  double partner_max_behind = 2.0;
  /// An outer wall stands where this share of its supporting outline points is inside it (building_walls.cpp
  /// shift_to_the_edge, DECISIONS #54, #167): 1, through the outermost. The roof's edge lies beyond its
  /// outermost points (the next scan line fell off it), and more so in a sparser scan: at 0.9 the half-density
  /// models' walls stood 0.05–0.2 m inside City3D's (Vaihingen_00044, 00036), at 1 nearer (City3D -> hsr on its
  /// ground better on 52 of 89, worse on 9; #152 saw one building lose its middle at 1, no longer so). 0.9: #54.
  double wall_edge_quantile = 1.0;
  /// An outer wall stands this much further out than wall_edge_quantile puts it, in spacings of its roofs in plan
  /// (core/spacing.h plan_spacing: sqrt(hull area / inliers), not r), scaled as that shift is (edge_beyond_
  /// outermost_points; without a footprint only: the pipeline sets 0 when one is given). **0: measured, not the
  /// default** (DECISIONS #219): 0.5 (the roof's edge half a spacing beyond its outermost points on average) moved
  /// the half-density median (draw 9) 0.615 -> 0.786 %, 24 buildings nearer City3D's and 56 farther: the recovered
  /// walls are not inside the roofs' edges by one bias (as #152 found at the 0.9 quantile).
  double wall_beyond_points = 0.0;
  /// A plane is a roof (its segments seed walls) when its normal is more than this from horizontal, i.e.
  /// |n_z| > sin(roof_min_tilt_deg); the building structure's walls are exactly vertical.
  double roof_min_tilt_deg = 5.0;
  // --- a room (see the file comment)
  bool split_regions = false;  ///< a region's pieces farther apart than r_d are separate recovered planes
  bool level_caps = false;     ///< a level plane over upright planes whose top meets no level plane
  bool level_sides = false;    ///< an upright plane down to the floor under a raised top's singular edge (#67)
  /// Each opening through a slab (issue 41 item 5; DECISIONS #97, #98): two upright planes across the slab at its
  /// jambs (an upright boundary segment of each face at one place along the slab, facing the opening) and a level
  /// plane under its lintel. Without them the cell between the slab's two faces runs from the doorway up through
  /// the lintel, and is either a block across the doorway or a gap over it.
  bool opening_heads = false;
  /// opening_heads: two upright planes, parallel within r_a and nearer each other than this, in r, are the two
  /// faces of one slab (the inlier distance of detection, StructureParams::max_distance: a slab thinner than it
  /// is what region growing without signed normals made one plane, DECISIONS #93).
  double slab_thickness = 2.0;
  /// opening_heads: the lintel is the faces' inliers between the jambs hanging from the highest with no gap in
  /// height wider than this, in r (the alpha radius's 3 r, at which points are one surface); the head is its lowest
  /// row. A jamb's position is its segments' mean, a few centimetres inside the opening's edge, so the edge's own
  /// rows count between the jambs down to the floor (DECISIONS #111). 0: the lowest inlier between the jambs (#97).
  double lintel_gap = 3.0;
  /// opening_heads: a jamb's boundary segment on each face stands within this of vertical, its outward normal
  /// within it of the slab's direction, in degrees. An opening's edge holds few points on each face (its rows
  /// half in shadow), and a segment fitted to 0.4 m of them stood 14 degrees off (office 3 rooms seed 1), where
  /// r_a (10) is made for planes fitted to hundreds of points (DECISIONS #112).
  double jamb_angle_deg = 20.0;
  /// opening_heads: a jamb's plane stands at the opening's edge, the outermost of the slab faces' inliers below the
  /// head within r of the jamb (the pairing's r) towards the opening, not at its segments' mean, which lies about
  /// half a spacing inside the wall: the faces' points between the two lay on the doorway's facets and voted a block
  /// across it (DECISIONS #138). false: at the segments' mean (#98).
  bool jamb_at_edge = true;
  bool piece_boxes = false;    ///< a box completing each piece's faces that no plane covers (#70)
  /// level_sides and piece_boxes: a raised top with the room's floor seen under it (a floor point under its
  /// inliers' hull in plan, more than r inside its edge) has free space under it, a table on legs or a chair's
  /// seat: its sides and its piece's box reach down to its underside (top_thickness under it), not to the floor
  /// (issue 41 item 2; DECISIONS #100).
  bool free_under_tops = false;
  /// free_under_tops: an upright plane stands under a raised top (its free space denied, what stands there on the
  /// floor) when at least this many of its inliers lie more than a spacing under the top's unseen underside (room_rules.cpp
  /// upright_below; DECISIONS #241). As for a post (post_min_points), fewer are stray returns: a chair's back takes a
  /// point or two of the post under its seat into its plane (office 2 rooms seed 1's chair at (5.39, 0.84): its seat's
  /// plane of 14 inliers, its back's plane holding 1 post point 0.27 m up; the seat stood on a block down to the floor
  /// and the min-cut made it air). 1: any inlier (#100).
  int upright_min_inliers = 3;
  /// free_under_tops: a top's thickness, in r (its underside is unseen; a box thinner than a spacing is no box).
  /// With rim_underside, the thickness where the top's rim says nothing, and the deepest a rim is looked for.
  double top_thickness = 1.0;
  /// free_under_tops: a raised top's underside lies where its rim ends (room_rules.cpp rim_underside; DECISIONS
  /// #229): the points on no plane facing sideways (normal within 60 degrees of level) and out of the top, within r
  /// of the edge of its inliers' hull in plan and less than top_thickness r under its plane, when at least
  /// rim_min_points stand there, lie evenly over the edge's height: the underside lies twice their mean depth
  /// under the top's plane, and the piece's box hangs from the top that thin (no smallest height), its posts
  /// reaching up to it. Why: no scanner sees a table's underside; one spacing (0.11 m at 80 points/m²) under a
  /// 4 cm top put 7.5 of the offices' 64.5 m² of truth -> mesh on the tops' undersides (#221), and a thinner
  /// top_thickness left boxes lower than r, which box_of_piece refused (tables 121 -> 35). The top's edge seen
  /// from the side is the top's own thickness. false: top_thickness everywhere (#100).
  bool rim_underside = true;
  /// The fewest rim points that set a top's underside (rim_underside): as for a post (post_min_points), fewer are
  /// stray returns.
  int rim_min_points = 3;
  /// piece_boxes with free_under_tops and rim_underside: the slab of a box hanging from a raised top whose rim
  /// measured its underside (between the box's bottom and the top's plane, within the box's sides) is vouched solid
  /// (RecoveryResult::solid_slabs): a level facet inside it pays ExtractionParams::slab_facet_weight of its area
  /// term. Why: two tops at one height (the synth office's tables, all 0.72-0.76 m) give two level planes
  /// millimetres apart, tilted by their fits; in the hierarchical partition each grows through the other's slab
  /// (same level, not adjacent: crossed) before the boxes' faces (level 3) exist to stop it, and the cells between it
  /// and the box's bottom hold no point: solid they paid the bottom's area and their sides', air the crossing
  /// facet's, as large, and the min-cut left the top a sliver a few millimetres thick (DECISIONS #229's Left, #230).
  /// Only a measured underside: a seat's, top_thickness r under it by default, vouched so, lost chairs (#230).
  /// false: none (#229).
  bool solid_slabs = true;
  /// piece_boxes: a plane of the piece stands for an upright side of its box only down to its lowest inlier; when
  /// that lies more than this, in r, above the side's bottom, the side is kept below it (a chair's back covers
  /// its box's back above the seat only: without the side under it the cell under the seat opened into the room
  /// and the chair was labelled air; DECISIONS #120). A spacing r: closer, the plane's own sampling may have
  /// left the gap. <= 0: a covering plane stands for the whole side (#70).
  double box_side_gap = 1.0;
  /// piece_boxes: a piece seen from one side only (no upright plane of it faces against its largest upright plane,
  /// within r_a) whose points lie thinner than this across that plane, in r, gets a box this deep behind its seen
  /// face. An open shelf seen from its front leaves its boards' edges and its back panel within a spacing of one
  /// plane: its box's back then lay within r of that plane, which covers it (covers), and the box was left open, so
  /// the shelf was air (DECISIONS #130). Two spacings: the back lies more than r behind the plane wherever in its
  /// points the plane was fitted. <= 0: the box spans the points only (#70).
  double min_piece_depth = 2.0;
  /// piece_boxes with min_piece_depth: the box of a piece seen from one side reaches min_piece_depth behind its
  /// seen face's front, the extreme of its points within the face's span across, when that lies more than a spacing
  /// r behind the extreme of all its points (something of the piece beside the face stands in front of it: an open
  /// shelf seen only from behind, in one piece with a pillar beside it); room_rules.cpp seen_face_front. It reached
  /// that deep behind the piece's front only, 0.11 m behind the shelf's back, and the shelf's 0.38 m body was air
  /// (DECISIONS #206). false: behind the piece's front only (#130).
  bool depth_from_seen_face = true;
  /// piece_boxes with free_under_tops: the piece's points under a raised top's underside, grouped in plan (linked
  /// within post_link), each group of at least this many points a post from the floor up to the underside, four
  /// upright faces in the box's frame (a table's legs: 0-13 points each, no plane; DECISIONS #139). <= 0: no posts.
  int post_min_points = 3;
  /// The posts' grouping in plan: points under a top within this of each other stand on one post, in r (a table's
  /// legs stand 0.4-1.7 m apart, a leg's points within its 5 cm).
  double post_link = 2.0;
  /// A post's smallest width across, in r: the points of a leg seen from one side lie on one face, and a post no
  /// wider than their spread would be a sliver (a leg of the synth office is 5 cm, half a spacing at 80 points/m²).
  double post_min_width = 0.5;
  /// piece_boxes: a level plane of a piece seen from one side only with free space on its other side (seen from
  /// below; or from above with board_min_points of the piece's points facing up under it, a lower board seen
  /// through an open shelf's front) is one face of a board: its unseen face stands this far behind it, in r, with
  /// four upright edges around its inliers (a shelf's 2 cm boards: one plane was no solid, the compartments on
  /// both its sides were air, and the board was nothing; DECISIONS #186). Half a spacing, as a post's width
  /// (post_min_width). <= 0: no board slabs.
  double board_thickness = 0.5;
  /// The fewest points of a piece facing up under a board seen from above that show free space under it: as for
  /// a post (post_min_points), fewer are stray returns.
  int board_min_points = 3;
  /// piece_boxes with free_under_tops and board_thickness: of a piece's raised tops with free space under them only
  /// those whose underside lies within r of its box's bottom (the lowest underside) are tops the box hangs from;
  /// a higher one is a board inside the box and gets its slab as any level plane (room_rules.cpp tops_at_bottom).
  /// A shelf's plinth top, 8 cm up, is the floor seen under each of its boards, so every board was such a top and
  /// none got a slab: the compartments on both its sides were air and so was the board (DECISIONS #198). false: no
  /// top with free space under it is a board (#186).
  bool boards_over_underside = true;
  /// piece_boxes: a piece standing on the floor with no free space under it (no raised top's, no seat's step) whose
  /// points facing sideways a circle in plan explains better than its box's rectangle (their summed distance to
  /// the circle less than to the rectangle's nearest side) and as closely as its planes explain their inliers (their
  /// mean distance to the circle no more than that of its sideways points on planes to their planes), the circle's
  /// centre inside the rectangle and its diameter no more than the rectangle's longer side and 2 r, is round (a
  /// pillar, a bin): its upright sides are this many faces around the circle, each through its arc's mean (no pit,
  /// no bulge on average), not the rectangle's four. Why: a round pillar's unseen back was the rectangle's side
  /// through its outermost seen points, a chord up to a third of its radius inside it (issue 41 item 4; DECISIONS
  /// #240). < 3: the rectangle always.
  int round_sides = 8;
  /// piece_boxes: an open shelf's board seen edge-on (room_rules.cpp edge_boards; DECISIONS #217). A row of points
  /// on no plane inside the piece's box (of any piece or none: a front edge's points lie farther than the piece link
  /// from the rest of the shelf), facing the way an upright plane of the piece was seen from (its inliers' mean
  /// normal, within r_a), more than min_piece_depth r in front of that plane and reaching the box's front, at one
  /// height (linked within edge_board_height r, no taller than that, at least edge_board_min_points, spread at least
  /// edge_board_min_width r along the plane) with no level plane of the piece within r of that height, is a board's
  /// front edge: a board_thickness r slab at that height from the box's front back to the plane, across the box.
  /// Why: from stations 1.5 m up the boards at 0.9-1.9 m are seen edge-on, no point faces up or down, only 1-4
  /// points of their 2 cm front edges are there, no plane holds them and the model was the back's slab alone
  /// (DECISIONS #212). Off: measured on the 18 offices (21 faces in 7 of them), the traced board's slab comes out
  /// air (its two faces' area outweighs three points' votes in the min-cut) and the shelves' truth -> mesh rises
  /// (#217). false: no such slabs.
  bool edge_boards = false;
  /// The fewest points of a row that make it a board's front edge (edge_boards): fewer are a side panel's edge
  /// or a stray return as much as a board's.
  int edge_board_min_points = 3;
  /// edge_boards: a row's points are linked by height within this, in r, and the row is no taller than this: a 2 cm
  /// front edge's points lie within noise of each other's height, the boards of a shelf 0.3-0.4 m apart.
  double edge_board_height = 0.5;
  /// edge_boards: a row spreads at least this along its plane, in r: a board's edge runs across the shelf, a side
  /// panel's front edge (points at one place along the plane) is no row.
  double edge_board_min_width = 1.0;
  /// piece_boxes: a level plane of a piece facing up is a raised top (its underside and posts under it,
  /// free_under_tops; a seat under a back, step_min_free) when its centroid lies more than this above the room's
  /// floor (its lowest point), in r. The floor's own points lie within a spacing of it; two spacings are clear of
  /// them. Was r_d (distance, 5 r: 0.55 m at 80 points/m²), above the synth office's chair seats (0.48-0.54 m):
  /// a seat was no top, its box stood on the floor with the seat inside it, and the min-cut made the chair air
  /// (DECISIONS #168). <= 0: r_d.
  double piece_top_height = 2.0;
  /// piece_boxes with free_under_tops: the top a seat_step stands on (a seat under a back) has free space under it
  /// when no upright plane of its piece reaches under it, though no floor was seen under it (a chair's seat hides
  /// the floor under it from scanners 1.5 m up). First measured and not kept (DECISIONS #169: 2 of the office's 18
  /// models invalid, by a post's side and its box's side planes ulps apart); on since #179, which made them one
  /// plane. false: the floor must be seen (#100).
  bool free_under_seats = true;
  /// piece_boxes with free_under_seats: a raised top over which fewer than step_min_points of its piece's points
  /// stand more than r (nothing stands on it: no seat_step), and under whose piece's edge in plan fewer than
  /// step_min_points points facing sideways stand (no side of a box seen under it; room_rules.cpp lone_top), has
  /// free space under it as a seat's has, though no floor was seen under it, when no upright plane of its piece
  /// reaches under it. A chair whose back no scanner saw is a seat alone: no step, its box stood from the floor to
  /// its highest point and the min-cut made the whole chair air (DECISIONS #211). false: only a step's top (#179).
  bool free_under_lone_tops = true;
  /// piece_boxes with free_under_tops: a raised top with the floor seen under it keeps its free space though an
  /// upright plane of its piece reaches under it (a desk's 2 cm panels and drawer pedestal, a cabinet or a chair in
  /// one piece with a table); the piece's points under it then stand on posts (post_min_points), each panel, the
  /// pedestal or the cabinet a post of its own points. Why: #100 let an upright plane under a top deny it the free
  /// space (without posts a desk's panels were lost), so the desk's box stood from the floor to its top and the
  /// floor points seen under it voted it air, top and all: 28 of 63 desks missing, 30.3 m² of the offices' truth ->
  /// mesh (DECISIONS #180). false: an upright plane under a top stands it on the floor (#100).
  bool panels_as_posts = true;
  /// piece_boxes: a seat under a back (room_rules.cpp seat_step). When at least step_min_points of a piece's points
  /// stand more than r over its highest raised level top that has any, and they span at least this much less than
  /// the piece along an axis of its box, in r, the box ends at that top and only their rectangle stands higher (a
  /// chair's box ran up to its back's top over the whole seat: the seat's top inside the box, the chair lost by its
  /// seat; DECISIONS #141). Two spacings: narrower, the back spans the seat but for its own points' spread.
  /// <= 0: one block (#70).
  double step_min_free = 2.0;
  /// The part above a step at least this wide across, in r (a chair's back is 4 cm, a third of a spacing at
  /// 80 points/m²); widened away from the side its points face.
  double step_min_width = 0.5;
  /// The fewest points over a top that make a step: as for a post (post_min_points), fewer are stray returns. A
  /// chair's back holds 13-17 points at 80 points/m², a quarter of them within r of the seat.
  int step_min_points = 3;
  /// piece_boxes: a piece with no plane on a raised top finds its seat in its points on no plane facing up, at
  /// least this many of them within r/2 of one height (room_rules.cpp seat_level), which then stands for a seat's
  /// plane: its step (step_min_free) and its free space (free_under_seats). A chair's seat holds 15-18 points at
  /// 80 points/m², often fewer than the smallest plane (min_piece_points), and 28 of the offices' 46 missing
  /// chairs had only their back's plane (DECISIONS #194). As for a post (post_min_points), fewer are stray returns;
  /// 5 and 8 kept 5 and 7 fewer chairs. <= 0: a top needs a plane (#141).
  int seat_min_points = 3;
  /// piece_boxes: a side of a piece's box (its top or an upright side) on which the piece's only planes within r
  /// were seen from inside the box (their inliers' mean normal against the side's) stands this far behind the
  /// nearest of them, in r, and they do not cover it: they are the inner faces of a board or panel whose outer face
  /// no scanner saw (an open shelf's top board seen from below, its side panels seen through its front), unless
  /// step_min_points of its points within r of the side face out (the side's own surface, on no plane). Without it
  /// the inner face stood for the side and the board was nothing (DECISIONS #154). As thick as an unseen top
  /// (top_thickness): a box thinner than a spacing is no box. <= 0: a plane covers a side from either side (#70).
  double inner_face_depth = 1.0;
  bool one_plane_per_surface = false;  ///< a recovered plane lying on a plane already there is left out (#73)
  /// piece_boxes: the fewest points of a piece that gets a box; the room's smallest plane (region_k + 1,
  /// set by the pipeline), since fewer points than a neighbourhood are no evidence of a surface.
  int min_piece_points = 13;
  /// piece_boxes: a piece's points are linked within this, in r; 0: the alpha radius (#70).
  double piece_link = 0.0;
  /// piece_boxes: a piece splits into the parts of it that are each an object of their own (DECISIONS #209): its
  /// points linked within this, in r (a detected plane's inliers always together), each part of at least
  /// min_piece_points points holding a detected plane's inliers; the rest of the piece joins the part nearest to
  /// it. Two spacings: points closer than that sample one surface, and the alpha radius's 3 r links across the
  /// gap between two things standing apart. <= 0: a piece is what piece_link links (#70).
  double piece_split_link = 2.0;
  /// piece_boxes, piece_split_link: a detected plane with min_piece_points inliers in each of two parts holds them
  /// together no more (one plane grown across the coplanar faces of two things); its part's planes then lie in the
  /// whole group. false (the default; DECISIONS #210: measured, the offices better, the synth room's mesh -> truth
  /// worse): one plane's inliers always in one part (#209).
  bool piece_split_across_planes = false;
};

/// Every field of RecoveryParams as JSON and back (recovery_params.cpp; core/params_json.h): the run report's
/// parameters and `hsr reconstruct --config`. from_json keeps fields the object lacks, and throws
/// Error(BadInput, "config") on a key it does not know or a value of the wrong type.
void to_json(nlohmann::json& j, const RecoveryParams& p);
void from_json(const nlohmann::json& j, RecoveryParams& p);

/// A segment, addressed as structure.planes[plane].segments[segment].
struct SegmentRef {
  int plane = -1, segment = -1;
  bool operator==(const SegmentRef& o) const { return plane == o.plane && segment == o.segment; }
};

/// A recovered (missing) plane. Invariants: plane.normal unit; segments sorted, all singular, from at least
/// two different detected planes (a piece of a split region: from one or more; a level cap: none; a level side:
/// the one segment of its top; a piece's box face: none);
/// support = sorted union of the segments' supporting points (input point indices; a level cap: the top
/// points of the planes it caps; a piece's box face: the piece's points on no plane nearest to it, possibly none).
struct RecoveredPlane {
  Plane plane;
  std::vector<SegmentRef> segments;
  std::vector<int> support;
  /// level_sides: the segment's ends on the side and their shadows on the floor (stage 4 adds them to its hull).
  /// Vertical mode: two points on the wall at the ends of its roofs' extent along it, a spacing above its
  /// highest roof there: a wall under an eave spans the eave and reaches over it, however few outline points
  /// a sparse scan left along it (stage 4 adds them to its hull). Empty otherwise.
  std::vector<Vec3> reach;
  /// The detected planes it closes, sorted (adjacent to it in the partition): a level cap (RecoveryParams::
  /// level_caps): the upright planes whose tops it closes; a piece's box face: the piece's planes; else empty.
  std::vector<int> caps;
  /// A piece's box face (RecoveryParams::piece_boxes): the piece's number (faces of one piece are adjacent and
  /// listed one after the other; plane.normal points out of the box; the support points vote on its facets);
  /// -1 otherwise.
  int piece = -1;
};

/// Invariants: singular[i] and partner[i] have structure.planes[i].segments.size() entries; partner[i][j]
/// is -1 exactly when singular[i][j], else the plane k whose intersection line with i contains the segment.
struct RecoveryResult {
  std::vector<std::vector<bool>> singular;
  std::vector<std::vector<int>> partner;
  std::vector<RecoveredPlane> recovered;
  /// solid_slabs: each raised top's slab as the half-spaces bounding it (Plane::signed_distance < 0 inside): its
  /// box's four upright sides, its bottom (the underside its rim measured) and the top's plane facing up
  /// (ExtractionInput::solid_slabs).
  std::vector<std::vector<Plane>> solid_slabs;
  /// one_plane_per_surface: the recovered planes left out because a plane already stood for their surface.
  std::size_t covered = 0;
  std::size_t num_singular() const;
};

/// `enclosure` (piece_boxes only; per plane, empty: none): the room's enclosure, its highly visible planes
/// (VisibilityResult::highly), whose points are no piece.
/// `walls_around_roofs` (building mode; DECISIONS #159): the structure's roof planes a first pass's model left out
/// (pipeline_left_out_roofs.cpp walls_for_left_out_roofs, scene/building/building.h left_out_roofs), given by the pipeline for its
/// second pass of stages 3 to 7, never by a user (not a parameter: the report's scene.left_out_roofs lists them).
/// Each gets the four sides of its inliers' smallest-area rectangle in plan as walls (building_walls.cpp
/// walls_around_roof): a roof part standing on another roof, whose outline no segment follows, has no wall under
/// it, no cell of the partition holds it and the min-cut leaves it out. Empty: none.
RecoveryResult run_recovery(const PointCloud& cloud, const SceneStructure& structure,
                            const RecoveryParams& params = {}, const std::vector<bool>& enclosure = {},
                            const std::vector<int>& walls_around_roofs = {});

}  // namespace hsr
