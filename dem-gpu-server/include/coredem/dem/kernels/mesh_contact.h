#pragma once
/// @file
/// Sphere–triangle-mesh wall contact (docs/physics.md §2, walls): the closest point of each
/// candidate triangle, then one contact per surface feature the sphere touches.
///
/// A triangle's closest point to the sphere centre x lies in one of seven regions: its face,
/// one of its three edges, one of its three vertices (Voronoi regions of the triangle). The
/// contacts of a sphere with the surface are the local minima of the distance from x over the
/// surface: a triangle's closest point p is one unless a neighbouring triangle has points
/// nearer to x around p. So, over the triangles within reach:
///   * a face touch is kept (the distance has its minimum inside that face), once where two
///     coplanar faces both claim the same point of their shared edge (rounding);
///   * an edge touch is kept only if every other triangle holding that edge also has its
///     closest point on it (x is in the edge's own Voronoi region: a convex edge, or a flat
///     surface exactly over the edge), once for the edge;
///   * a vertex touch likewise only if every triangle holding the vertex has its closest point
///     at the vertex, once for the vertex.
/// What is left is one contact per feature the sphere really touches: one on a flat or convex
/// region, continuous as the sphere slides across edges and vertices (at a region boundary the
/// face and the edge point coincide), even on a mesh finer than the contact patch; two or more
/// in a concave valley (one per face), as with analytic walls. Every triangle holding a touched
/// edge or vertex is itself within reach (it holds a point at the touch's distance), and no
/// farther than the touch, so it is among the nearest kMaxMeshTouches kept: the test sees all
/// of them. Triangles are two-sided; h = |x − p| ≥ 0 and the normal points from
/// p towards x (the triangle's own normal if x lies on it).
///
/// History key of a touch: −(2 + keyBase + triangle index), the triangle that holds the kept
/// feature first in candidate order (ascending index).

#include <cstdint>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/vec3.h"

namespace coredem::dem::kernels {

/// One triangle of a mesh wall with its topology (ids unique over all meshes of a run).
struct MeshTriangle {
  Vec3 a, b, c;
  std::int32_t v[3];          ///< vertex ids of a, b, c
  std::int32_t e[3];          ///< edge ids: e[0] = ab, e[1] = bc, e[2] = ca
  std::int32_t material = -1; ///< material index of the mesh; −1: the particle's own
};

/// Region of a triangle's closest point: kRegionFace, kRegionEdge + k (edge k), kRegionVertex + k.
enum TriangleRegion : int { kRegionFace = 0, kRegionEdge = 1, kRegionVertex = 4 };

/// Closest point of triangle t to x and the region it lies in.
struct TrianglePoint {
  Vec3 p;
  int region;
};

/// The closest point of triangle t to x (Voronoi regions of vertices, then edges, then face).
DEM_HD TrianglePoint closestOnTriangle(const MeshTriangle& t, Vec3 x) {
  const Vec3 ab = t.b - t.a, ac = t.c - t.a, ap = x - t.a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0.0 && d2 <= 0.0)
    return {t.a, kRegionVertex + 0};
  const Vec3 bp = x - t.b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0.0 && d4 <= d3)
    return {t.b, kRegionVertex + 1};
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0)
    return {t.a + (d1 / (d1 - d3)) * ab, kRegionEdge + 0};
  const Vec3 cp = x - t.c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0.0 && d5 <= d6)
    return {t.c, kRegionVertex + 2};
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0)
    return {t.a + (d2 / (d2 - d6)) * ac, kRegionEdge + 2};
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) {
    const double u = (d4 - d3) / ((d4 - d3) + (d5 - d6));
    return {t.b + u * (t.c - t.b), kRegionEdge + 1};
  }
  const double inv = 1.0 / (va + vb + vc);
  return {t.a + (vb * inv) * ab + (vc * inv) * ac, kRegionFace};
}

/// Distance (m) from x to triangle t.
DEM_HD double triangleDistance(const MeshTriangle& t, Vec3 x) {
  const Vec3 e = x - closestOnTriangle(t, x).p;
  return ::sqrt(dot(e, e));
}

/// Most touches of one sphere with the mesh walls considered at once: with more triangles
/// within reach (a mesh finer than the sphere) the nearest are kept, so the triangles holding
/// the real contact and its neighbours' features are among them.
inline constexpr int kMaxMeshTouches = 16;

/// One kept touch of a sphere with a mesh wall.
struct MeshTouch {
  double h;          ///< distance from the centre to the surface (m), ≥ 0
  Vec3 n;            ///< unit normal from the surface towards the centre
  std::uint32_t tri; ///< the triangle holding the feature (the history key's)
  int region;        ///< TriangleRegion of the feature in that triangle
};

namespace detail {
/// Whether triangle t holds edge id e.
DEM_HD bool holdsEdge(const MeshTriangle& t, std::int32_t e) {
  return t.e[0] == e || t.e[1] == e || t.e[2] == e;
}
/// Whether triangle t holds vertex id v.
DEM_HD bool holdsVertex(const MeshTriangle& t, std::int32_t v) {
  return t.v[0] == v || t.v[1] == v || t.v[2] == v;
}
} // namespace detail

/// The touches (h < reach) of a sphere centred at x with the candidate triangles
/// tris[cand[k]], k < nCand (ascending), one per touched feature as the file comment says;
/// writes at most kMaxMeshTouches (the nearest) to out and returns their number.
DEM_HD int meshTouches(const MeshTriangle* tris, const std::uint32_t* cand, int nCand, Vec3 x,
                       double reach, MeshTouch* out) {
  // Pass 1: every triangle within reach, its closest point; the nearest kMaxMeshTouches of them,
  // in candidate order (a touch nearer than the farthest kept one replaces it).
  int raw = 0;
  for (int k = 0; k < nCand; ++k) {
    const MeshTriangle& t = tris[cand[k]];
    const TrianglePoint cp = closestOnTriangle(t, x);
    const Vec3 e = x - cp.p;
    const double h2 = dot(e, e);
    if (!(h2 < reach * reach))
      continue;
    const double h = ::sqrt(h2);
    Vec3 n;
    if (h > 0.0) {
      n = (1.0 / h) * e;
    } else {
      const Vec3 c = cross(t.b - t.a, t.c - t.a);
      n = (1.0 / ::sqrt(dot(c, c))) * c;
    }
    if (raw == kMaxMeshTouches) {
      int far = 0;
      for (int j = 1; j < raw; ++j)
        if (out[j].h > out[far].h)
          far = j;
      if (!(h < out[far].h))
        continue;
      for (int j = far; j < raw - 1; ++j)
        out[j] = out[j + 1];
      --raw;
    }
    out[raw++] = MeshTouch{h, n, cand[k], cp.region};
  }
  // Pass 2: keep an edge or vertex touch only where every triangle holding the feature is
  // touched on that same feature, once per feature (marked first, then compacted: the tests
  // read every raw touch).
  std::uint32_t dropped = 0;
  for (int k = 0; k < raw; ++k) {
    const MeshTouch m = out[k];
    if (m.region == kRegionFace) {
      // Two coplanar faces both claiming a point of their shared edge (rounding): once.
      for (int j = 0; j < k; ++j)
        if (out[j].region == kRegionFace && dot(out[j].n, m.n) > 1.0 - 1e-12 &&
            ::fabs(out[j].h - m.h) <= 1e-12 * reach)
          dropped |= 1u << k;
      continue;
    }
    const bool vertex = m.region >= kRegionVertex;
    const MeshTriangle& mt = tris[m.tri];
    const std::int32_t id = vertex ? mt.v[m.region - kRegionVertex] : mt.e[m.region - kRegionEdge];
    bool drop = false;
    for (int j = 0; j < raw && !drop; ++j) {
      if (j == k)
        continue;
      const MeshTriangle& o = tris[out[j].tri];
      if (!(vertex ? detail::holdsVertex(o, id) : detail::holdsEdge(o, id)))
        continue;
      const int rj = out[j].region;
      const bool same =
          vertex ? (rj >= kRegionVertex && o.v[rj - kRegionVertex] == id)
                 : (rj >= kRegionEdge && rj < kRegionVertex && o.e[rj - kRegionEdge] == id);
      drop = same ? j < k : true;
    }
    dropped |= drop ? (1u << k) : 0u;
  }
  int kept = 0;
  for (int k = 0; k < raw; ++k)
    if (!(dropped >> k & 1u))
      out[kept++] = out[k];
  return kept;
}

} // namespace coredem::dem::kernels
