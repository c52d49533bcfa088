// Masking protocol of the supplement §2.2 for missing-plane recovery (DESIGN.md §3, issue 5):
// for each synth model and each of its scanned planes in turn, remove that plane's points, run structure +
// recovery, and match the recovered planes to the removed one (angle and offset within tolerance, one to
// one). Reports precision, recall and F1 over all trials, and over the trials whose plane is bounded by the
// edges of at least two other scanned planes (the ones recovery can see: a recovered plane needs two
// singular segments from two planes). Also runs every model unmasked and counts false positives.
//
// Trials: the truth planes that structure detects on the unmasked scan (a plane that is not detected with
// its points cannot be missed more without them); "bounded" trials: planes sharing truth edges with at
// least two other planes detected on the unmasked scan.
// A recovered plane is a true positive when it matches the masked plane (the first one only: one to one);
// it is neutral ("undetected") when it matches another truth plane that the run's structure did not detect
// (the unscanned bottoms of outdoor models, or faces too sparse to be detected: genuinely missing planes);
// otherwise it is a false positive (no truth plane, or a duplicate of a detected one).
//
// Usage: bench_recovery [--verbose] [--visibility] [--angle DEG] [--offset R] [model...]
// --visibility: per model, the visibility labels instead (highly visible count, outward normals vs truth);
// with --literal, the paper's whole-sphere ratio and unnormalised smoothness (DESIGN.md literal).
#include "core/error.h"
#include "core/log.h"
#include "recovery/recovery.h"
#include "visibility/visibility.h"
#include "structure/structure.h"
#include "synth/synth.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <map>
#include <set>
#include <string>
#include <vector>

using namespace hsr;

namespace {

struct Tally {
  int trials = 0, tp = 0, fp = 0, unscanned = 0;
  void add(const Tally& o) { trials += o.trials; tp += o.tp; fp += o.fp; unscanned += o.unscanned; }
  double precision() const { return tp + fp > 0 ? double(tp) / (tp + fp) : 1.0; }
  double recall() const { return trials > 0 ? double(tp) / trials : 0.0; }
  double f1() const { const double p = precision(), r = recall(); return p + r > 0 ? 2 * p * r / (p + r) : 0.0; }
};

/// Area centroid of the truth faces of each plane (fan triangulation: faces are convex).
std::vector<Vec3> plane_centroids(const SynthScan& scan) {
  std::vector<Vec3> sum(scan.planes.size(), Vec3::Zero());
  std::vector<double> area(scan.planes.size(), 0.0);
  for (std::size_t f = 0; f < scan.truth.faces.size(); ++f) {
    const auto& loop = scan.truth.faces[f];
    const int p = scan.face_plane[f];
    for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
      const Vec3& a = scan.truth.vertices[loop[0]];
      const Vec3& b = scan.truth.vertices[loop[i]];
      const Vec3& c = scan.truth.vertices[loop[i + 1]];
      const double t = 0.5 * (b - a).cross(c - a).norm();
      sum[p] += t * (a + b + c) / 3.0;
      area[p] += t;
    }
  }
  for (std::size_t p = 0; p < sum.size(); ++p) if (area[p] > 0) sum[p] /= area[p];
  return sum;
}

/// Other planes sharing a truth edge with plane p.
std::vector<std::vector<int>> bounding_planes(const SynthScan& scan) {
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::set<int>> edge_planes;
  for (std::size_t f = 0; f < scan.truth.faces.size(); ++f) {
    const auto& loop = scan.truth.faces[f];
    for (std::size_t i = 0; i < loop.size(); ++i) {
      std::uint32_t a = loop[i], b = loop[(i + 1) % loop.size()];
      if (a > b) std::swap(a, b);
      edge_planes[{a, b}].insert(scan.face_plane[f]);
    }
  }
  std::vector<std::set<int>> nb(scan.planes.size());
  for (const auto& [e, planes] : edge_planes)
    for (int p : planes)
      for (int q : planes)
        if (p != q) nb[p].insert(q);
  std::vector<std::vector<int>> out;
  for (const auto& s : nb) out.emplace_back(s.begin(), s.end());
  return out;
}

/// Truth planes detected by a structure run: the majority truth label of each detected plane's inliers.
/// `truth_of_point[i]` is the truth plane of the run's point i.
std::vector<bool> detected_truth(const SceneStructure& s, const std::vector<int>& truth_of_point, std::size_t n_truth) {
  std::vector<bool> detected(n_truth, false);
  for (const DetectedPlane& dp : s.planes) {
    std::map<int, int> votes;
    for (int i : dp.inliers) ++votes[truth_of_point[static_cast<std::size_t>(i)]];
    int best = -1, best_n = 0;
    for (auto [t, n] : votes) if (n > best_n) { best = t; best_n = n; }
    if (best >= 0) detected[static_cast<std::size_t>(best)] = true;
  }
  return detected;
}

bool matches(const Plane& rec, const Plane& truth, const Vec3& truth_centroid, double cos_tol, double off_tol) {
  return std::abs(rec.normal.dot(truth.normal)) >= cos_tol && std::abs(rec.signed_distance(truth_centroid)) <= off_tol;
}

}  // namespace

int main(int argc, char** argv) {
  bool verbose = false, visibility_only = false, literal = false;
  double angle_tol = 5.0, offset_tol = 3.0;  // degrees, r
  std::vector<std::string> models;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--verbose")) verbose = true;
    else if (!std::strcmp(argv[i], "--visibility")) visibility_only = true;
    else if (!std::strcmp(argv[i], "--literal")) literal = true;
    else if (!std::strcmp(argv[i], "--angle") && i + 1 < argc) angle_tol = std::atof(argv[++i]);
    else if (!std::strcmp(argv[i], "--offset") && i + 1 < argc) offset_tol = std::atof(argv[++i]);
    else models.push_back(argv[i]);
  }
  if (models.empty()) models = synth_model_names();
  log::set_level(log::Level::Quiet);
  const double cos_tol = std::cos(angle_tol * M_PI / 180.0);

  Tally all, bounded;
  std::printf("masking protocol: angle <= %.1f deg, offset <= %.1f r\n", angle_tol, offset_tol);
  std::printf("%-13s %7s %6s %4s %4s %5s | %7s %4s %4s %5s | %s\n", "model", "scanned", "trials", "TP", "FP",
              "undet", "bounded", "TP", "FP", "undet", "unmasked: recovered / undetected-true / FP");
  for (const std::string& model : models) {
    const SynthScan scan = run_synth(model, {});
    const std::vector<Vec3> centroids = plane_centroids(scan);
    StructureParams sp;
    sp.scanners = scan.scanners;
    if (visibility_only) {
      const SceneStructure s = run_structure(scan.cloud, sp);
      VisibilityParams vp;
      vp.one_sided = vp.normalize_smoothness = !literal;
      const VisibilityResult vis = run_visibility(scan.cloud, s, vp);
      int high = 0, agree = 0;
      std::printf("%-13s %zu planes, %d passes:", model.c_str(), s.planes.size(), vis.iterations);
      for (std::size_t k = 0; k < s.planes.size(); ++k) {
        std::map<int, int> votes;
        for (int i : s.planes[k].inliers) ++votes[scan.point_plane[static_cast<std::size_t>(i)]];
        int t = -1, best = 0;
        for (auto [q, n] : votes) if (n > best) { best = n; t = q; }
        high += vis.highly[k];
        agree += vis.outward_normal[k].dot(scan.planes[static_cast<std::size_t>(t)].plane.normal) > 0.9;
        std::printf(" %s%.2f", vis.highly[k] ? "H" : "b", vis.ratio[k]);
      }
      std::printf("\n  highly visible %d / %zu, outward normal agrees with truth %d / %zu\n", high, s.planes.size(),
                  agree, s.planes.size());
      continue;
    }

    // Classifies the recovered planes of one run: which truth plane each matches (or none).
    auto classify = [&](const std::vector<RecoveredPlane>& rec, int masked, double r, const std::vector<bool>& detected,
                        Tally& t, bool print) {
      bool found = false;
      for (const RecoveredPlane& rp : rec) {
        int hit = -1;
        if (masked >= 0 && matches(rp.plane, scan.planes[masked].plane, centroids[masked], cos_tol, offset_tol * r))
          hit = masked;
        else
          for (std::size_t q = 0; q < scan.planes.size(); ++q)
            if (!detected[q] && static_cast<int>(q) != masked &&
                matches(rp.plane, scan.planes[q].plane, centroids[q], cos_tol, offset_tol * r)) { hit = int(q); break; }
        if (hit == masked && masked >= 0 && !found) { found = true; ++t.tp; }
        else if (hit >= 0 && hit != masked) ++t.unscanned;
        else ++t.fp;  // no match, or a second match of the masked plane (not one-to-one)
        if (print)
          std::printf("    recovered n=(%.3f %.3f %.3f) d=%.3f from %zu segments -> %s\n", rp.plane.normal.x(),
                      rp.plane.normal.y(), rp.plane.normal.z(), rp.plane.offset, rp.segments.size(),
                      hit == masked && masked >= 0 ? "masked plane" : hit >= 0 ? "undetected truth plane" : "FALSE");
      }
      return found;
    };

    // Unmasked run.
    Tally unmasked;
    int n_rec = 0;
    std::vector<bool> detected0(scan.planes.size(), false);
    try {
      const SceneStructure s = run_structure(scan.cloud, sp);
      const RecoveryResult rr = run_recovery(scan.cloud, s, {});
      n_rec = static_cast<int>(rr.recovered.size());
      detected0 = detected_truth(s, scan.point_plane, scan.planes.size());
      if (verbose) std::printf("  %s unmasked: %zu planes, %zu singular segments\n", model.c_str(), s.planes.size(), rr.num_singular());
      classify(rr.recovered, -1, s.spacing, detected0, unmasked, verbose);
    } catch (const Error& e) {
      std::printf("  %s unmasked: %s\n", model.c_str(), e.one_line().c_str());
    }
    // Bounding planes that are detected on the unmasked scan.
    std::vector<int> bounds(scan.planes.size(), 0);
    {
      const std::vector<std::vector<int>> nb = bounding_planes(scan);
      for (std::size_t p = 0; p < nb.size(); ++p)
        for (int q : nb[p]) bounds[p] += detected0[static_cast<std::size_t>(q)];
    }

    Tally mt, bt;
    int scanned = 0;
    for (std::size_t p = 0; p < scan.planes.size(); ++p) {
      if (scan.planes[p].points == 0) continue;
      ++scanned;
      if (!detected0[p]) continue;
      PointCloud cloud;
      cloud.origin = scan.cloud.origin;
      std::vector<int> truth_of_point;
      for (std::size_t i = 0; i < scan.cloud.size(); ++i)
        if (scan.point_plane[i] != static_cast<int>(p)) {
          truth_of_point.push_back(scan.point_plane[i]);
          cloud.points.push_back(scan.cloud.points[i]);
          if (scan.cloud.has_normals()) cloud.normals.push_back(scan.cloud.normals[i]);
        }
      Tally t;
      t.trials = 1;
      bool found = false;
      try {
        const SceneStructure s = run_structure(cloud, sp);
        const RecoveryResult rr = run_recovery(cloud, s, {});
        if (verbose)
          std::printf("  %s mask plane %zu (n=(%.2f %.2f %.2f), %zu points, bounded by %d): %zu recovered\n",
                      model.c_str(), p, scan.planes[p].plane.normal.x(), scan.planes[p].plane.normal.y(),
                      scan.planes[p].plane.normal.z(), scan.planes[p].points, bounds[p], rr.recovered.size());
        found = classify(rr.recovered, static_cast<int>(p), s.spacing,
                         detected_truth(s, truth_of_point, scan.planes.size()), t, verbose);
      } catch (const Error& e) {
        if (verbose) std::printf("  %s mask plane %zu: %s\n", model.c_str(), p, e.one_line().c_str());
      }
      (void)found;
      mt.add(t);
      if (bounds[p] >= 2) bt.add(t);
    }
    all.add(mt);
    bounded.add(bt);
    std::printf("%-13s %7d %6d %4d %4d %5d | %7d %4d %4d %5d | %d / %d / %d\n", model.c_str(), scanned, mt.trials,
                mt.tp, mt.fp, mt.unscanned, bt.trials, bt.tp, bt.fp, bt.unscanned, n_rec, unmasked.unscanned,
                unmasked.fp);
    std::fflush(stdout);
  }
  if (visibility_only) return 0;
  std::printf("all trials:     %d, precision %.3f, recall %.3f, F1 %.3f\n", all.trials, all.precision(), all.recall(), all.f1());
  std::printf("bounded (>= 2): %d, precision %.3f, recall %.3f, F1 %.3f\n", bounded.trials, bounded.precision(),
              bounded.recall(), bounded.f1());
  return 0;
}
