#pragma once
/// @file
/// The run's walls on the device and, per particle, the walls it may touch until the next
/// neighbour rebuild (the candidates the contact and heat modules evaluate).
///
/// * Analytic walls (kernels/wall_contact.h: planes, surfaces of revolution): a bit per wall
///   for the first kNearBits walls; walls beyond them are candidates of every particle.
/// * Mesh walls (kernels/mesh_contact.h): a binned triangle search. The bins (a uniform grid
///   over the meshes' bounding box, each bin listing the triangles whose box, grown by the
///   largest reach, overlaps it) are built once on the host: walls do not move. At each rebuild
///   every particle looks up the bin of its reference position and keeps the triangles of that
///   bin within its reach, in ascending index (a count pass, a scan, a fill pass: the same
///   kernels on every backend); bit kMeshBit of its wall bits says it has some.
///
/// A particle moves at most skin/2 from its reference position (xref) before the next rebuild
/// and radii only shrink, so a wall or triangle farther than f·R + skin/2 from xref cannot come
/// within f·R of the centre until then (f = EngineSetup::wallReachFactor: 1 for contacts,
/// 1 + FLPC when the heat module's wall gas lens is on).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "backend/arrays.h"
#include "coredem/dem/kernels/mesh_contact.h"
#include "coredem/dem/kernels/vec3.h"
#include "coredem/dem/kernels/wall_contact.h"
#include "engine.h"
#include "particle_store.h"

namespace coredem::dem {

/// Analytic walls with a candidate bit of their own; bit kWallMeshBit says "mesh candidates".
inline constexpr int kWallNearBits = 31;
inline constexpr std::uint32_t kWallMeshBit = 1u << 31;

/// Two mesh triangles hand a touch's tangential history on only where their normals are
/// within 10° (cos 10°): a curved surface faceted at least as finely (an STL cylinder of 36 or
/// more facets around) keeps it across facets, a corner or valley sharper than that does not.
inline constexpr double kHistoryBendCos = 0.98480775301220806;

/// The walls as the contact and heat kernels read them (device pointers), and the one order in
/// which a particle's touches are found: its candidate analytic walls ascending (the bits of the
/// first kWallNearBits, then every wall beyond them), each wall's touches in feature order, then
/// its mesh touches (kernels/mesh_contact.h).
struct WallView {
  const kernels::Wall* walls;
  int nWalls;
  const kernels::MeshTriangle* tris;
  const std::uint32_t* meshStart;
  const std::uint32_t* meshList;
  std::int64_t meshKeyBase; ///< nWalls · kMaxWallFeatures

  /// Calls f(h, n, key) for every touch of particle i (centre x) within `reach` with the walls
  /// of its candidate bits: h the distance to the surface, n the unit normal from the wall
  /// towards the centre, key the touch's history key (−(2 + k + nWalls·f) for feature f of
  /// analytic wall k, −(2 + meshKeyBase + t) for triangle t).
  template <class F>
  DEM_HD void touches(std::uint32_t nearBits, std::size_t i, kernels::Vec3 x, double reach,
                      F&& f) const {
    std::uint32_t bits = nearBits & ~kWallMeshBit;
    for (int k = bits != 0 ? kernels::lowestBit(bits) : kWallNearBits; k < nWalls;) {
      kernels::WallTouch wt[kernels::kMaxWallTouches];
      const int nt = kernels::wallTouches(walls[k], x, reach, wt);
      for (int c = 0; c < nt; ++c)
        f(wt[c].h, wt[c].n, -(2 + k + static_cast<std::int64_t>(nWalls) * wt[c].feature));
      if (k < kWallNearBits) {
        bits &= bits - 1;
        k = bits != 0 ? kernels::lowestBit(bits) : kWallNearBits;
      } else {
        ++k;
      }
    }
    if (nearBits & kWallMeshBit) {
      kernels::MeshTouch mt[kernels::kMaxMeshTouches];
      const std::uint32_t m0 = meshStart[i];
      const int nm = kernels::meshTouches(tris, meshList + m0,
                                          static_cast<int>(meshStart[i + 1] - m0), x, reach, mt);
      for (int c = 0; c < nm; ++c)
        f(mt[c].h, mt[c].n, -(2 + meshKeyBase + static_cast<std::int64_t>(mt[c].tri)));
    }
  }

  /// The material of the wall a touch with history key `key` belongs to (kernels::Wall::material,
  /// kernels::MeshTriangle::material): −1 for the particle's own (the default).
  DEM_HD int materialOf(std::int64_t key) const {
    const std::int64_t k = -key - 2;
    return k < meshKeyBase ? walls[k % nWalls].material : tris[k - meshKeyBase].material;
  }

  /// Whether a touch new to `key` may take over the history of the last sub-step's wall touch
  /// `old` (one the sphere no longer touches; contact_owners.h hands each history on once):
  /// another feature of the same analytic wall (a sphere rolling over a rim onto a cap), or a
  /// triangle sharing a vertex with the new one and nearly coplanar with it (normals within
  /// kHistoryBendCos: sliding across an edge or a vertex of a flat or gently curved surface,
  /// not around a corner or into a valley).
  DEM_HD bool continues(std::int64_t key, std::int64_t old) const {
    const std::int64_t o = -old - 2, k = -key - 2;
    if (o < 0)
      return false;
    if (k < meshKeyBase)
      return o < meshKeyBase && o % nWalls == k % nWalls;
    if (o < meshKeyBase)
      return false;
    const kernels::MeshTriangle& t = tris[k - meshKeyBase];
    const kernels::MeshTriangle& u = tris[o - meshKeyBase];
    bool shared = false;
    for (int a = 0; a < 3; ++a)
      shared = shared || u.v[a] == t.v[0] || u.v[a] == t.v[1] || u.v[a] == t.v[2];
    if (!shared)
      return false;
    // |cos| of the angle between the normals (triangles are two-sided), squared: no root.
    const kernels::Vec3 nt = kernels::cross(t.b - t.a, t.c - t.a);
    const kernels::Vec3 nu = kernels::cross(u.b - u.a, u.c - u.a);
    const double c = kernels::dot(nt, nu);
    return c * c >= kHistoryBendCos * kHistoryBendCos * kernels::dot(nt, nt) * kernels::dot(nu, nu);
  }
};

template <class Exec>
class WallLists {
public:
  template <class T>
  using Dual = backend::DualArray<T, Exec>;
  template <class T>
  using Dev = backend::DeviceArray<T, Exec>;

  static constexpr int kNearBits = kWallNearBits;
  static constexpr std::uint32_t kMeshBit = kWallMeshBit;
  /// Most bins of the triangle search (the bin edge grows to stay below).
  static constexpr std::size_t kMaxBins = std::size_t{1} << 22;

  void setup(const EngineSetup& s) {
    _nWalls = static_cast<int>(s.walls.size());
    _walls.allocate(s.walls.size());
    std::copy(s.walls.begin(), s.walls.end(), _walls.h());
    _walls.markHostModified();
    _walls.toDevice();
    _reachFactor = s.wallReachFactor;
    _nTris = s.triangles.size();
    if (_nTris > 0)
      buildBins(s);
  }

  int wallCount() const { return _nWalls; }
  const kernels::Wall* walls() const { return _walls.d(); }
  const kernels::MeshTriangle* triangles() const { return _tris.d(); }
  /// Per particle: wall bits (bit k < kNearBits: analytic wall k, all bits when there are more
  /// walls than bits; kMeshBit: mesh candidates).
  const std::uint32_t* near() const { return _near.d(); }
  /// Per particle: its mesh candidates meshList()[meshStart()[i] .. meshStart()[i + 1]).
  const std::uint32_t* meshStart() const { return _meshStart.d(); }
  const std::uint32_t* meshList() const { return _meshList.d(); }
  /// History key base of the mesh triangles: a touch of triangle t has key −(2 + base + t).
  std::int64_t meshKeyBase() const {
    return static_cast<std::int64_t>(_nWalls) * kernels::kMaxWallFeatures;
  }
  /// What the kernels read (device pointers).
  WallView view() const {
    return {_walls.d(), _nWalls, _tris.d(), _meshStart.d(), _meshList.d(), meshKeyBase()};
  }
  std::size_t bytes() const {
    return _walls.bytes() + _tris.bytes() + _binStart.bytes() + _binTris.bytes() + _near.bytes() +
           _meshStart.bytes() + _meshList.bytes();
  }

  /// The candidates of the neighbour lists of build `generation`, from xref (rebuilt once per
  /// build). Reads xref, radius.
  void ensure(Exec& exec, ParticleStore<Exec>& p, std::uint64_t generation, double skin) {
    if (_generation == generation && _n == p.n)
      return;
    _generation = generation;
    _n = p.n;
    _near.reserve(p.n);
    std::uint32_t* near = _near.d();
    const double* xr = p.xref.d();
    const double* r = p.radius.d();
    const kernels::Wall* walls = _walls.d();
    const int nWalls = _nWalls;
    const double halfSkin = 0.5 * skin;
    const double f = _reachFactor;
    exec.parallelFor(p.n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t bits = 0;
      if (nWalls > kNearBits) {
        bits = ~kMeshBit;
      } else {
        const kernels::Vec3 xi = kernels::load3(xr, static_cast<long long>(i));
        const double reach = f * r[i] + halfSkin;
        for (int k = 0; k < nWalls; ++k) {
          // Not "at least reach away" (also catches NaN): a candidate.
          if (!(kernels::wallClearance(walls[k], xi) >= reach))
            bits |= 1u << k;
        }
      }
      near[i] = bits;
    });
    if (_nTris > 0)
      buildMeshLists(exec, p, halfSkin);
  }

  // (Public for nvcc: a function holding an extended device lambda cannot be private.)
  /// Bin of a point, or −1 outside the bins.
  struct Bins {
    kernels::Vec3 lo;
    double inv;
    int nx, ny, nz;
    DEM_HD long long at(kernels::Vec3 x) const {
      const double fx = (x.x - lo.x) * inv, fy = (x.y - lo.y) * inv, fz = (x.z - lo.z) * inv;
      if (!(fx >= 0.0 && fy >= 0.0 && fz >= 0.0 && fx < nx && fy < ny && fz < nz))
        return -1;
      return static_cast<long long>(fx) +
             nx * (static_cast<long long>(fy) + ny * static_cast<long long>(fz));
    }
  };

  /// Visits the triangles of particle i's bin within its reach, in ascending index.
  struct MeshSearch {
    const double* xr;
    const double* r;
    const kernels::MeshTriangle* tris;
    const std::uint32_t* bs;
    const std::uint32_t* bt;
    Bins bins;
    double f;
    double halfSkin;
    template <class Take>
    DEM_HD void operator()(std::size_t i, Take&& take) const {
      const kernels::Vec3 xi = kernels::load3(xr, static_cast<long long>(i));
      const long long b = bins.at(xi);
      if (b < 0)
        return;
      const double reach = f * r[i] + halfSkin;
      for (std::uint32_t k = bs[b]; k < bs[b + 1]; ++k)
        if (!(kernels::triangleDistance(tris[bt[k]], xi) >= reach)) // NaN: a candidate
          take(bt[k]);
    }
  };

  void buildBins(const EngineSetup& s) {
    using kernels::Vec3;
    _tris.allocate(_nTris);
    std::copy(s.triangles.begin(), s.triangles.end(), _tris.h());
    _tris.markHostModified();
    _tris.toDevice();
    // Reach of the largest particle: its triangles lie within this of its reference position.
    const double grow = s.wallReachFactor * s.maxRadius + 0.5 * s.skin;
    double lo[3] = {HUGE_VAL, HUGE_VAL, HUGE_VAL}, hi[3] = {-HUGE_VAL, -HUGE_VAL, -HUGE_VAL};
    auto boxOf = [&](const kernels::MeshTriangle& t, double* a, double* b) {
      const Vec3 v[3] = {t.a, t.b, t.c};
      for (int d = 0; d < 3; ++d) {
        a[d] = HUGE_VAL, b[d] = -HUGE_VAL;
        for (const Vec3& p : v) {
          const double c = d == 0 ? p.x : (d == 1 ? p.y : p.z);
          a[d] = std::min(a[d], c - grow);
          b[d] = std::max(b[d], c + grow);
        }
      }
    };
    for (const kernels::MeshTriangle& t : s.triangles) {
      double a[3], b[3];
      boxOf(t, a, b);
      for (int d = 0; d < 3; ++d)
        lo[d] = std::min(lo[d], a[d]), hi[d] = std::max(hi[d], b[d]);
    }
    // Bin edge: twice the reach, or larger to stay within kMaxBins.
    double h = std::max(2.0 * grow, 1e-12);
    auto count = [&](double e) {
      std::size_t c = 1;
      for (int d = 0; d < 3; ++d)
        c *= static_cast<std::size_t>(std::ceil((hi[d] - lo[d]) / e));
      return c;
    };
    while (count(h) > kMaxBins)
      h *= 1.25;
    Bins b{Vec3{lo[0], lo[1], lo[2]}, 1.0 / h, 0, 0, 0};
    b.nx = std::max(1, static_cast<int>(std::ceil((hi[0] - lo[0]) / h)));
    b.ny = std::max(1, static_cast<int>(std::ceil((hi[1] - lo[1]) / h)));
    b.nz = std::max(1, static_cast<int>(std::ceil((hi[2] - lo[2]) / h)));
    _bins = b;
    const std::size_t nb = static_cast<std::size_t>(b.nx) * b.ny * b.nz;
    // Each triangle in every bin its grown box overlaps (counts, then the lists, in index order).
    std::vector<std::uint32_t> start(nb + 1, 0), fill;
    auto range = [&](const kernels::MeshTriangle& t, int* i0, int* i1) {
      double a[3], c[3];
      boxOf(t, a, c);
      const int n[3] = {b.nx, b.ny, b.nz};
      for (int d = 0; d < 3; ++d) {
        i0[d] = std::clamp(static_cast<int>(std::floor((a[d] - lo[d]) / h)), 0, n[d] - 1);
        i1[d] = std::clamp(static_cast<int>(std::floor((c[d] - lo[d]) / h)), 0, n[d] - 1);
      }
    };
    for (int pass = 0; pass < 2; ++pass) {
      if (pass == 1) {
        for (std::size_t k = 0; k < nb; ++k)
          start[k + 1] += start[k];
        fill.assign(start.begin(), start.end() - 1);
        _binTris.allocate(std::max<std::size_t>(start[nb], 1));
      }
      for (std::size_t t = 0; t < _nTris; ++t) {
        int i0[3], i1[3];
        range(s.triangles[t], i0, i1);
        for (int z = i0[2]; z <= i1[2]; ++z)
          for (int y = i0[1]; y <= i1[1]; ++y)
            for (int x = i0[0]; x <= i1[0]; ++x) {
              const std::size_t k =
                  static_cast<std::size_t>(x) +
                  static_cast<std::size_t>(b.nx) *
                      (static_cast<std::size_t>(y) + static_cast<std::size_t>(b.ny) * z);
              if (pass == 0)
                ++start[k + 1];
              else
                _binTris.h()[fill[k]++] = static_cast<std::uint32_t>(t);
            }
      }
    }
    _binStart.allocate(nb + 1);
    std::copy(start.begin(), start.end(), _binStart.h());
    _binStart.markHostModified();
    _binStart.toDevice();
    _binTris.markHostModified();
    _binTris.toDevice();
  }

  /// Per particle, the triangles of its bin within reach (count, scan, fill).
  void buildMeshLists(Exec& exec, ParticleStore<Exec>& p, double halfSkin) {
    const std::size_t n = p.n;
    _meshCount.reserve(n + 1);
    _meshStart.reserve(n + 1);
    std::uint32_t* cnt = _meshCount.d();
    std::uint32_t* near = _near.d();
    const double* xr = p.xref.d();
    const double* r = p.radius.d();
    const kernels::MeshTriangle* tris = _tris.d();
    const std::uint32_t* bs = _binStart.d();
    const std::uint32_t* bt = _binTris.d();
    const MeshSearch visit{xr, r, tris, bs, bt, _bins, _reachFactor, halfSkin};
    exec.parallelFor(n + 1, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t c = 0;
      if (i < n)
        visit(i, [&](std::uint32_t) { ++c; });
      cnt[i] = c;
      if (i < n && c > 0)
        near[i] |= kMeshBit;
    });
    std::uint32_t* ms = _meshStart.d();
    exec.exclusiveScan(cnt, ms, n + 1);
    std::uint32_t total = 0;
    Exec::copyToHost(&total, ms + n, sizeof(total));
    _meshList.reserve(std::max<std::uint32_t>(total, 1));
    std::uint32_t* ml = _meshList.d();
    exec.parallelFor(n, [=] DEM_LAMBDA(std::size_t i) {
      std::uint32_t at = ms[i];
      visit(i, [&](std::uint32_t t) { ml[at++] = t; });
    });
  }

private:
  int _nWalls = 0;
  std::size_t _nTris = 0;
  double _reachFactor = 1.0;
  Dual<kernels::Wall> _walls;
  Dual<kernels::MeshTriangle> _tris;
  Dual<std::uint32_t> _binStart; ///< per bin + 1: start of its triangles in _binTris
  Dual<std::uint32_t> _binTris;  ///< triangles of every bin, ascending per bin
  Bins _bins{};
  Dev<std::uint32_t> _near;      ///< per particle: wall bits
  Dev<std::uint32_t> _meshCount; ///< per particle + 1: mesh candidates (scan input)
  Dev<std::uint32_t> _meshStart; ///< per particle + 1: start of its mesh candidates
  Dev<std::uint32_t> _meshList;  ///< mesh candidates of every particle
  std::uint64_t _generation = ~std::uint64_t{0};
  std::size_t _n = ~std::size_t{0};
};

} // namespace coredem::dem
