#pragma once
/// @file
/// Minimal 3-vector for DEM kernels (host and device). Plain aggregate, no invariants.

#include <math.h>

#include "coredem/dem/kernels/common.h"

namespace coredem::dem::kernels {

struct Vec3 {
  double x, y, z;
};

DEM_HD Vec3 operator+(Vec3 a, Vec3 b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
DEM_HD Vec3 operator-(Vec3 a, Vec3 b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
DEM_HD Vec3 operator-(Vec3 a) {
  return {-a.x, -a.y, -a.z};
}
DEM_HD Vec3 operator*(double s, Vec3 a) {
  return {s * a.x, s * a.y, s * a.z};
}
DEM_HD Vec3 operator*(Vec3 a, double s) {
  return {s * a.x, s * a.y, s * a.z};
}
DEM_HD Vec3& operator+=(Vec3& a, Vec3 b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
DEM_HD double dot(Vec3 a, Vec3 b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
DEM_HD Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
DEM_HD double norm(Vec3 a) {
  return ::sqrt(dot(a, a));
}
DEM_HD Vec3 load3(const double* p, long long i) {
  return {p[3 * i], p[3 * i + 1], p[3 * i + 2]};
}
DEM_HD void store3(double* p, long long i, Vec3 v) {
  p[3 * i] = v.x;
  p[3 * i + 1] = v.y;
  p[3 * i + 2] = v.z;
}

} // namespace coredem::dem::kernels
