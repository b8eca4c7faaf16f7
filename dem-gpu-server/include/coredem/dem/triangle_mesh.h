#pragma once
/// @file
/// Triangle-mesh walls of the DEM on the host: reading and writing STL files (ASCII and binary),
/// welding the vertices, edge topology, checks with messages that say what to fix, and the
/// generators of simple walls (a rectangle, a surface of revolution: cylinder, cone, hopper).
///
/// This library (target coredem::dem_geometry) needs no engine: the orchestrator links it to read
/// and check a case's walls before anything starts. Lengths are in metres throughout.

#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace coredem::dem {

/// A triangulated wall surface, vertices welded so that neighbouring triangles share vertex
/// indices.
struct TriangleMesh {
  std::string name;                    ///< where it came from (file name), used in every message
  std::vector<double> vertices;        ///< x0,y0,z0,x1,... (m)
  std::vector<std::int32_t> triangles; ///< 3 vertex indices per triangle, file order and winding

  std::size_t vertexCount() const { return vertices.size() / 3; }
  std::size_t triangleCount() const { return triangles.size() / 3; }
};

/// A mesh that cannot be read or fails a check; the message names the file (TriangleMesh::name),
/// what is wrong (with the triangle, 1-based as counted in the file, and its vertices) and the fix.
class MeshError : public std::runtime_error {
public:
  using runtime_error::runtime_error;
};

/// Options of readStl().
struct StlOptions {
  double scale = 1.0; ///< coordinates multiplied by scale (0.001: file in mm); finite and > 0
};

/// Reads an ASCII or binary STL file. Binary when the file size is 84 + 50·count for the uint32
/// triangle count of its header (binary files often begin with "solid" too), ASCII when it begins
/// with `solid` (several solids allowed, keywords case-insensitive). The stored facet normals are
/// ignored: the winding (right-hand rule) decides the orientation. Vertices closer than 1e-9 x
/// the bounding-box diagonal are welded into one (identical ones always). Triangles keep the file
/// order, so triangle i (0-based) is triangle i + 1 of the file. Throws MeshError (missing or
/// unreadable file, empty mesh, truncated binary file, ASCII syntax error with its line, non-finite
/// coordinate with its triangle).
TriangleMesh readStl(const std::filesystem::path& file, const StlOptions& options = {});

/// Writes `mesh` as an ASCII (17 significant digits) or binary (single-precision) STL file, the
/// facet normals computed from the winding. Throws MeshError when the file cannot be written.
void writeStl(const TriangleMesh& mesh, const std::filesystem::path& file, bool binary);

/// Edges of a mesh: an edge shared by two triangles has one id (ids in order of first use).
struct MeshTopology {
  /// 3 edge ids per triangle: edge k joins vertex k and vertex (k+1)%3 of the triangle.
  std::vector<std::int32_t> triangleEdges;
  std::int32_t edgeCount = 0;
  std::vector<std::int32_t> edgeUse; ///< triangles per edge (edgeCount entries)
  /// 2 vertex indices per edge, in the direction its first triangle traverses it.
  std::vector<std::int32_t> edgeVertices;
};

/// The edges of `mesh`; throws MeshError for a vertex index out of range.
MeshTopology meshTopology(const TriangleMesh& mesh);

/// Options of checkMesh().
struct MeshCheckOptions {
  bool requireClosed = false; ///< every edge shared by exactly two triangles
  /// lo x,y,z, hi x,y,z (m) the walls are expected to fit: a mesh whose bounding box is far larger
  /// (diagonal > 20x the domain's) is reported as probably in millimetres.
  std::optional<std::array<double, 6>> domain;
};

/// Checks `mesh` and throws MeshError on the first problem: no triangles, a vertex index out of
/// range or a non-finite coordinate; a mesh far larger than the domain (millimetres); a
/// degenerate triangle (two vertices welded into one, or area <= 1e-12 x longest edge²); a
/// non-manifold edge (more than two triangles); an inverted triangle (wound against the majority
/// of its connected surface) or a non-orientable surface; with requireClosed, an open edge.
void checkMesh(const TriangleMesh& mesh, const MeshCheckOptions& options);

/// lo x,y,z, hi x,y,z (m) of the vertices; all zero for a mesh without vertices.
std::array<double, 6> boundingBox(const TriangleMesh& mesh);

/// Generators (tests and cases): a rectangle origin + [0,1]u + [0,1]v cut into nu x nv quads, 2
/// triangles each, normal along u x v. Throws MeshError for nu or nv < 1 or parallel u, v.
TriangleMesh meshRectangle(std::array<double, 3> origin, std::array<double, 3> u,
                           std::array<double, 3> v, int nu, int nv);

/// A surface of revolution: axis through `origin` along `axis` (normalised here); `profile` is a
/// polyline of (t, r) points (t along the axis (m), r >= 0 radius (m)), revolved with `segments`
/// (>= 3) segments around (a point with r = 0 is one vertex on the axis). capStart / capEnd close
/// the first / last profile point with a fan disc (only if its r > 0). Normals (right-hand
/// winding) point away from the axis on the lateral surface (outwards), caps outward too, so a
/// closed result is a consistently outward-oriented closed surface: the winding is chosen so that
/// the region enclosed by the profile and the axis lies behind every triangle, whichever way the
/// profile runs. Cylinder: profile {(0,R),(H,R)}; cone/hopper: {(0,r0),(H,R)}. Throws MeshError
/// for a zero axis, fewer than 2 profile points, a negative or non-finite value, or two
/// consecutive equal profile points.
TriangleMesh meshRevolved(std::array<double, 3> origin, std::array<double, 3> axis,
                          const std::vector<std::array<double, 2>>& profile, int segments,
                          bool capStart, bool capEnd);

} // namespace coredem::dem
