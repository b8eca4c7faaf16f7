// Geometry of cylinder, cone and mesh walls for the pre-flight checks (wall_geometry.h).
#include <algorithm>
#include <cmath>
#include <limits>

#include <coredem/orchestrator/wall_geometry.h>

namespace coredem::orchestrator {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

double dot(const Vec3& a, const Vec3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

/// A 2-D point (y, z) of the projection along x.
struct P2 {
  double y = 0, z = 0;
};

/// Orientation of p against the directed edge a -> b in (y, z), > 0 when p is to the left, for
/// the point p + (ε, ε²) with an infinitesimal ε (simulation of simplicity): never 0 unless a = b.
/// The edge is evaluated in one canonical direction, so the two triangles sharing it get exactly
/// opposite signs and a ray through the edge crosses exactly one of them.
int orientation(P2 a, P2 b, P2 p) {
  int flip = 1;
  if (b.y < a.y || (b.y == a.y && b.z < a.z)) {
    std::swap(a, b);
    flip = -1;
  }
  const double o = (b.y - a.y) * (p.z - a.z) - (b.z - a.z) * (p.y - a.y);
  if (o != 0.0) {
    return o > 0.0 ? flip : -flip;
  }
  // d/dε of the orientation: -(b.z - a.z); then d/dε²: (b.y - a.y).
  if (b.z != a.z) {
    return b.z < a.z ? flip : -flip;
  }
  if (b.y != a.y) {
    return b.y > a.y ? flip : -flip;
  }
  return 0;
}

double area2(P2 a, P2 b, P2 c) {
  return (b.y - a.y) * (c.z - a.z) - (b.z - a.z) * (c.y - a.y);
}

} // namespace

Bounds wallBounds(const RevolvedWallConfig& w) {
  Bounds b;
  for (int d = 0; d < 3; ++d) {
    const auto k = std::size_t(d);
    const double across = std::sqrt(std::max(0.0, 1.0 - w.axis[k] * w.axis[k]));
    if (!w.finite) {
      const bool bounded = w.axis[k] == 0.0;
      b.lo[k] = bounded ? w.point[k] - w.radiusFrom : -kInf;
      b.hi[k] = bounded ? w.point[k] + w.radiusFrom : kInf;
      continue;
    }
    const double c0 = w.point[k] + w.from * w.axis[k], c1 = w.point[k] + w.to * w.axis[k];
    b.lo[k] = std::min(c0 - w.radiusFrom * across, c1 - w.radiusTo * across);
    b.hi[k] = std::max(c0 + w.radiusFrom * across, c1 + w.radiusTo * across);
  }
  return b;
}

Bounds meshBounds(const MeshWallConfig& m) {
  Bounds b{{kInf, kInf, kInf}, {-kInf, -kInf, -kInf}};
  for (std::size_t i = 0; i + 2 < m.vertices.size(); i += 3) {
    for (std::size_t d = 0; d < 3; ++d) {
      b.lo[d] = std::min(b.lo[d], m.vertices[i + d]);
      b.hi[d] = std::max(b.hi[d], m.vertices[i + d]);
    }
  }
  return b;
}

double axialCoordinate(const RevolvedWallConfig& w, const Vec3& x) {
  const Vec3 rel{x[0] - w.point[0], x[1] - w.point[1], x[2] - w.point[2]};
  return dot(rel, w.axis);
}

std::optional<double> insideClearance(const RevolvedWallConfig& w, const Vec3& x) {
  const double t = axialCoordinate(w, x);
  double radius = w.radiusFrom, slope = 0.0;
  if (w.finite) {
    const double length = w.to - w.from;
    const double eps = 1e-12 * (length + std::abs(w.from) + std::abs(w.to));
    if (t < w.from - eps || t > w.to + eps) {
      return std::nullopt;
    }
    slope = (w.radiusTo - w.radiusFrom) / length;
    radius = w.radiusFrom + slope * (std::clamp(t, w.from, w.to) - w.from);
  }
  Vec3 radial{};
  for (std::size_t d = 0; d < 3; ++d) {
    radial[d] = x[d] - w.point[d] - t * w.axis[d];
  }
  const double rho = std::sqrt(dot(radial, radial));
  // The lateral surface is a line r = R(t) in the meridional plane: the distance to it.
  return (radius - rho) / std::sqrt(1.0 + slope * slope);
}

std::vector<Vec3> cornersWithinExtent(const Bounds& box, const RevolvedWallConfig& w) {
  std::array<Vec3, 8> corner{};
  std::array<double, 8> t{};
  for (int k = 0; k < 8; ++k) {
    for (std::size_t d = 0; d < 3; ++d) {
      corner[std::size_t(k)][d] = (k >> d) & 1 ? box.hi[d] : box.lo[d];
    }
    t[std::size_t(k)] = axialCoordinate(w, corner[std::size_t(k)]);
  }
  std::vector<Vec3> out;
  for (std::size_t k = 0; k < 8; ++k) {
    if (!w.finite || (t[k] >= w.from && t[k] <= w.to)) {
      out.push_back(corner[k]);
    }
  }
  if (!w.finite) {
    return out;
  }
  // The 12 edges (corners differing in one bit) crossing the planes t = from and t = to.
  for (std::size_t i = 0; i < 8; ++i) {
    for (std::size_t bit = 1; bit < 8; bit <<= 1) {
      const std::size_t j = i | bit;
      if (j == i) {
        continue;
      }
      for (const double s : {w.from, w.to}) {
        if ((t[i] - s) * (t[j] - s) < 0.0) {
          const double f = (s - t[i]) / (t[j] - t[i]);
          Vec3 x{};
          for (std::size_t d = 0; d < 3; ++d) {
            x[d] = corner[i][d] + f * (corner[j][d] - corner[i][d]);
          }
          out.push_back(x);
        }
      }
    }
  }
  return out;
}

ClosedSurface::ClosedSurface(const std::vector<double>& vertices,
                             const std::vector<std::int32_t>& triangles)
    : _vertices(vertices)
    , _triangles(triangles) {
  const std::size_t nt = triangles.size() / 3;
  for (int a = 0; a < 2; ++a) {
    _lo[a] = kInf;
    _hi[a] = -kInf;
  }
  for (std::size_t i = 0; i + 2 < vertices.size(); i += 3) {
    for (int a = 0; a < 2; ++a) {
      _lo[a] = std::min(_lo[a], vertices[i + 1 + std::size_t(a)]);
      _hi[a] = std::max(_hi[a], vertices[i + 1 + std::size_t(a)]);
    }
  }
  // About one triangle per cell, at most 1024 x 1024 cells.
  const int n = std::clamp(int(std::ceil(std::sqrt(double(nt)))), 1, 1024);
  for (int a = 0; a < 2; ++a) {
    _cells[a] = _hi[a] > _lo[a] ? n : 1;
    _cell[a] = _hi[a] > _lo[a] ? (_hi[a] - _lo[a]) / n : 1.0;
  }
  const std::size_t cellCount = std::size_t(_cells[0]) * std::size_t(_cells[1]);
  _start.assign(cellCount + 1, 0);
  // Two passes over the triangles' (y, z) boxes: count per cell, then fill.
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<std::int32_t> fill;
    if (pass == 1) {
      for (std::size_t c = 0; c < cellCount; ++c) {
        _start[c + 1] += _start[c];
      }
      _items.resize(std::size_t(_start[cellCount]));
      fill.assign(_start.begin(), _start.end() - 1);
    }
    for (std::size_t t = 0; t < nt; ++t) {
      int lo[2] = {_cells[0], _cells[1]}, hi[2] = {-1, -1};
      for (std::size_t k = 0; k < 3; ++k) {
        const std::size_t v = std::size_t(triangles[3 * t + k]);
        for (int a = 0; a < 2; ++a) {
          const int c = cellOf(vertices[3 * v + 1 + std::size_t(a)], a);
          lo[a] = std::min(lo[a], c);
          hi[a] = std::max(hi[a], c);
        }
      }
      for (int iz = lo[1]; iz <= hi[1]; ++iz) {
        for (int iy = lo[0]; iy <= hi[0]; ++iy) {
          const std::size_t c = std::size_t(iy) + std::size_t(_cells[0]) * std::size_t(iz);
          if (pass == 0) {
            ++_start[c + 1];
          } else {
            _items[std::size_t(fill[c]++)] = std::int32_t(t);
          }
        }
      }
    }
  }
}

int ClosedSurface::cellOf(double v, int axis) const {
  return std::clamp(int(std::floor((v - _lo[axis]) / _cell[axis])), 0, _cells[axis] - 1);
}

bool ClosedSurface::contains(const Vec3& x) const {
  if (x[1] < _lo[0] || x[1] > _hi[0] || x[2] < _lo[1] || x[2] > _hi[1]) {
    return false;
  }
  const std::size_t c =
      std::size_t(cellOf(x[1], 0)) + std::size_t(_cells[0]) * std::size_t(cellOf(x[2], 1));
  const P2 p{x[1], x[2]};
  bool inside = false;
  for (std::int32_t k = _start[c]; k < _start[c + 1]; ++k) {
    const std::size_t t = std::size_t(_items[std::size_t(k)]);
    P2 q[3];
    double xs[3];
    for (std::size_t j = 0; j < 3; ++j) {
      const std::size_t v = std::size_t(_triangles[3 * t + j]);
      q[j] = {_vertices[3 * v + 1], _vertices[3 * v + 2]};
      xs[j] = _vertices[3 * v];
    }
    const double area = area2(q[0], q[1], q[2]);
    if (area == 0.0) {
      continue; // seen edge-on: the ray does not cross it (the perturbed point is never on it)
    }
    const int s = area > 0.0 ? 1 : -1;
    if (orientation(q[0], q[1], p) != s || orientation(q[1], q[2], p) != s ||
        orientation(q[2], q[0], p) != s) {
      continue;
    }
    // Where the line through the point along x meets the triangle's plane (barycentric).
    const double l0 = area2(q[1], q[2], p) / area, l1 = area2(q[2], q[0], p) / area;
    const double hit = l0 * xs[0] + l1 * xs[1] + (1.0 - l0 - l1) * xs[2];
    if (hit > x[0]) {
      inside = !inside;
    }
  }
  return inside;
}

} // namespace coredem::orchestrator
