#pragma once
/// @file
/// The host side of the model families declared as type lists (kernels/model_list.h): from a
/// family's ModelList its registry entries, one `models:` row per declared parameter (key
/// "<family>.<model>.<parameter>", parsed and range-checked from the declaration, stored in the
/// family's ParamPack), the hash text of the chosen model's parameters and their range check.
/// Templates over the configuration type and where it keeps the family's ParamPack, so that the
/// tests instantiate them with a family of their own; models.cpp binds them to DemConfig.

#include <array>
#include <charconv>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "coredem/common/check.h"
#include "coredem/dem/kernels/model_list.h"
#include "coredem/dem/models.h"

namespace coredem::dem::registry {

/// The registry entries of a family's type list (name, id as `E`, doc from each declaration).
template <class E, class... Ms>
constexpr std::array<ModelEntry<E>, sizeof...(Ms)> entriesOf(kernels::ModelList<Ms...> list) {
  return {
      ModelEntry<E>{Ms::name, static_cast<E>(kernels::modelId<Ms, decltype(list)>), Ms::doc}...};
}

/// "%.17g" (the hash's and the defaults' spelling of a number).
inline std::string g17(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

/// The shortest text that reads back as `v` (defaults and ranges as users read them).
inline std::string shortest(double v) {
  char b[40];
  const auto r = std::to_chars(b, b + sizeof b, v);
  return std::string(b, r.ptr);
}

/// A finite number in the range `lo`..`hi` (`loOpen`: lo excluded), described by `what`.
inline std::optional<double> number(std::string_view value, double lo, bool loOpen, double hi,
                                    std::string_view what, std::string& error) {
  double v = 0.0;
  const char* end = value.data() + value.size();
  const auto r = std::from_chars(value.data(), end, v);
  const bool ok = r.ec == std::errc() && r.ptr == end && std::isfinite(v) &&
                  (loOpen ? v > lo : v >= lo) && v <= hi;
  if (ok)
    return v;
  error = coredem::format("'{}' is not allowed; expected {}", value, what);
  return std::nullopt;
}

/// The `models:` key of parameter `param` of model `M` in `family`: "<family>.<model>.<param>".
template <class M>
std::string paramKey(std::string_view family, const char* param) {
  return coredem::format("{}.{}.{}", family, M::name, param);
}

/// The range of a declared parameter as users read it, e.g. "number in (0, 1]".
template <class P>
std::string rangeText(const kernels::ModelParam<P>& p) {
  return coredem::format("number in {}{}, {}]", p.loOpen ? "(" : "[", shortest(p.lo),
                         shortest(p.hi));
}

/// True when `v` is in the declared range of `p`.
template <class P>
bool inRange(const kernels::ModelParam<P>& p, double v) {
  return std::isfinite(v) && (p.loOpen ? v > p.lo : v >= p.lo) && v <= p.hi;
}

/// One `models:` row of a declared parameter, for configurations of type Config.
template <class Config>
struct ParamRow {
  std::string key;          ///< "<family>.<model>.<parameter>"
  std::string family;       ///< the family's prefix
  std::string values;       ///< the range, e.g. "number in (0, 10]"
  std::string defaultValue; ///< the declared default (Params{})
  std::string doc;          ///< "<doc> (<units>), <model> only"
  std::string (*apply)(Config& config, std::string_view value) = nullptr; ///< "" when stored
};

/// Parser of parameter `I` of model `M` of `List` (its range from the declaration), stored in the
/// family's ParamPack of the configuration: std::invoke(Pack, config) (a pointer to the member,
/// or a function returning a reference to it).
template <class Config, class List, auto Pack, class M, std::size_t I>
std::string applyParam(Config& c, std::string_view v) {
  constexpr auto params = M::params();
  constexpr kernels::ModelParam<typename M::Params> p = params[I];
  std::string e;
  if (const auto x = number(v, p.lo, p.loOpen, p.hi,
                            coredem::format("a {} ({}, {})", rangeText(p), p.units,
                                            shortest(typename M::Params{}.*p.field)),
                            e)) {
    kernels::ParamPack<List>& pack = std::invoke(Pack, c);
    pack.template of<M>().*p.field = *x;
  }
  return e;
}

/// One row per declared parameter of every model of `List`, in id and declaration order.
template <class Config, class List, auto Pack>
std::vector<ParamRow<Config>> paramRowsOf(std::string_view family) {
  std::vector<ParamRow<Config>> rows;
  kernels::forEachModel(List{}, [&]<class M>() {
    constexpr auto params = M::params();
    [&]<std::size_t... I>(std::index_sequence<I...>) {
      (rows.push_back({paramKey<M>(family, params[I].key), std::string(family),
                       rangeText(params[I]), shortest(typename M::Params{}.*params[I].field),
                       coredem::format("{} ({}), {} only", params[I].doc, params[I].units, M::name),
                       &applyParam<Config, List, Pack, M, I>}),
       ...);
    }
    (std::make_index_sequence<params.size()>{});
  });
  return rows;
}

/// Calls f(key, value, default, param) for each declared parameter of the chosen model `id` of
/// `List` (the family's `family` prefix in the keys).
template <class List, class F>
void forChosenParams(const kernels::ParamPack<List>& pack, int id, std::string_view family, F&& f) {
  kernels::forEachModel(List{}, [&]<class M>() {
    if (kernels::modelId<M, List> != id)
      return;
    for (const auto& p : M::params())
      f(paramKey<M>(family, p.key), pack.template of<M>().*p.field, typename M::Params{}.*p.field,
        p);
  });
}

/// The hash text of the chosen model's parameters: "|<key>:<%.17g>;" for each that differs from
/// its declared default ("" when none does, so that earlier hashes stay).
template <class List>
std::string paramsHashText(const kernels::ParamPack<List>& pack, int id, std::string_view family) {
  std::string t;
  forChosenParams(pack, id, family, [&](const std::string& key, double v, double def, const auto&) {
    if (v != def)
      t += "|" + key + ":" + g17(v) + ";";
  });
  return t;
}

/// Throws coredem::UserError naming the key when a parameter of the chosen model is outside its
/// declared range.
template <class List>
void checkParams(const kernels::ParamPack<List>& pack, int id, std::string_view family) {
  forChosenParams(pack, id, family, [&](const std::string& key, double v, double, const auto& p) {
    COREDEM_CHECK(inRange(p, v), "models: {} = {} is outside its range: {}", key, v, rangeText(p));
  });
}

} // namespace coredem::dem::registry
