#pragma once
/// @file
/// The per-cell gas fields of the current CFD step as host/device mirrors, uploaded once per
/// setGas and read (never written) by the engine core, the heat module and the chemistry module.
/// An array the CFD did not send is empty (has() is false).

#include <cstddef>
#include <vector>

#include "backend/arrays.h"
#include "engine.h"

namespace coredem::dem {

template <class Exec>
struct GasFields {
  using Arr = backend::DualArray<double, Exec>;

  Arr ug, gradP, Tg, rhoG, muG, kappaG, cpG, Yg;
  Arr fluid;     ///< φ_f per cell (empty: 1 everywhere)
  Arr heatSplit; ///< Q_split per cell, J/m³ of V_c (empty: none; heat.h giveHeatSplit)

  static bool has(const Arr& a) { return a.size() > 0; }

  /// Copies every field to the host mirror and the device (one transfer per field and step).
  void set(const GasArrays& g) {
    upload(ug, g.ug);
    upload(gradP, g.gradP);
    upload(Tg, g.Tg);
    upload(rhoG, g.rhoG);
    upload(muG, g.muG);
    upload(kappaG, g.kappaG);
    upload(cpG, g.cpG);
    upload(Yg, g.Yg);
    upload(fluid, g.fluidFraction);
    upload(heatSplit, g.heatToParticles);
  }

  std::size_t bytes() const {
    std::size_t b = 0;
    for (const Arr* a : {&ug, &gradP, &Tg, &rhoG, &muG, &kappaG, &cpG, &Yg, &fluid, &heatSplit})
      b += a->bytes();
    return b;
  }

private:
  static void upload(Arr& a, const std::vector<double>& v) {
    a.allocate(v.size());
    for (std::size_t k = 0; k < v.size(); ++k)
      a.h()[k] = v[k];
    a.markHostModified();
    a.toDevice();
  }
};

} // namespace coredem::dem
