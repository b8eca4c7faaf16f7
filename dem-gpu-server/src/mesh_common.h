#pragma once
/// @file
/// Helpers shared by the triangle-mesh sources (triangle_mesh.cpp: STL reading and writing;
/// mesh_checks.cpp: topology and checks; mesh_generators.cpp): vector arithmetic on
/// std::array, the tolerances, and the texts of the MeshError messages.

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

namespace coredem::dem::mesh_detail {

using Vec3 = std::array<double, 3>;

inline Vec3 sub(const Vec3& a, const Vec3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
inline Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
inline double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline double norm(const Vec3& a) {
  return std::sqrt(dot(a, a));
}

/// Relative weld tolerance: vertices closer than this x the bounding-box diagonal are one.
constexpr double kWeldTolerance = 1e-9;
/// A triangle is degenerate when its area <= this x (longest edge)².
constexpr double kDegenerateArea = 1e-12;
/// A mesh whose bounding-box diagonal exceeds this x the domain's is probably in millimetres.
constexpr double kUnitsRatio = 20.0;
/// Bytes of a binary STL: an 80-byte header and a uint32 count, then 50 bytes a triangle.
constexpr std::uint64_t kBinaryHeader = 84;
constexpr std::uint64_t kBinaryRecord = 50;

inline std::string label(const TriangleMesh& mesh) {
  return mesh.name.empty() ? "(unnamed mesh)" : mesh.name;
}

[[noreturn]] inline void fail(const std::string& where, const std::string& what) {
  throw MeshError(where + ": " + what);
}

inline std::string number(double x) {
  std::ostringstream s;
  s.precision(9);
  s << x;
  return s.str();
}

inline std::string pointText(const Vec3& p) {
  return "(" + number(p[0]) + ", " + number(p[1]) + ", " + number(p[2]) + ")";
}

inline std::string boxText(const std::array<double, 6>& box) {
  return "[" + pointText({box[0], box[1], box[2]}) + " .. " + pointText({box[3], box[4], box[5]}) +
         "] m";
}

inline double boxDiagonal(const std::array<double, 6>& box) {
  return norm({box[3] - box[0], box[4] - box[1], box[5] - box[2]});
}

inline Vec3 vertexAt(const TriangleMesh& mesh, std::int32_t v) {
  const auto i = 3 * static_cast<std::size_t>(v);
  return {mesh.vertices[i], mesh.vertices[i + 1], mesh.vertices[i + 2]};
}

inline std::int32_t corner(const TriangleMesh& mesh, std::size_t t, int k) {
  return mesh.triangles[3 * t + static_cast<std::size_t>(k)];
}

/// "triangle 7 (vertices (x, y, z), (x, y, z), (x, y, z) m)", numbered from 1 as in the file.
inline std::string triangleText(const TriangleMesh& mesh, std::size_t t) {
  return "triangle " + std::to_string(t + 1) + " (vertices " +
         pointText(vertexAt(mesh, corner(mesh, t, 0))) + ", " +
         pointText(vertexAt(mesh, corner(mesh, t, 1))) + ", " +
         pointText(vertexAt(mesh, corner(mesh, t, 2))) + " m)";
}

/// Vertex indices in range and coordinates finite (meshes built by hand, not only read).
inline void checkIndicesAndCoordinates(const TriangleMesh& mesh) {
  if (mesh.vertices.size() % 3 != 0 || mesh.triangles.size() % 3 != 0) {
    fail(label(mesh), "malformed mesh: " + std::to_string(mesh.vertices.size()) +
                          " vertex coordinates and " + std::to_string(mesh.triangles.size()) +
                          " triangle indices (both must be multiples of 3)");
  }
  const auto vertexCount = static_cast<std::int64_t>(mesh.vertexCount());
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = corner(mesh, t, k);
      if (v < 0 || v >= vertexCount) {
        fail(label(mesh), "triangle " + std::to_string(t + 1) + " refers to vertex " +
                              std::to_string(v) + ", but the mesh has " +
                              std::to_string(vertexCount) +
                              " vertices (indices 0 .. n-1); fix the triangle list");
      }
    }
  }
  for (std::size_t t = 0; t < mesh.triangleCount(); ++t) {
    for (int k = 0; k < 3; ++k) {
      const Vec3 p = vertexAt(mesh, corner(mesh, t, k));
      if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2])) {
        fail(label(mesh), "triangle " + std::to_string(t + 1) +
                              " has a non-finite coordinate in its vertex " +
                              std::to_string(k + 1) + " " + pointText(p) +
                              "; repair the surface or export it again");
      }
    }
  }
}
} // namespace coredem::dem::mesh_detail
