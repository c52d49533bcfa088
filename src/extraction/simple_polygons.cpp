// Exact proof that every output polygon of the extraction is simple (extraction.h, prove_simple_polygons).
//
// A face is proven simple on the complex's exact (rational) vertices: at least 3 corners, not all on one
// line, every corner exactly on the plane of the first three that are not, and, projected along that
// plane's dominant normal axis (an exact affine map of the plane onto a coordinate plane), no two edges meeting
// except consecutive ones at their shared corner. Pairs of edges are found by a sweep over double
// bounding boxes widened far beyond the doubles' error, so only the exact tests decide.
// Then the doubles written to the file: the same 2D test on the rounded corners, and every corner against
// every nearby edge of the mesh. Parts of faces closer than the doubles' precision (sub-precision cells of
// the exact complex) can touch or cross once rounded; eval then finds the mesh self-intersecting, and this
// file says why beforehand. Where such a face touches or crosses itself (a neck narrower than the precision),
// zip_sub_precision_necks mends it (DECISIONS #161).
#include "extraction/extraction.h"
#include "extraction/near_edge_index.h"
#include "extraction/polygons.h"

#include "core/error.h"
#include "core/log.h"
#include "partition/exact_geometry.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>
#include <string>

namespace hsr {
namespace {

using partition_internal::P2;

/// Homogeneous integer coordinates (X, Y, Z, W), W > 0, of an exact point: (X, Y, Z) / W = p, no gcd.
void homogeneous(const ExactPoint& p, mpz_class (&h)[4]) {
  const mpz_class &xd = p.x.get_den(), &yd = p.y.get_den(), &zd = p.z.get_den();
  if (xd == yd && yd == zd) {
    h[0] = p.x.get_num(), h[1] = p.y.get_num(), h[2] = p.z.get_num(), h[3] = xd;
    return;
  }
  h[0] = p.x.get_num() * yd * zd, h[1] = p.y.get_num() * xd * zd, h[2] = p.z.get_num() * xd * yd;
  h[3] = xd * yd * zd;
}

/// The exact plane through the first three corners of the loop that are not collinear (a = corner 0, b the
/// next corner apart from it, c the first after b off the line ab); all zero when every corner is on one
/// line. Integer products of the corners' homogeneous coordinates: a positive multiple of the plane, with no
/// gcd (rationals would canonicalise every product: the Newell sum over all corners, 20 s of GMP gcd on a
/// hall's floor; three corners' rational cross product, most of the proof's time on a hall).
ExactPlane plane_of_loop(const std::vector<ExactPoint>& loop) {
  const ExactPoint& a = loop[0];
  std::size_t j = 1;
  while (j < loop.size() && loop[j] == a) ++j;
  if (j + 1 >= loop.size()) return ExactPlane{0, 0, 0, 0};
  mpz_class A[4], B[4], C[4], u[3], v[3];
  homogeneous(a, A);
  homogeneous(loop[j], B);
  for (int i = 0; i < 3; ++i) u[i] = B[i] * A[3] - A[i] * B[3];  // Wa Wb (b - a)
  for (std::size_t k = j + 1; k < loop.size(); ++k) {
    homogeneous(loop[k], C);
    for (int i = 0; i < 3; ++i) v[i] = C[i] * A[3] - A[i] * C[3];  // Wa Wc (c - a)
    const mpz_class nx = u[1] * v[2] - u[2] * v[1], ny = u[2] * v[0] - u[0] * v[2], nz = u[0] * v[1] - u[1] * v[0];
    if (sgn(nx) == 0 && sgn(ny) == 0 && sgn(nz) == 0) continue;
    // n . (p - a) = 0, times Wa: (n Wa) . p - n . (Xa, Ya, Za) = 0.
    return ExactPlane{Rational(nx * A[3]), Rational(ny * A[3]), Rational(nz * A[3]),
                      Rational(-(nx * A[0] + ny * A[1] + nz * A[2]))};
  }
  return ExactPlane{0, 0, 0, 0};
}

/// c lies on the closed segment [a, b], given that the three are collinear.
bool within(const P2& a, const P2& b, const P2& c) {
  return std::min(a.u, b.u) <= c.u && c.u <= std::max(a.u, b.u) && std::min(a.v, b.v) <= c.v &&
         c.v <= std::max(a.v, b.v);
}

/// The closed segments [a, b] and [c, d] share a point.
bool segments_meet(const P2& a, const P2& b, const P2& c, const P2& d) {
  using partition_internal::orient_sign;
  const int o1 = orient_sign(a, b, c), o2 = orient_sign(a, b, d);
  const int o3 = orient_sign(c, d, a), o4 = orient_sign(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  return (o1 == 0 && within(a, b, c)) || (o2 == 0 && within(a, b, d)) || (o3 == 0 && within(c, d, a)) ||
         (o4 == 0 && within(c, d, b));
}

/// Consecutive edges a -> b -> c meet beyond b: a zero-length edge, or c turning back along b -> a.
bool consecutive_edges_overlap(const P2& a, const P2& b, const P2& c) {
  if (a == b || b == c) return true;
  if (partition_internal::orient_sign(a, b, c) != 0) return false;
  return sgn((a.u - b.u) * (c.u - b.u) + (a.v - b.v) * (c.v - b.v)) > 0;
}

/// Empty when the 2D loop is simple, else what is wrong with it (edges numbered from 0 = q[0] -> q[1]).
std::string why_not_simple(const std::vector<P2>& q) {
  const std::size_t n = q.size();
  struct Box {
    double lo_u, hi_u, lo_v, hi_v;
  };
  std::vector<Box> box(n);
  double scale = 0;
  for (const P2& p : q) scale = std::max({scale, std::abs(p.u.get_d()), std::abs(p.v.get_d())});
  const double margin = 1e-9 * scale + 1e-300;  // get_d is within 2^-52 relative: far inside the margin
  for (std::size_t i = 0; i < n; ++i) {
    const P2 &a = q[i], &b = q[(i + 1) % n];
    const double au = a.u.get_d(), av = a.v.get_d(), bu = b.u.get_d(), bv = b.v.get_d();
    box[i] = {std::min(au, bu) - margin, std::max(au, bu) + margin, std::min(av, bv) - margin,
              std::max(av, bv) + margin};
  }
  std::vector<std::size_t> order(n);
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t x, std::size_t y) {
    return box[x].lo_u < box[y].lo_u || (box[x].lo_u == box[y].lo_u && x < y);
  });
  std::vector<std::size_t> active;
  for (const std::size_t e : order) {
    active.erase(std::remove_if(active.begin(), active.end(), [&](std::size_t f) { return box[f].hi_u < box[e].lo_u; }),
                 active.end());
    for (const std::size_t f : active) {
      if (box[f].hi_v < box[e].lo_v || box[e].hi_v < box[f].lo_v) continue;
      const std::size_t i = std::min(e, f), j = std::max(e, f);
      bool bad;
      if (j == i + 1) bad = consecutive_edges_overlap(q[i], q[j], q[(j + 1) % n]);
      else if (i == 0 && j == n - 1) bad = consecutive_edges_overlap(q[j], q[0], q[1]);
      else bad = segments_meet(q[i], q[i + 1], q[j], q[(j + 1) % n]);
      if (bad) return "edges " + std::to_string(i) + " and " + std::to_string(j) + " meet beyond a shared corner";
    }
    active.push_back(e);
  }
  return {};
}

/// Empty when the exact loop is a simple planar polygon; sets `frame` to its projection.
std::string why_not_simple_exact(const std::vector<ExactPoint>& loop, partition_internal::PlaneFrame& frame) {
  if (loop.size() < 3) return "fewer than 3 corners";
  const ExactPlane plane = plane_of_loop(loop);
  if (sgn(plane.a) == 0 && sgn(plane.b) == 0 && sgn(plane.c) == 0) return "zero area";
  // Every corner is on the plane when all is well, where no double filter decides: the exact test, on the
  // plane's integer form made once (not once per corner).
  const partition_internal::IntPlane on = partition_internal::int_plane(plane);
  for (std::size_t i = 0; i < loop.size(); ++i)
    if (partition_internal::side_exact(on, loop[i]) != 0) return "corner " + std::to_string(i) + " is off its plane";
  frame = partition_internal::frame_of(plane);
  std::vector<P2> q;
  q.reserve(loop.size());
  for (const ExactPoint& p : loop) q.push_back(partition_internal::to_2d(frame, p));
  return why_not_simple(q);
}

/// Per face: does one of its corners lie within `tol` of another corner of the mesh, or of an edge it is not
/// an end of (or does one of its edges pass within `tol` of another corner)? There the doubles can make
/// faces touch or cross that are apart exactly. Each edge scans the corners in its bounding box along the
/// axis where that box is thinnest.
std::vector<char> faces_near_rounding(const PolygonMesh& mesh, double tol) {
  std::vector<std::uint32_t> all(mesh.vertices.size());
  std::iota(all.begin(), all.end(), 0u);
  const NearEdgeIndex index(mesh.vertices, all);
  std::vector<std::vector<std::uint32_t>> faces_of(mesh.vertices.size());
  for (std::uint32_t f = 0; f < mesh.faces.size(); ++f)
    for (std::uint32_t v : mesh.faces[f]) faces_of[v].push_back(f);
  std::vector<char> near(mesh.faces.size(), 0);
  for (std::uint32_t f = 0; f < mesh.faces.size(); ++f) {
    const auto& loop = mesh.faces[f];
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const std::uint32_t a = loop[i], b = loop[(i + 1) % loop.size()];
      const Vec3 &pa = mesh.vertices[a], d = mesh.vertices[b] - pa;
      index.for_each_in_edge_box(a, b, tol, [&](std::uint32_t w) {
        const Vec3& pw = mesh.vertices[w];
        const double t = d.squaredNorm() > 0 ? std::clamp((pw - pa).dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
        if ((pa + t * d - pw).norm() > tol) return;
        near[f] = 1;
        for (std::uint32_t g : faces_of[w]) near[g] = 1;
      });
    }
  }
  return near;
}

}  // namespace

std::size_t prove_simple_polygons(const CellComplex& cx, const PolygonMesh& mesh,
                                  const std::vector<std::int64_t>& mesh_index,
                                  std::vector<char>* not_simple_once_rounded) {
  std::vector<std::uint32_t> complex_vertex(mesh.vertices.size(), 0);
  std::vector<char> mapped(mesh.vertices.size(), 0);
  for (std::size_t v = 0; v < mesh_index.size(); ++v)
    if (mesh_index[v] >= 0) {
      HSR_ASSERT(static_cast<std::size_t>(mesh_index[v]) < mesh.vertices.size(), "mesh index out of range");
      complex_vertex[mesh_index[v]] = static_cast<std::uint32_t>(v);
      mapped[mesh_index[v]] = 1;
    }
  // Closer than a few ulps of the largest coordinate, the doubles (each within an ulp of its rational)
  // may touch or cross where the rationals do not.
  double scale = 0;
  for (const Vec3& p : mesh.vertices) scale = std::max(scale, p.cwiseAbs().maxCoeff());
  std::vector<char> at_risk = faces_near_rounding(mesh, 16 * std::numeric_limits<double>::epsilon() * scale);
  std::vector<ExactPoint> exact, rounded;
  if (not_simple_once_rounded) not_simple_once_rounded->assign(mesh.faces.size(), 0);
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    exact.clear();
    rounded.clear();
    for (std::uint32_t v : mesh.faces[f]) {
      HSR_ASSERT(v < mesh.vertices.size() && mapped[v], "output face with a vertex that is no complex vertex");
      exact.push_back(cx.vertices[complex_vertex[v]]);
      const Vec3& p = mesh.vertices[v];
      rounded.push_back({Rational(p.x()), Rational(p.y()), Rational(p.z())});
    }
    partition_internal::PlaneFrame frame;
    const std::string why = why_not_simple_exact(exact, frame);
    if (!why.empty())
      throw Error(Status::Internal, "extraction",
                  "output polygon " + std::to_string(f) + " (" + std::to_string(exact.size()) +
                      " corners) is not simple: " + why);
    std::vector<P2> q;
    q.reserve(rounded.size());
    for (const ExactPoint& p : rounded) q.push_back(partition_internal::to_2d(frame, p));
    if (why_not_simple(q).empty()) continue;
    at_risk[f] = 1;
    if (not_simple_once_rounded) (*not_simple_once_rounded)[f] = 1;
  }
  const auto count = static_cast<std::size_t>(std::count(at_risk.begin(), at_risk.end(), 1));
  if (count > 0 && !not_simple_once_rounded)  // with the flags, the caller mends them and says what is left
    log::warn("extraction: " + std::to_string(count) +
              " output polygon(s) come closer to themselves or to another than the coordinates' precision: "
              "they may touch or cross once rounded to doubles");
  return count;
}

namespace {

/// The rounded corners of `face` (mesh vertices) in `frame`.
std::vector<P2> rounded_in(const PolygonMesh& mesh, const Loop& face, const partition_internal::PlaneFrame& frame) {
  std::vector<P2> q;
  q.reserve(face.size());
  for (std::uint32_t v : face) {
    const Vec3& p = mesh.vertices[v];
    q.push_back(partition_internal::to_2d(frame, ExactPoint{Rational(p.x()), Rational(p.y()), Rational(p.z())}));
  }
  return q;
}

/// A face of the mesh as it came from the complex: its exact plane's projection and which way it turns there.
struct FaceFrame {
  partition_internal::PlaneFrame frame;
  int turn = 0;  ///< sign of the exact corners' area in `frame`
};

FaceFrame face_frame(const CellComplex& cx, const Loop& face, const std::vector<std::uint32_t>& complex_vertex) {
  std::vector<ExactPoint> exact;
  exact.reserve(face.size());
  for (std::uint32_t v : face) exact.push_back(cx.vertices[complex_vertex[v]]);
  FaceFrame out;
  out.frame = partition_internal::frame_of(plane_of_loop(exact));
  std::vector<P2> q;
  q.reserve(exact.size());
  for (const ExactPoint& p : exact) q.push_back(partition_internal::to_2d(out.frame, p));
  out.turn = sgn(partition_internal::twice_area(q));
  return out;
}

/// `loop` cut at its repeated corners into loops that repeat none (the part between two visits of a corner is cut
/// out, again and again); the pieces of fewer than 3 corners are dropped.
std::vector<Loop> split_at_repeated_corners(const Loop& loop) {
  std::vector<Loop> out, todo{loop};
  while (!todo.empty()) {
    Loop l = std::move(todo.back());
    todo.pop_back();
    std::map<std::uint32_t, std::size_t> seen;
    bool cut = false;
    for (std::size_t i = 0; i < l.size() && !cut; ++i) {
      const auto [it, fresh] = seen.emplace(l[i], i);
      if (fresh) continue;
      const std::size_t j = it->second;
      Loop rest(l.begin() + static_cast<std::ptrdiff_t>(i), l.end());
      rest.insert(rest.end(), l.begin(), l.begin() + static_cast<std::ptrdiff_t>(j));
      todo.push_back(std::move(rest));
      todo.emplace_back(l.begin() + static_cast<std::ptrdiff_t>(j), l.begin() + static_cast<std::ptrdiff_t>(i));
      cut = true;
    }
    if (!cut && l.size() >= 3) out.push_back(std::move(l));
  }
  std::reverse(out.begin(), out.end());  // the piece holding the loop's first corner first
  return out;
}

}  // namespace

std::size_t zip_sub_precision_necks(const CellComplex& cx, PolygonMesh& mesh,
                                    const std::vector<std::int64_t>& mesh_index,
                                    const std::vector<char>& not_simple_once_rounded) {
  HSR_ASSERT(not_simple_once_rounded.size() == mesh.faces.size(), "one flag per face");
  if (std::find(not_simple_once_rounded.begin(), not_simple_once_rounded.end(), 1) == not_simple_once_rounded.end() ||
      !closed_two_sided(mesh.faces))
    return 0;
  std::vector<std::uint32_t> complex_vertex(mesh.vertices.size(), 0);
  for (std::size_t v = 0; v < mesh_index.size(); ++v)
    if (mesh_index[v] >= 0) complex_vertex[static_cast<std::size_t>(mesh_index[v])] = static_cast<std::uint32_t>(v);
  // Slot k holds what face k became (its pieces, all on its plane); frames are taken from the faces as given.
  std::vector<std::vector<Loop>> slots(mesh.faces.size());
  for (std::size_t k = 0; k < mesh.faces.size(); ++k) slots[k] = {mesh.faces[k]};
  std::map<std::size_t, FaceFrame> frames;
  const auto frame_of_slot = [&](std::size_t k) -> const FaceFrame& {
    auto it = frames.find(k);
    if (it == frames.end()) it = frames.emplace(k, face_frame(cx, mesh.faces[k], complex_vertex)).first;
    return it->second;
  };
  const auto within_precision = [](const Vec3& a, const Vec3& b, double tol) {
    return (a - b).cwiseAbs().maxCoeff() <= tol;
  };
  std::size_t inserted = 0;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    if (!not_simple_once_rounded[f] || slots[f].size() != 1) continue;
    const Loop& face = slots[f][0];
    const std::size_t n = face.size();
    // Per edge i (face[i] -> face[i + 1]): the corners on it once rounded, by their place along it. Doubles choose
    // the candidates only; whether the zip is kept is decided exactly below (closed, simple, same turn).
    std::map<std::size_t, std::vector<std::pair<double, std::uint32_t>>> on_edge;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t a = face[i], b = face[(i + 1) % n];
      const Vec3 &pa = mesh.vertices[a], &pb = mesh.vertices[b], d = pb - pa;
      if (!(d.squaredNorm() > 0)) continue;
      for (const std::uint32_t c : face) {
        if (c == a || c == b) continue;
        const Vec3& pc = mesh.vertices[c];
        const double largest =
            std::max({1.0, pa.cwiseAbs().maxCoeff(), pb.cwiseAbs().maxCoeff(), pc.cwiseAbs().maxCoeff()});
        const double tol = kSubPrecisionUlps * std::numeric_limits<double>::epsilon() * largest;
        const double t = (pc - pa).dot(d) / d.squaredNorm();
        if (!(t > 0 && t < 1) || !within_precision(pa + t * d, pc, tol) || within_precision(pa, pc, tol) ||
            within_precision(pb, pc, tol))
          continue;
        on_edge[i].emplace_back(t, c);
      }
    }
    if (on_edge.empty()) continue;
    std::map<DirectedEdge, std::size_t> owner;  // directed edge -> slot
    for (std::size_t k = 0; k < slots.size(); ++k)
      for (const Loop& l : slots[k])
        for (std::size_t i = 0; i < l.size(); ++i) owner[{l[i], l[(i + 1) % l.size()]}] = k;
    std::map<std::size_t, Loop> changed;  // twin slot -> its loop with the corners inserted
    Loop zipped;
    bool ok = true;
    for (std::size_t i = 0; i < n && ok; ++i) {
      zipped.push_back(face[i]);
      const auto it = on_edge.find(i);
      if (it == on_edge.end()) continue;
      auto corners = it->second;
      std::sort(corners.begin(), corners.end());
      for (const auto& tc : corners) zipped.push_back(tc.second);
      const std::uint32_t a = face[i], b = face[(i + 1) % n];
      const auto tw = owner.find({b, a});
      if (tw == owner.end() || tw->second == f || slots[tw->second].size() != 1) {
        ok = false;
        break;
      }
      Loop& g = changed.emplace(tw->second, slots[tw->second][0]).first->second;
      const std::size_t m = g.size();
      std::size_t at = 0;
      while (at < m && !(g[at] == b && g[(at + 1) % m] == a)) ++at;
      if (at == m) {
        ok = false;
        break;
      }
      std::size_t put = at + 1;  // g: ... b, the corners from the last to the first, a ...
      for (auto r = corners.rbegin(); r != corners.rend(); ++r)
        g.insert(g.begin() + static_cast<std::ptrdiff_t>(put++), r->second);
    }
    if (!ok) continue;
    std::vector<Loop> pieces = split_at_repeated_corners(zipped);
    if (pieces.empty()) continue;
    const FaceFrame& own = frame_of_slot(f);
    for (const Loop& l : pieces) {
      const std::vector<P2> q = rounded_in(mesh, l, own.frame);
      ok = ok && why_not_simple(q).empty() && sgn(partition_internal::twice_area(q)) == own.turn;
    }
    for (const auto& [k, g] : changed) {
      const FaceFrame& theirs = frame_of_slot(k);
      const std::vector<P2> q = rounded_in(mesh, g, theirs.frame);
      ok = ok && why_not_simple(q).empty() && sgn(partition_internal::twice_area(q)) == theirs.turn;
    }
    if (!ok) continue;
    std::vector<std::vector<Loop>> trial = slots;
    trial[f] = pieces;
    for (const auto& [k, g] : changed) trial[k] = {g};
    std::vector<Loop> flat;
    for (const auto& s : trial) flat.insert(flat.end(), s.begin(), s.end());
    if (!closed_two_sided(flat)) continue;
    slots = std::move(trial);
    for (const auto& [i, corners] : on_edge) inserted += corners.size();
  }
  if (inserted == 0) return 0;
  std::vector<Loop> faces;
  std::vector<FaceClass> classes;
  for (std::size_t k = 0; k < slots.size(); ++k)
    for (Loop& l : slots[k]) {
      faces.push_back(std::move(l));
      if (!mesh.face_class.empty()) classes.push_back(mesh.face_class[k]);
    }
  mesh.faces = std::move(faces);
  if (!mesh.face_class.empty()) mesh.face_class = std::move(classes);
  return inserted;
}

}  // namespace hsr
