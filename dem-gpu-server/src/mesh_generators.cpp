// Triangle-mesh walls on the host: bounding box and generated meshes (rectangle, surfaces of
// revolution) (coredem/dem/triangle_mesh.h).
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

/// The orthonormal (e1, e2) with e1 x e2 = axis (a unit vector).
std::pair<Vec3, Vec3> perpendicularBasis(const Vec3& axis) {
  const Vec3 helper = std::abs(axis[0]) < 0.9 ? Vec3{1.0, 0.0, 0.0} : Vec3{0.0, 1.0, 0.0};
  const double along = dot(helper, axis);
  Vec3 e1{helper[0] - along * axis[0], helper[1] - along * axis[1], helper[2] - along * axis[2]};
  const double length = norm(e1);
  e1 = {e1[0] / length, e1[1] / length, e1[2] / length};
  return {e1, cross(axis, e1)};
}

} // namespace

std::array<double, 6> boundingBox(const TriangleMesh& mesh) {
  if (mesh.vertexCount() == 0) {
    return {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
  }
  std::array<double, 6> box{};
  for (std::size_t d = 0; d < 3; ++d) {
    box[d] = box[d + 3] = mesh.vertices[d];
  }
  for (std::size_t v = 0; v < mesh.vertexCount(); ++v) {
    for (std::size_t d = 0; d < 3; ++d) {
      box[d] = std::min(box[d], mesh.vertices[3 * v + d]);
      box[d + 3] = std::max(box[d + 3], mesh.vertices[3 * v + d]);
    }
  }
  return box;
}

TriangleMesh meshRectangle(std::array<double, 3> origin, std::array<double, 3> u,
                           std::array<double, 3> v, int nu, int nv) {
  if (nu < 1 || nv < 1) {
    fail("rectangle",
         "nu = " + std::to_string(nu) + " and nv = " + std::to_string(nv) + " must both be >= 1");
  }
  const double area = norm(cross(u, v));
  if (!(area > kDegenerateArea * std::max(dot(u, u), dot(v, v)))) {
    fail("rectangle", "its sides u " + pointText(u) + " m and v " + pointText(v) +
                          " m are parallel or zero; give two independent directions");
  }
  TriangleMesh mesh;
  mesh.name = "rectangle";
  for (int j = 0; j <= nv; ++j) {
    for (int i = 0; i <= nu; ++i) {
      const double a = static_cast<double>(i) / nu, b = static_cast<double>(j) / nv;
      for (std::size_t d = 0; d < 3; ++d) {
        mesh.vertices.push_back(origin[d] + a * u[d] + b * v[d]);
      }
    }
  }
  const auto index = [&](int i, int j) { return static_cast<std::int32_t>(j * (nu + 1) + i); };
  for (int j = 0; j < nv; ++j) {
    for (int i = 0; i < nu; ++i) {
      const std::int32_t a = index(i, j), b = index(i + 1, j), c = index(i + 1, j + 1),
                         d = index(i, j + 1);
      mesh.triangles.insert(mesh.triangles.end(), {a, b, c, a, c, d});
    }
  }
  return mesh;
}

TriangleMesh meshRevolved(std::array<double, 3> origin, std::array<double, 3> axis,
                          const std::vector<std::array<double, 2>>& profile, int segments,
                          bool capStart, bool capEnd) {
  const std::string where = "revolved surface";
  const double axisLength = norm(axis);
  if (!(axisLength > 0.0) || !std::isfinite(axisLength)) {
    fail(where, "its axis " + pointText(axis) + " must be a finite non-zero vector");
  }
  axis = {axis[0] / axisLength, axis[1] / axisLength, axis[2] / axisLength};
  if (segments < 3) {
    fail(where, std::to_string(segments) + " segments around: give at least 3");
  }
  if (profile.size() < 2) {
    fail(where, "its profile has " + std::to_string(profile.size()) +
                    " point(s): give at least 2 (t, r) points");
  }
  for (std::size_t i = 0; i < profile.size(); ++i) {
    const auto [t, r] = profile[i];
    if (!std::isfinite(t) || !std::isfinite(r) || r < 0.0) {
      fail(where, "profile point " + std::to_string(i + 1) + " (t " + number(t) + ", r " +
                      number(r) + ") m: t must be finite and r finite and >= 0");
    }
    if (i > 0 && profile[i] == profile[i - 1]) {
      fail(where, "profile points " + std::to_string(i) + " and " + std::to_string(i + 1) +
                      " are the same point; remove one");
    }
  }
  // The region behind the triangles is the profile closed along the axis: with the winding
  // below, its normals are the profile's tangent (dt, dr) turned to (-dr, dt) in the (t, r) plane,
  // which points out of that region when it runs clockwise (negative shoelace area).
  double twiceArea =
      profile.front()[0] * profile.front()[1] - profile.back()[0] * profile.back()[1];
  for (std::size_t i = 0; i + 1 < profile.size(); ++i) {
    twiceArea += profile[i][0] * profile[i + 1][1] - profile[i + 1][0] * profile[i][1];
  }
  const bool flip = twiceArea > 0.0;

  const auto [e1, e2] = perpendicularBasis(axis);
  TriangleMesh mesh;
  mesh.name = where;
  const auto addVertex = [&](const Vec3& p) {
    mesh.vertices.insert(mesh.vertices.end(), p.begin(), p.end());
    return static_cast<std::int32_t>(mesh.vertexCount() - 1);
  };
  const auto onAxis = [&](double t) {
    return Vec3{origin[0] + t * axis[0], origin[1] + t * axis[1], origin[2] + t * axis[2]};
  };
  const auto seg = static_cast<std::size_t>(segments);
  std::vector<double> cosine(seg), sine(seg);
  for (std::size_t j = 0; j < seg; ++j) {
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(j) / segments;
    cosine[j] = std::cos(angle);
    sine[j] = std::sin(angle);
  }
  // One ring of vertex indices a profile point (all the same for a point on the axis).
  std::vector<std::vector<std::int32_t>> rings;
  for (const auto& [t, r] : profile) {
    const Vec3 centre = onAxis(t);
    if (r == 0.0) {
      rings.emplace_back(seg, addVertex(centre));
      continue;
    }
    std::vector<std::int32_t> ring(seg);
    for (std::size_t j = 0; j < seg; ++j) {
      Vec3 p{};
      for (std::size_t d = 0; d < 3; ++d) {
        p[d] = centre[d] + r * (cosine[j] * e1[d] + sine[j] * e2[d]);
      }
      ring[j] = addVertex(p);
    }
    rings.push_back(std::move(ring));
  }
  const auto addTriangle = [&](std::int32_t a, std::int32_t b, std::int32_t c) {
    if (a == b || b == c || a == c) {
      return; // a corner on the axis
    }
    if (flip) {
      std::swap(b, c);
    }
    mesh.triangles.insert(mesh.triangles.end(), {a, b, c});
  };
  // The band from ring A to ring B: quads (A_j, A_j+1, B_j+1, B_j), triangles with the normal
  // (-dr, dt) of the profile.
  const auto addBand = [&](const std::vector<std::int32_t>& a, const std::vector<std::int32_t>& b) {
    for (std::size_t j = 0; j < seg; ++j) {
      const std::size_t k = (j + 1) % seg;
      addTriangle(a[j], a[k], b[k]);
      addTriangle(a[j], b[k], b[j]);
    }
  };
  if (capStart && profile.front()[1] > 0.0) {
    addBand(std::vector<std::int32_t>(seg, addVertex(onAxis(profile.front()[0]))), rings.front());
  }
  for (std::size_t i = 0; i + 1 < rings.size(); ++i) {
    addBand(rings[i], rings[i + 1]);
  }
  if (capEnd && profile.back()[1] > 0.0) {
    addBand(rings.back(), std::vector<std::int32_t>(seg, addVertex(onAxis(profile.back()[0]))));
  }
  return mesh;
}

} // namespace coredem::dem
