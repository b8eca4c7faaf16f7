// Triangle-mesh walls on the host: topology and checks (coredem/dem/triangle_mesh.h).
#include <algorithm>
#include <bit>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <numbers>
#include <sstream>
#include <string_view>
#include <system_error>
#include <unordered_map>
#include <utility>

#include "coredem/dem/triangle_mesh.h"
#include "mesh_common.h"

namespace coredem::dem {
namespace {

using namespace mesh_detail;

// ---- checks -------------------------------------------------------------------------------

void checkUnits(const TriangleMesh& mesh, const std::array<double, 6>& domain) {
  const double domainDiagonal = boxDiagonal(domain);
  if (!(domainDiagonal > 0.0)) {
    return; // no extent to compare with
  }
  const std::array<double, 6> box = boundingBox(mesh);
  const double diagonal = boxDiagonal(box);
  if (diagonal > kUnitsRatio * domainDiagonal) {
    fail(label(mesh), "the STL is probably in millimetres: its bounding box " + boxText(box) +
                          " has a diagonal of " + number(diagonal) + " m, more than " +
                          number(kUnitsRatio) + " times the domain's " + boxText(domain) +
                          " (diagonal " + number(domainDiagonal) +
                          " m); set `scale: 0.001` for this wall (or check the domain)");
  }
}

void checkDegenerate(const TriangleMesh& mesh) {
  const double weld = kWeldTolerance * boxDiagonal(boundingBox(mesh));
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    const std::int32_t a = corner(mesh, t, 0), b = corner(mesh, t, 1), c = corner(mesh, t, 2);
    if (a == b || b == c || a == c) {
      fail(label(mesh), "degenerate " + triangleText(mesh, t) +
                            ": two of its vertices are the same point after welding (vertices "
                            "closer than " +
                            number(weld) +
                            " m are merged); remove the triangle or repair the mesh (remove "
                            "zero-area faces) and export it again");
    }
    const Vec3 pa = vertexAt(mesh, a), pb = vertexAt(mesh, b), pc = vertexAt(mesh, c);
    const double area = 0.5 * norm(cross(sub(pb, pa), sub(pc, pa)));
    const double longest = std::max({norm(sub(pb, pa)), norm(sub(pc, pb)), norm(sub(pa, pc))});
    if (area <= kDegenerateArea * longest * longest) {
      fail(label(mesh), "degenerate " + triangleText(mesh, t) + ": its area " + number(area) +
                            " m² is zero for its size (vertices on one line); remove the "
                            "triangle or repair the mesh (remove zero-area faces) and export it "
                            "again");
    }
  }
}

/// The two triangles of an edge and whether each traverses it from its lower vertex index up.
struct EdgeSides {
  std::size_t triangle[2] = {0, 0};
  bool upward[2] = {false, false};
};

std::string edgeText(const TriangleMesh& mesh, const MeshTopology& topology, std::int32_t e) {
  const auto i = 2 * static_cast<std::size_t>(e);
  return pointText(vertexAt(mesh, topology.edgeVertices[i])) + "–" +
         pointText(vertexAt(mesh, topology.edgeVertices[i + 1])) + " m";
}

void checkManifold(const TriangleMesh& mesh, const MeshTopology& topology) {
  if (std::all_of(topology.edgeUse.begin(), topology.edgeUse.end(),
                  [](std::int32_t use) { return use <= 2; })) {
    return;
  }
  // The first triangle, in file order, that is the third on one of its edges.
  const auto edges = static_cast<std::size_t>(topology.edgeCount);
  std::vector<std::size_t> firstTwo(2 * edges, 0);
  std::vector<int> seen(edges, 0);
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (std::size_t k = 0; k < 3; ++k) {
      const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
      const int s = seen[e]++;
      if (s < 2) {
        firstTwo[2 * e + static_cast<std::size_t>(s)] = t;
        continue;
      }
      fail(label(mesh),
           "non-manifold edge " + edgeText(mesh, topology, static_cast<std::int32_t>(e)) +
               " shared by " + std::to_string(topology.edgeUse[e]) +
               " triangles: " + triangleText(mesh, t) + " is the third on it, after triangles " +
               std::to_string(firstTwo[2 * e] + 1) + " and " +
               std::to_string(firstTwo[2 * e + 1] + 1) +
               "; a wall edge may join at most two triangles: split the surface into "
               "separate walls or repair the mesh");
    }
  }
}

void checkWinding(const TriangleMesh& mesh, const MeshTopology& topology) {
  const auto edges = static_cast<std::size_t>(topology.edgeCount);
  std::vector<EdgeSides> sides(edges);
  std::vector<int> filled(edges, 0);
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const auto e =
          static_cast<std::size_t>(topology.triangleEdges[3 * t + static_cast<std::size_t>(k)]);
      const int s = filled[e]++;
      if (s < 2) { // more: non-manifold, reported before
        sides[e].triangle[s] = t;
        sides[e].upward[s] = corner(mesh, t, k) < corner(mesh, t, (k + 1) % 3);
      }
    }
  }
  // Flood each connected surface (triangles joined by edges of two) from its first triangle:
  // +1 keeps that triangle's winding, -1 is its opposite.
  std::vector<int> orientation(mesh.triangleCount(), 0);
  std::vector<std::size_t> component, queue;
  for (std::size_t start = 0; start < mesh.triangleCount(); ++start) {
    if (orientation[start] != 0) {
      continue;
    }
    component.clear();
    queue.assign(1, start);
    orientation[start] = 1;
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const std::size_t t = queue[q];
      component.push_back(t);
      for (std::size_t k = 0; k < 3; ++k) {
        const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
        if (filled[e] != 2) {
          continue;
        }
        const int self = sides[e].triangle[0] == t ? 0 : 1;
        const std::size_t other = sides[e].triangle[1 - self];
        // Consistent neighbours traverse a shared edge in opposite directions.
        const bool same = sides[e].upward[0] == sides[e].upward[1];
        const int wanted = same ? -orientation[t] : orientation[t];
        if (orientation[other] == 0) {
          orientation[other] = wanted;
          queue.push_back(other);
        } else if (orientation[other] != wanted) {
          fail(label(mesh), "the surface around " + triangleText(mesh, other) +
                                " cannot be oriented consistently (a Möbius-like strip: every "
                                "choice of winding inverts some triangle); repair the mesh");
        }
      }
    }
    const auto flipped = static_cast<std::size_t>(std::count_if(
        component.begin(), component.end(), [&](std::size_t t) { return orientation[t] < 0; }));
    if (flipped == 0 || flipped == component.size()) {
      continue;
    }
    const int majority = 2 * flipped > component.size() ? -1 : 1;
    const std::size_t minority = majority > 0 ? flipped : component.size() - flipped;
    // The first triangle against the majority that borders one with it (one always exists).
    std::sort(component.begin(), component.end());
    for (const std::size_t t : component) {
      if (orientation[t] == majority) {
        continue;
      }
      for (std::size_t k = 0; k < 3; ++k) {
        const auto e = static_cast<std::size_t>(topology.triangleEdges[3 * t + k]);
        if (filled[e] != 2) {
          continue;
        }
        const std::size_t other = sides[e].triangle[sides[e].triangle[0] == t ? 1 : 0];
        if (orientation[other] == majority) {
          fail(label(mesh),
               "inverted " + triangleText(mesh, t) + ": it traverses its edge " +
                   edgeText(mesh, topology, static_cast<std::int32_t>(e)) +
                   " in the same direction as its neighbour triangle " + std::to_string(other + 1) +
                   ", so its normal points the other way; " + std::to_string(minority) +
                   " of the " + std::to_string(component.size()) +
                   " triangles of its connected surface are wound against the others: flip "
                   "them (reverse their vertex order, e.g. \"unify normals\" in the mesh tool) "
                   "and export the surface again");
        }
      }
    }
  }
}

void checkClosed(const TriangleMesh& mesh, const MeshTopology& topology) {
  std::size_t open = 0;
  std::int32_t first = -1;
  for (std::int32_t e = 0; e < topology.edgeCount; ++e) {
    if (topology.edgeUse[static_cast<std::size_t>(e)] == 1) {
      open += 1;
      first = first < 0 ? e : first;
    }
  }
  if (open == 0) {
    return;
  }
  std::size_t triangle = 0;
  for (std::size_t i = 0; i < topology.triangleEdges.size(); ++i) {
    if (topology.triangleEdges[i] == first) {
      triangle = i / 3;
      break;
    }
  }
  fail(label(mesh), "the surface is not closed: " + std::to_string(open) +
                        " open edge(s) (an edge of only one triangle), the first the edge " +
                        edgeText(mesh, topology, first) + " of " + triangleText(mesh, triangle) +
                        "; a closed wall is required here: fill the hole (e.g. add the missing "
                        "cap) or export the surface again as a closed solid");
}
} // namespace

MeshTopology meshTopology(const TriangleMesh& mesh) {
  checkIndicesAndCoordinates(mesh);
  MeshTopology topology;
  topology.triangleEdges.resize(mesh.triangles.size());
  std::unordered_map<std::uint64_t, std::int32_t> ids;
  ids.reserve(mesh.triangles.size());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t a = corner(mesh, t, k), b = corner(mesh, t, (k + 1) % 3);
      const std::uint64_t key = (static_cast<std::uint64_t>(std::min(a, b)) << 32) |
                                static_cast<std::uint32_t>(std::max(a, b));
      const auto [it, inserted] = ids.try_emplace(key, topology.edgeCount);
      if (inserted) {
        topology.edgeCount += 1;
        topology.edgeUse.push_back(0);
        topology.edgeVertices.insert(topology.edgeVertices.end(), {a, b});
      }
      topology.edgeUse[static_cast<std::size_t>(it->second)] += 1;
      topology.triangleEdges[3 * t + static_cast<std::size_t>(k)] = it->second;
    }
  }
  return topology;
}

void checkMesh(const TriangleMesh& mesh, const MeshCheckOptions& options) {
  checkIndicesAndCoordinates(mesh);
  if (mesh.triangleCount() == 0) {
    fail(label(mesh), "the mesh holds no triangles; give a wall surface with at least one");
  }
  if (options.domain) {
    checkUnits(mesh, *options.domain);
  }
  checkDegenerate(mesh);
  const MeshTopology topology = meshTopology(mesh);
  checkManifold(mesh, topology);
  checkWinding(mesh, topology);
  if (options.requireClosed) {
    checkClosed(mesh, topology);
  }
}
} // namespace coredem::dem
