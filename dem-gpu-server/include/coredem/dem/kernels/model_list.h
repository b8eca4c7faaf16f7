#pragma once
/// @file
/// Compile-time model registries of the kernels (docs/architecture.md "Model registries"): a
/// family's models are a type list, `ModelList<A, B, …>`, written once in the family's header
/// (the registration line). A model is a struct in its own header that declares
///
///   static constexpr const char* name;   // as written in case.yaml (`models: {drag: name}`)
///   static constexpr const char* doc;    // one line for docs/case-schema.md and messages
///   struct Params { … };                 // plain data, defaults = the documented defaults
///   static constexpr auto params();      // std::array of ModelParam<Params>: its `models:` keys
///   DEM_HD static … evaluate(const Params&, …);   // the family's kernel signature
///
/// From the list come the model's id (its position: appending keeps earlier ids, and so the
/// configuration hashes of earlier runs), the parameters of every model in one plain struct
/// (ParamPack, passed by value into kernels), the dispatch on the id (a chain of compares
/// generated from the list, no virtual call: the same code on the cpu and cuda backends), and on
/// the host the `models:` keys, their validation, their hash and their docs row (models.h).

#include <array>
#include <type_traits>

#include "coredem/dem/kernels/common.h"

namespace coredem::dem::kernels {

/// The models of one family, in id order (the registration line).
template <class... Ms>
struct ModelList {
  static constexpr int size = sizeof...(Ms);
};

/// A model's id in its family: its position in the list.
template <class M, class List>
struct ModelId;
template <class M, class... Ms>
struct ModelId<M, ModelList<Ms...>> {
  static constexpr int value = [] {
    int index = 0, found = -1;
    ((found = (found < 0 && std::is_same_v<M, Ms>) ? index : found, ++index), ...);
    return found;
  }();
  static_assert(value >= 0, "the model is not registered in this family's ModelList");
};
template <class M, class List>
inline constexpr int modelId = ModelId<M, List>::value;

/// One numeric parameter of a model: its `models:` key is "<family>.<model>.<key>" (models.h).
/// Host-side description (range, default from Params{}, units and doc); never used in kernels.
template <class P>
struct ModelParam {
  const char* key;   ///< e.g. "c1"
  double P::*field;  ///< where it is stored
  double lo, hi;     ///< allowed range [lo, hi] (lo excluded when loOpen)
  bool loOpen;       ///< lo excluded
  const char* units; ///< e.g. "-", "m"
  const char* doc;   ///< one line
};

/// A model without parameters: `static constexpr auto params() { return noParams<Params>(); }`.
template <class P>
constexpr std::array<ModelParam<P>, 0> noParams() {
  return {};
}

/// The parameters of one model inside a ParamPack.
template <class M>
struct ParamSlot {
  typename M::Params params{};
};

/// The parameters of every model of a family in one plain struct (copied by value into kernels).
template <class List>
struct ParamPack;
template <class... Ms>
struct ParamPack<ModelList<Ms...>> : ParamSlot<Ms>... {
  template <class M>
  DEM_HD const typename M::Params& of() const {
    return static_cast<const ParamSlot<M>&>(*this).params;
  }
  template <class M>
  DEM_HD typename M::Params& of() {
    return static_cast<ParamSlot<M>&>(*this).params;
  }
};

/// Dispatch on a model id: Family::template evaluate<M>(args…) for the model M of that id (the
/// last model for an id out of range). Family is the family's dispatch struct (e.g. drag.h).
template <class Family, class List>
struct Dispatch;
template <class Family, class M, class... Rest>
struct Dispatch<Family, ModelList<M, Rest...>> {
  template <class... Args>
  DEM_HD static auto call(int id, const Args&... args) {
    if constexpr (sizeof...(Rest) == 0) {
      (void)id;
      return Family::template evaluate<M>(args...);
    } else {
      return id == 0 ? Family::template evaluate<M>(args...)
                     : Dispatch<Family, ModelList<Rest...>>::call(id - 1, args...);
    }
  }
};

/// The model M as a value: what visitModel passes (`typename decltype(tag)::type`).
template <class M>
struct ModelTag {
  using type = M;
};

/// Calls f(ModelTag<M>{}) for the model M of id `id` (the last model for an id out of range),
/// host side: Dispatch's chain of compares once for a whole pass, f then runs code instantiated
/// for M (e.g. contacts.h: the owners' pass of the chosen contact law, no test per pair). With
/// one model in the list, f(ModelTag<M>{}) and nothing else.
template <class M, class... Rest, class F>
void visitModel(ModelList<M, Rest...>, int id, F&& f) {
  if constexpr (sizeof...(Rest) == 0) {
    (void)id;
    f(ModelTag<M>{});
  } else if (id == 0) {
    f(ModelTag<M>{});
  } else {
    visitModel(ModelList<Rest...>{}, id - 1, f);
  }
}

/// Calls f.template operator()<M>() for every model of the list, in id order (host side:
/// registries, options, hashing).
template <class... Ms, class F>
constexpr void forEachModel(ModelList<Ms...>, F&& f) {
  (f.template operator()<Ms>(), ...);
}

} // namespace coredem::dem::kernels
