// Stage 6's label clean-up, how it counts output faces (label_cleanup.h): the way extraction's merge makes them,
// per support plane the surface facets of one orientation that share edges form one region; a region is one
// face, plus one per hole (a region with a hole is split into disks: DECISIONS #8). Each plane's facets with
// T-junction vertices inserted, their shared edges, and the regions under a labelling.
#include "extraction/label_cleanup_internal.h"

#include "extraction/surface.h"

#include <map>

namespace hsr::label_cleanup_internal {

double loop_area(const CellComplex& cx, const std::vector<std::uint32_t>& loop) {
  Vec3 n = Vec3::Zero();
  for (std::size_t i = 0; i < loop.size(); ++i)
    n += cx.vertices_approx[loop[i]].cross(cx.vertices_approx[loop[(i + 1) % loop.size()]]);
  return 0.5 * n.norm();
}

std::vector<PlaneFacets> plane_facets(const CellComplex& cx) {
  std::vector<PlaneFacets> out(cx.planes.size());
  for (std::size_t f = 0; f < cx.facets.size(); ++f) out[cx.facets[f].plane].facets.push_back(static_cast<int>(f));
  for (PlaneFacets& p : out) {
    std::vector<std::vector<std::uint32_t>> loops;
    for (int f : p.facets) loops.push_back(cx.facets[f].vertices);
    insert_t_junctions(cx, loops);  // a complex built without flat vertices meets in T-junctions
    std::map<std::uint32_t, int> vertex_id;
    std::map<Edge, std::vector<int>> by_edge;
    p.edges.resize(loops.size());
    p.vertices.resize(loops.size());
    for (std::size_t k = 0; k < loops.size(); ++k) {
      const auto& l = loops[k];
      for (std::size_t i = 0; i < l.size(); ++i) {
        const auto [it, added] = vertex_id.emplace(l[i], p.vertex_count);
        p.vertex_count += added;
        p.vertices[k].push_back(it->second);
        by_edge[{std::min(l[i], l[(i + 1) % l.size()]), std::max(l[i], l[(i + 1) % l.size()])}].push_back(
            static_cast<int>(k));
      }
    }
    p.neighbours.resize(loops.size());
    p.edge_facets.reserve(by_edge.size());
    for (const auto& [e, ks] : by_edge) {
      for (int k : ks) p.edges[k].push_back(p.edge_count);
      p.edge_facets.push_back(ks);
      ++p.edge_count;
      for (int a : ks)
        for (int b : ks)
          if (a != b) p.neighbours[a].push_back(b);
    }
    for (auto& nb : p.neighbours) {
      std::sort(nb.begin(), nb.end());
      nb.erase(std::unique(nb.begin(), nb.end()), nb.end());
    }
    for (auto& ef : p.edge_facets) ef.erase(std::unique(ef.begin(), ef.end()), ef.end());
    p.vertex_facets.resize(static_cast<std::size_t>(p.vertex_count));
    for (std::size_t k = 0; k < p.vertices.size(); ++k)
      for (int v : p.vertices[k])
        if (p.vertex_facets[v].empty() || p.vertex_facets[v].back() != static_cast<int>(k)) p.vertex_facets[v].push_back(static_cast<int>(k));
  }
  return out;
}

std::vector<Region> regions_of(const CellComplex& cx, const PlaneFacets& p, int plane, const std::vector<bool>& inside,
                               const std::vector<int>& seeds, Stamps& stamps) {
  std::vector<Region> out;
  for_each_region(cx, p, inside, seeds, stamps, nullptr, [&](const std::vector<int>& members, int faces, long, long) {
    Region r;
    r.plane = plane;
    r.faces = faces;
    for (int k : members) r.facets.push_back(p.facets[k]);
    out.push_back(std::move(r));
  });
  return out;
}

}  // namespace hsr::label_cleanup_internal
