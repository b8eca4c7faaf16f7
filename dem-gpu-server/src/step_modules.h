#pragma once
/// @file
/// The list of the DEM sub-step modules (step_module.h), in the order the engine runs them
/// (engine_impl.h): each sub-step, the sources of every enabled module in this order on the same
/// configuration, the motion update, then the updates in this order. Adding a module: its file
/// and its entry in StepModules below; the engine calls it through the StepModule interface.
/// A compile-time list (a std::tuple iterated by a fold): no virtual calls, every call inlined.

#include <cstddef>
#include <tuple>

#include "chemistry.h"
#include "contacts.h"
#include "drag.h"
#include "heat.h"
#include "step_module.h"

namespace coredem::dem {

/// The modules M..., owned by value, iterated in their order.
template <class Exec, class... M>
class ModuleList {
public:
  static_assert((StepModule<M, Exec> && ...), "every entry is a StepModule (step_module.h)");

  /// f(module) for every module, in the list's order.
  template <class F>
  void forEach(F&& f) {
    std::apply([&](auto&... m) { (f(m), ...); }, _modules);
  }
  template <class F>
  void forEach(F&& f) const {
    std::apply([&](const auto&... m) { (f(m), ...); }, _modules);
  }

  /// The module of type T (for the engine's per-module services: ledgers, contact history).
  template <class T>
  T& get() {
    return std::get<T>(_modules);
  }
  template <class T>
  const T& get() const {
    return std::get<T>(_modules);
  }

  std::size_t bytes() const {
    std::size_t b = 0;
    forEach([&](const auto& m) { b += m.bytes(); });
    return b;
  }

private:
  std::tuple<M...> _modules;
};

/// The sub-step modules, in their order (engine_impl.h, docs/architecture.md "Step order").
template <class Exec>
using StepModules = ModuleList<Exec,
                               DragModule<Exec>,      // gas forces, PCM cells, K_sl (drag.h)
                               ContactModule<Exec>,   // contact forces (contacts.h)
                               HeatModule<Exec>,      // particle heat transfer (heat.h)
                               ChemistryModule<Exec>> // reactions, mass, diameter (chemistry.h)
    ;

} // namespace coredem::dem
