// office_pieces MESH DIR [--within M] [--share S] [--samples FILE]: which pieces of a `hsr synth office` truth (DIR/truth.obj,
// DIR/planes.json) a model MESH has (issue 41 item 2). Prints one JSON object.
//
// A piece's truth surface is the truth faces lying in its own frame's box (partitions: in the partition's
// box), off the room's floor, ceilings and outer walls, and only on planes the scan has points on (a face no
// station sees, such as a tabletop's underside, cannot be asked of a reconstruction). It is sampled on a
// 2 cm pitch (a seeded uniform draw, area-weighted); the piece is present when at least `share` of its
// samples lie within `within` of the model. The count asks for the surface where it is, not for a box
// around it: a table closed into a block down to the floor still has its top, but a lost top is absent.
//
// "truth_to_mesh_m2" says where truth -> mesh comes from: the whole truth surface sampled as above, each
// sample's distance to the model times its area (the pitch squared), summed per kind of what holds it in plan
// (a piece's frame from the floor up to its top, so the floor under a table counts to the table; else
// "partition", else "room": floor, walls and ceiling away from every piece). Divided by the truth's area and
// the diagonal it is `hsr eval`'s truth -> mesh mean (up to the sampling).
//
// `--samples FILE` writes each sample of that whole truth surface as a line "block x y z nx ny nz distance" (block:
// the index it counts to, as truth_to_mesh_m2_per_block, -1: none, the room; n: the truth face's normal),
// so where a piece's m² lies can be told apart (a shelf's boards from its sides, a chair's seat from its post).
//
// "doorways" says which doorways are open (issue 41 item 5: the free space connected through each): the model of
// a room is its air, so a doorway is open when the model's winding number is 1 (air) at its centre in plan (the
// partition's middle) at each of kDoorwayHeights; "summary" counts them as kind "doorway".
#include "core/face_class.h"
#include "eval/eval.h"
#include "io/io.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <map>
#include <random>
#include <string>

namespace {

using hsr::Vec3;

constexpr double kSamplePitch = 0.02;  ///< metres between samples on a piece's surface (area per sample: its square)
/// Heights above the floor (metres) at which a doorway's centre must be air for it to be open: a chair seat's
/// height, a table's, a person's shoulders (all under the 2.1 m lintel).
constexpr double kDoorwayHeights[] = {0.3, 1.0, 1.8};

/// The generalised winding number of `p` about a closed mesh (1 inside, 0 outside): Van Oosterom and Strackee's
/// solid angle summed over each face's fan triangles.
double winding_number(const hsr::PolygonMesh& m, const Vec3& p) {
  double total = 0;
  for (const auto& f : m.faces)
    for (std::size_t i = 1; i + 1 < f.size(); ++i) {
      const Vec3 a = m.vertices[f[0]] - p, b = m.vertices[f[i]] - p, c = m.vertices[f[i + 1]] - p;
      const double la = a.norm(), lb = b.norm(), lc = c.norm();
      total += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
    }
  return total / (4 * M_PI);
}

struct Block {
  std::string kind;
  Vec3 own_min, own_max, origin;
  double angle = 0;
  bool holds(const Vec3& p, double tol) const {
    const double c = std::cos(angle), s = std::sin(angle);
    const Vec3 d = p - origin, q(c * d.x() + s * d.y(), -s * d.x() + c * d.y(), d.z());
    return (q.array() >= own_min.array() - tol).all() && (q.array() <= own_max.array() + tol).all();
  }
};

Vec3 vec(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

}  // namespace

int main(int argc, char** argv) {
  if (argc < 3) {
    std::cerr << "usage: office_pieces MESH DIR [--within M (0.05)] [--share S (0.8)] [--samples FILE]\n";
    return 2;
  }
  double within = 0.05, share = 0.8;
  std::string samples_path;  // --samples FILE: each truth sample "block x y z nx ny nz distance" (block -1: none)
  for (int i = 3; i + 1 < argc; i += 2) {
    const std::string a = argv[i];
    if (a == "--within") within = std::atof(argv[i + 1]);
    else if (a == "--share") share = std::atof(argv[i + 1]);
    else if (a == "--samples") samples_path = argv[i + 1];
  }
  try {
    const hsr::PolygonMesh mesh = hsr::read_mesh(argv[1]);
    const std::string dir = argv[2];
    const hsr::PolygonMesh truth = hsr::read_mesh(dir + "/truth.obj");
    std::ifstream in(dir + "/planes.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    std::vector<Block> blocks;
    std::vector<std::pair<Vec3, Vec3>> doorways;  // world boxes
    for (const auto& b : j["blocks"]) {
      Block k;
      k.kind = b["kind"].get<std::string>();
      if (k.kind == "doorway") {
        doorways.emplace_back(vec(b["min"]), vec(b["max"]));
        continue;
      }
      k.angle = b["angle"].get<double>();
      k.own_min = vec(b.contains("own_min") ? b["own_min"] : b["min"]);
      k.own_max = vec(b.contains("own_max") ? b["own_max"] : b["max"]);
      k.origin = b.contains("origin") ? vec(b["origin"]) : Vec3::Zero();
      blocks.push_back(k);
    }
    const hsr::CoplanarGroups groups = hsr::coplanar_groups(truth);
    std::vector<bool> seen(j["planes"].size());
    for (std::size_t p = 0; p < seen.size(); ++p) seen[p] = j["planes"][p]["points"].get<std::size_t>() > 0;
    const hsr::BBox box = hsr::bounding_box(truth.vertices);
    std::vector<std::vector<Vec3>> samples(blocks.size());
    std::mt19937_64 rng(1);
    auto u01 = [&] { return static_cast<double>(rng() >> 11) * 0x1.0p-53; };
    std::vector<Vec3> all_samples;  // the whole truth surface, for the breakdown
    std::vector<Vec3> all_normals;  // each sample's face normal (--samples)
    std::mt19937_64 rng_all(2);
    for (const auto& loop : truth.faces) {
      const Vec3& a = truth.vertices[loop[0]];
      for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
        const Vec3 &p = truth.vertices[loop[i]], &q = truth.vertices[loop[i + 1]];
        const double n = 0.5 * (p - a).cross(q - a).norm() / (kSamplePitch * kSamplePitch);
        const auto draws = static_cast<std::size_t>(std::floor(n + static_cast<double>(rng_all() >> 11) * 0x1.0p-53));
        for (std::size_t d = 0; d < draws; ++d) {
          double s = static_cast<double>(rng_all() >> 11) * 0x1.0p-53, t = static_cast<double>(rng_all() >> 11) * 0x1.0p-53;
          if (s + t > 1) s = 1 - s, t = 1 - t;
          all_samples.push_back(a + s * (p - a) + t * (q - a));
          all_normals.push_back((p - a).cross(q - a).normalized());
        }
      }
    }
    for (std::size_t f = 0; f < truth.faces.size(); ++f) {
      const auto& loop = truth.faces[f];
      auto all = [&](auto&& pred) {
        for (auto v : loop)
          if (!pred(truth.vertices[v])) return false;
        return true;
      };
      bool room = false;
      for (int a = 0; a < 3; ++a)
        room = room || all([&](const Vec3& p) { return p[a] == box.min[a]; }) || all([&](const Vec3& p) { return p[a] == box.max[a]; });
      if (room || !seen[static_cast<std::size_t>(groups.face_group[f])]) continue;
      for (std::size_t b = 0; b < blocks.size(); ++b) {
        if (!all([&](const Vec3& p) { return blocks[b].holds(p, 1e-6); })) continue;
        const Vec3& a = truth.vertices[loop[0]];
        for (std::size_t i = 1; i + 1 < loop.size(); ++i) {
          const Vec3 &p = truth.vertices[loop[i]], &q = truth.vertices[loop[i + 1]];
          const double n = 0.5 * (p - a).cross(q - a).norm() / (kSamplePitch * kSamplePitch);
          const auto draws = static_cast<std::size_t>(std::floor(n + u01()));
          for (std::size_t d = 0; d < draws; ++d) {
            double s = u01(), t = u01();
            if (s + t > 1) s = 1 - s, t = 1 - t;
            samples[b].push_back(a + s * (p - a) + t * (q - a));
          }
        }
        break;
      }
    }
    nlohmann::json out;
    out["within_m"] = within;
    out["share"] = share;
    std::map<std::string, std::pair<int, int>> summary;  // kind -> present, total (pieces with seen surface)
    std::map<std::string, int> unseen;
    out["pieces"] = nlohmann::json::array();
    for (std::size_t b = 0; b < blocks.size(); ++b) {
      if (samples[b].empty()) {
        ++unseen[blocks[b].kind];
        continue;
      }
      const std::vector<double> d = hsr::point_mesh_distances(samples[b], mesh);
      std::size_t near = 0;
      for (double x : d) near += x <= within;
      const double got = static_cast<double>(near) / static_cast<double>(d.size());
      const bool present = got >= share;
      auto& s = summary[blocks[b].kind];
      s.first += present, s.second += 1;
      // By height in the piece's own frame (10 cm bands from its bottom): samples and those within, so a piece's
      // loss can be told apart (a table's legs from its top, a chair's post from its seat and back).
      nlohmann::json bands = nlohmann::json::array();
      for (std::size_t i = 0; i < d.size(); ++i) {
        const auto k = static_cast<std::size_t>(std::max(0.0, (samples[b][i].z() - blocks[b].own_min.z()) / 0.1));
        while (bands.size() <= k) bands.push_back({0, 0});
        bands[k][0] = bands[k][0].get<int>() + 1;
        bands[k][1] = bands[k][1].get<int>() + (d[i] <= within);
      }
      // "block": its index among planes.json's blocks but doorways (as truth_to_mesh_m2_per_block).
      out["pieces"].push_back({{"kind", blocks[b].kind}, {"block", b}, {"samples", d.size()}, {"share_within", got}, {"present", present}, {"bands", bands}});
    }
    {
      const std::vector<double> d = hsr::point_mesh_distances(all_samples, mesh);
      std::map<std::string, double> cost;
      std::vector<double> block_cost(blocks.size(), 0.0);
      for (std::size_t i = 0; i < all_samples.size(); ++i) {
        std::string kind = "room";
        for (std::size_t b = 0; b < blocks.size(); ++b) {
          Vec3 q = all_samples[i];
          if (blocks[b].kind != "partition") q.z() = std::max(q.z(), blocks[b].own_min.z());  // from the floor up
          if (blocks[b].holds(q, 1e-6)) {
            kind = blocks[b].kind;
            block_cost[b] += d[i] * kSamplePitch * kSamplePitch;
            break;
          }
        }
        cost[kind] += d[i] * kSamplePitch * kSamplePitch;
      }
      if (!samples_path.empty()) {  // per sample, the block it counts to (as truth_to_mesh_m2_per_block)
        std::ofstream out_s(samples_path);
        for (std::size_t i = 0; i < all_samples.size(); ++i) {
          int holder = -1;
          for (std::size_t b = 0; b < blocks.size() && holder < 0; ++b) {
            Vec3 q = all_samples[i];
            if (blocks[b].kind != "partition") q.z() = std::max(q.z(), blocks[b].own_min.z());
            if (blocks[b].holds(q, 1e-6)) holder = static_cast<int>(b);
          }
          const Vec3& p = all_samples[i];
          const Vec3& n = all_normals[i];
          out_s << holder << ' ' << p.x() << ' ' << p.y() << ' ' << p.z() << ' ' << n.x() << ' ' << n.y() << ' ' << n.z()
                << ' ' << d[i] << '\n';
        }
      }
      for (const auto& [k, c] : cost) out["truth_to_mesh_m2"][k] = c;
      out["truth_to_mesh_m2_per_block"] = nlohmann::json::array();  // planes.json's blocks but doorways, in order
      for (std::size_t b = 0; b < blocks.size(); ++b) out["truth_to_mesh_m2_per_block"].push_back({{"kind", blocks[b].kind}, {"m2", block_cost[b]}});
    }
    out["doorways"] = nlohmann::json::array();
    for (const auto& [lo, hi] : doorways) {
      bool open = true;
      nlohmann::json w = nlohmann::json::array();
      for (double z : kDoorwayHeights) {
        const double n = winding_number(mesh, Vec3(0.5 * (lo.x() + hi.x()), 0.5 * (lo.y() + hi.y()), lo.z() + z));
        w.push_back(n);
        open = open && std::abs(n - 1.0) < 0.5;
      }
      out["doorways"].push_back({{"open", open}, {"winding", w}});
      auto& s = summary["doorway"];
      s.first += open, s.second += 1;
    }
    for (const auto& [k, s] : summary) out["summary"][k] = {{"present", s.first}, {"total", s.second}, {"unseen", unseen[k]}};
    std::cout << out.dump() << "\n";
  } catch (const std::exception& e) {
    std::cerr << "office_pieces: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
