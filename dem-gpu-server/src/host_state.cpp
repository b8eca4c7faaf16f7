// HostState operations generated from the particle schema: shape checks, defaults, compaction.
#include <string>

#include "coredem/common/check.h"
#include "engine.h"

namespace coredem::dem {
namespace {

/// Value of a Default for particle i (Diameter: 2 R_i, needs radius).
double defaultValue(schema::Default d, const HostState& s, std::size_t i) {
  switch (d) {
  case schema::Default::Zero:
    return 0.0;
  case schema::Default::MinusOne:
    return -1.0;
  case schema::Default::Diameter:
    return 2.0 * s.radius[i];
  case schema::Default::Required:
    break;
  }
  throw InternalError("particle schema: a Required field has no default");
}

/// Sizes `v` to n · width and fills it with the field's default.
template <class T>
void assignDefault(const schema::FieldInfo& f, HostState& s, std::vector<T>& v) {
  if (f.def == schema::Default::Required) {
    throw InternalError(coredem::format("particle field '{}' ({}) has no default and was not set",
                                        f.name, f.member));
  }
  if (f.def == schema::Default::Diameter && s.radius.size() != s.n) {
    throw InternalError(
        coredem::format("particle field '{}': its default needs radius, which holds {} "
                        "values for {} particles",
                        f.name, s.radius.size(), s.n));
  }
  const std::size_t w = schema::valuesPerParticle(f, s.extents());
  v.resize(s.n * w);
  for (std::size_t i = 0; i < s.n; ++i)
    for (std::size_t k = 0; k < w; ++k)
      v[i * w + k] = static_cast<T>(defaultValue(f.def, s, i));
}

} // namespace

void checkShapes(const HostState& s, const char* where) {
  schema::forEachField(s, [&](const schema::FieldInfo& f, const auto& v) {
    if (v.size() != s.expectedSize(f)) {
      throw InternalError(
          coredem::format("{}: particle field '{}' holds {} values, expected {} ({} "
                          "particles × {} per particle)",
                          where, f.name, v.size(), s.expectedSize(f), s.n,
                          schema::valuesPerParticle(f, s.extents())));
    }
  });
}

void fillDefaults(HostState& s) {
  schema::forEachField(s, [&](const schema::FieldInfo& f, auto& v) {
    if (v.empty() && s.expectedSize(f) > 0 && f.def != schema::Default::Required)
      assignDefault(f, s, v);
  });
}

void compactParticles(HostState& s, const std::vector<std::size_t>& keep) {
  checkShapes(s, "compactParticles");
  const std::size_t n = s.n;
  for (std::size_t a = 0; a < keep.size(); ++a) {
    if (keep[a] >= n || (a > 0 && keep[a] <= keep[a - 1])) {
      throw InternalError("compactParticles: keep must be ascending particle indices");
    }
  }
  schema::forEachField(s, [&](const schema::FieldInfo& f, auto& v) {
    if (!f.has(schema::kCompacted))
      return;
    const std::size_t w = schema::valuesPerParticle(f, s.extents());
    for (std::size_t a = 0; a < keep.size(); ++a)
      for (std::size_t k = 0; k < w; ++k)
        v[a * w + k] = v[keep[a] * w + k];
    v.resize(keep.size() * w);
  });
  s.n = keep.size();
  // Fields that do not follow their particles start over from their defaults (Diameter uses
  // the compacted radius).
  schema::forEachField(s, [&](const schema::FieldInfo& f, auto& v) {
    if (!f.has(schema::kCompacted))
      assignDefault(f, s, v);
  });
  s.listValid = 0; // indices changed: rebuilt before the next force evaluation
}

} // namespace coredem::dem
