#pragma once
/// @file
/// Minimal 3-vector for DEM kernels (host and device). Plain aggregate, no invariants.
/// A template on the scalar type (lanes.h): Vec3 holds doubles; Vec3T<Double2> holds two
/// vectors, one per lane, for the cpu backend's two-pair contact loop.

#include <math.h>

#include "coredem/dem/kernels/common.h"
#include "coredem/dem/kernels/lanes.h"

namespace coredem::dem::kernels {

template <class S>
struct Vec3T {
  S x, y, z;
};
using Vec3 = Vec3T<double>;

template <class S>
DEM_HD Vec3T<S> operator+(Vec3T<S> a, Vec3T<S> b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z};
}
template <class S>
DEM_HD Vec3T<S> operator-(Vec3T<S> a, Vec3T<S> b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z};
}
template <class S>
DEM_HD Vec3T<S> operator-(Vec3T<S> a) {
  return {-a.x, -a.y, -a.z};
}
/// s: S or a double (broadcast to every lane).
template <class T, class S>
DEM_HD Vec3T<S> operator*(T s, Vec3T<S> a) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class T, class S>
DEM_HD Vec3T<S> operator*(Vec3T<S> a, T s) {
  return {s * a.x, s * a.y, s * a.z};
}
template <class S>
DEM_HD Vec3T<S>& operator+=(Vec3T<S>& a, Vec3T<S> b) {
  a.x += b.x;
  a.y += b.y;
  a.z += b.z;
  return a;
}
template <class S>
DEM_HD S dot(Vec3T<S> a, Vec3T<S> b) {
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
template <class S>
DEM_HD Vec3T<S> cross(Vec3T<S> a, Vec3T<S> b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
template <class S>
DEM_HD S norm(Vec3T<S> a) {
  return laneSqrt(dot(a, a));
}
/// Per lane, m ? a : b.
template <class M, class S>
DEM_HD Vec3T<S> laneSelect(M m, Vec3T<S> a, Vec3T<S> b) {
  return {laneSelect(m, a.x, b.x), laneSelect(m, a.y, b.y), laneSelect(m, a.z, b.z)};
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
