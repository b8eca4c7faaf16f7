#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <set>
#include <sstream>

#include <coredem/protocol/fields.h>
#include <coredem/protocol/validate.h>

#include "message_impl.h"

namespace coredem::protocol {

namespace {

std::string shapeString(const std::vector<std::uint64_t>& shape) {
  std::string s = "[";
  for (std::size_t i = 0; i < shape.size(); ++i) {
    if (i) {
      s += ',';
    }
    s += std::to_string(shape[i]);
  }
  return s + "]";
}

/// The body case that belongs to a message type (message_types.h).
v1::Envelope::BodyCase bodyCaseOf(v1::MessageType type) {
  const MessageTypeInfo* row = findMessageType(type);
  return row != nullptr ? row->bodyCase : v1::Envelope::BODY_NOT_SET;
}

template <class T>
Status checkFinite(const ArrayView& view) {
  const std::size_t n = view.bytes.size() / sizeof(T);
  const std::byte* p = view.bytes.data();
  for (std::size_t i = 0; i < n; ++i) {
    T v;
    std::memcpy(&v, p + i * sizeof(T), sizeof(T));
    if (!std::isfinite(v)) {
      std::string what = std::isnan(v) ? "NaN" : (v > 0 ? "+Inf" : "-Inf");
      std::string where = "flat index " + std::to_string(i);
      const auto& shape = view.descriptor->shape();
      if (shape.size() == 2 && shape[1] > 0) {
        where += " (row " + std::to_string(i / shape[1]) + ", column " +
                 std::to_string(i % shape[1]) + ")";
      }
      return Status::error(v1::ERROR_CODE_NON_FINITE,
                           "array '" + printable(view.name()) + "' contains " + what + " at " +
                               where +
                               "; every value must be finite - check the sender's solution "
                               "for divergence at that cell");
    }
  }
  return {};
}

Status checkArrays(const Message& message, std::span<const fields::FieldSpec> required,
                   std::uint64_t cells, std::uint64_t species, bool requireFinite) {
  std::set<std::string, std::less<>> seen;
  for (std::size_t i = 0; i < message.arrayCount(); ++i) {
    ArrayView v = message.array(i);
    if (!seen.insert(v.name()).second) {
      return Status::error(v1::ERROR_CODE_DUPLICATE_FIELD,
                           "array '" + printable(v.name()) + "' appears more than once in one " +
                               messageTypeName(message.type()) + " message; send it once");
    }
  }
  for (const auto& spec : required) {
    auto v = message.findArray(spec.name);
    if (!v) {
      return Status::error(v1::ERROR_CODE_MISSING_FIELD,
                           messageTypeName(message.type()) + " message lacks the required array '" +
                               std::string(spec.name) + "' (" + std::string(spec.description) +
                               ", " + std::string(spec.unit) +
                               "); send every field listed in "
                               "coredem/protocol/fields.h");
    }
    if (v->dtype() != v1::DTYPE_FLOAT64) {
      return Status::error(v1::ERROR_CODE_DTYPE,
                           "array '" + printable(v->name()) + "' has dtype " +
                               dtypeName(v->dtype()) +
                               " but coupling fields are float64; convert before sending");
    }
    auto expected = fields::shapeOf(spec.extent, cells, species);
    if (v->shape() != expected) {
      return Status::error(v1::ERROR_CODE_SHAPE,
                           "array '" + printable(v->name()) + "' has shape " +
                               shapeString(v->shape()) + " but " + shapeString(expected) +
                               " was expected for " + std::to_string(cells) +
                               " configured cells and " + std::to_string(species) +
                               " species; send one row per coupling cell of Configure");
    }
  }
  if (requireFinite) {
    for (std::size_t i = 0; i < message.arrayCount(); ++i) {
      ArrayView v = message.array(i);
      Status s;
      if (v.dtype() == v1::DTYPE_FLOAT64) {
        s = checkFinite<double>(v);
      } else if (v.dtype() == v1::DTYPE_FLOAT32) {
        s = checkFinite<float>(v);
      }
      if (!s.ok()) {
        return s;
      }
    }
  }
  return {};
}

Status structure(const Message& message) {
  const auto& impl = MessageAccess::impl(message);
  const auto& env = impl.envelope;
  if (static_cast<std::size_t>(env.arrays_size()) != impl.arrays.size()) {
    return Status::error(v1::ERROR_CODE_FRAME_COUNT,
                         "the envelope describes " + std::to_string(env.arrays_size()) +
                             " arrays but the message has " + std::to_string(impl.arrays.size()) +
                             " array frames");
  }
  for (int i = 0; i < env.arrays_size(); ++i) {
    const auto& d = env.arrays(i);
    std::size_t elem = dtypeSize(d.dtype());
    if (elem == 0) {
      return Status::error(v1::ERROR_CODE_DTYPE, "array '" + printable(d.name()) +
                                                     "' has unknown dtype " + dtypeName(d.dtype()));
    }
    std::uint64_t elements = 0;
    if (impl.arrays[static_cast<std::size_t>(i)].size != d.byte_length() ||
        !shapeElements(d.shape(), &elements) || elements * elem != d.byte_length()) {
      return Status::error(v1::ERROR_CODE_BYTE_LENGTH,
                           "array '" + printable(d.name()) +
                               "': frame size, byte_length and prod(shape)*sizeof(dtype) "
                               "disagree");
    }
  }
  return {};
}

/// The partial-message arrays (v1.2): touched_count <= cells, "cells" int64 [M] strictly
/// ascending and < cells, and for GasFields "fluid_volume" float64 [M].
Status checkPartial(const Message& message, std::uint64_t rows, std::uint64_t cells) {
  const std::string what = "partial " + messageTypeName(message.type());
  if (rows > cells) {
    return Status::error(v1::ERROR_CODE_SHAPE, what + " lists " + std::to_string(rows) +
                                                   " coupling cells but the grid has " +
                                                   std::to_string(cells));
  }
  const auto idx = message.findArray(fields::kTouchedCells);
  if (!idx) {
    return Status::error(v1::ERROR_CODE_MISSING_FIELD,
                         what + " lacks the array 'cells' (int64, the coupling cells it lists)");
  }
  const std::vector<std::uint64_t> shape{rows};
  if (idx->dtype() != v1::DTYPE_INT64 || idx->shape() != shape) {
    return Status::error(v1::ERROR_CODE_SHAPE,
                         what + ": array 'cells' has dtype " + dtypeName(idx->dtype()) +
                             " and shape " + shapeString(idx->shape()) + " but int64 " +
                             shapeString(shape) + " (touched_count) was expected");
  }
  const auto v = idx->as<std::int64_t>();
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (v[i] < 0 || static_cast<std::uint64_t>(v[i]) >= cells) {
      return Status::error(v1::ERROR_CODE_SHAPE,
                           what + ": cells[" + std::to_string(i) + "] = " + std::to_string(v[i]) +
                               " is not a coupling cell (0.." + std::to_string(cells - 1) + ")");
    }
    if (i > 0 && v[i] <= v[i - 1]) {
      return Status::error(v1::ERROR_CODE_DUPLICATE_FIELD,
                           what + ": cells[" + std::to_string(i) + "] = " + std::to_string(v[i]) +
                               (v[i] == v[i - 1] ? " is listed twice" : " is out of order") +
                               "; list each coupling cell once, ascending");
    }
  }
  if (message.type() == v1::MESSAGE_TYPE_GAS_FIELDS) {
    const auto fv = message.findArray(fields::kFluidVolume);
    if (!fv) {
      return Status::error(v1::ERROR_CODE_MISSING_FIELD,
                           what + " lacks the array 'fluid_volume' (float64, m3 per listed cell)");
    }
    if (fv->dtype() != v1::DTYPE_FLOAT64 || fv->shape() != shape) {
      return Status::error(v1::ERROR_CODE_SHAPE, what + ": array 'fluid_volume' has dtype " +
                                                     dtypeName(fv->dtype()) + " and shape " +
                                                     shapeString(fv->shape()) + " but float64 " +
                                                     shapeString(shape) + " was expected");
    }
  }
  return {};
}

} // namespace

std::uint64_t cellCount(const v1::CouplingMesh& mesh) {
  if (mesh.kind_case() != v1::CouplingMesh::kCartesian) {
    return 0;
  }
  const auto& c = mesh.cartesian().counts();
  std::uint64_t xy = 0, xyz = 0;
  if (__builtin_mul_overflow(static_cast<std::uint64_t>(c.x()), c.y(), &xy) ||
      __builtin_mul_overflow(xy, static_cast<std::uint64_t>(c.z()), &xyz)) {
    return std::numeric_limits<std::uint64_t>::max();
  }
  return xyz;
}

namespace {

/// The envelope against the expectation: a known type with its body, expected now, of this
/// session, in sequence and of the expected step.
Status checkEnvelope(const Message& message, const Expectation& e) {
  const auto& env = message.envelope();
  const v1::MessageType type = env.type();
  if (!v1::MessageType_IsValid(type) || type == v1::MESSAGE_TYPE_UNSPECIFIED) {
    return Status::error(v1::ERROR_CODE_UNKNOWN_TYPE,
                         "message type " + std::to_string(static_cast<int>(type)) +
                             " is not known to coredem protocol v1 (this build knows 1.." +
                             std::to_string(static_cast<int>(v1::MessageType_MAX)) +
                             "); the sender may speak a newer version - check the Hello "
                             "negotiation");
  }
  if (env.body_case() != bodyCaseOf(type)) {
    return Status::error(v1::ERROR_CODE_BODY_MISMATCH,
                         "Envelope.type is " + messageTypeName(type) +
                             " but the body carries another message (oneof case " +
                             std::to_string(static_cast<int>(env.body_case())) +
                             "); set the body that matches the type");
  }
  if (!e.types.empty() && std::find(e.types.begin(), e.types.end(), type) == e.types.end()) {
    std::string allowed;
    for (auto t : e.types) {
      if (!allowed.empty()) {
        allowed += ", ";
      }
      allowed += messageTypeName(t);
    }
    return Status::error(v1::ERROR_CODE_UNEXPECTED_MESSAGE,
                         "a " + messageTypeName(type) + " message is not expected now; expected " +
                             allowed);
  }
  if (e.sessionId && env.session_id() != *e.sessionId) {
    return Status::error(v1::ERROR_CODE_UNKNOWN_SESSION,
                         "session id '" + printable(env.session_id()) +
                             "' does not match this session ('" + *e.sessionId +
                             "'); use the session_id of the Welcome reply");
  }
  if (e.sequence && env.sequence() != *e.sequence) {
    return Status::error(v1::ERROR_CODE_OUT_OF_ORDER,
                         "sequence number " + std::to_string(env.sequence()) + " received, " +
                             std::to_string(*e.sequence) + " expected");
  }
  if (e.sequenceAfter && env.sequence() <= *e.sequenceAfter) {
    return Status::error(v1::ERROR_CODE_OUT_OF_ORDER,
                         "sequence number " + std::to_string(env.sequence()) +
                             " is not greater than the last one received (" +
                             std::to_string(*e.sequenceAfter) +
                             "); a message was duplicated or replayed");
  }
  if (e.step && env.step() != *e.step) {
    return Status::error(v1::ERROR_CODE_OUT_OF_ORDER,
                         messageTypeName(type) + " for step " + std::to_string(env.step()) +
                             " received, step " + std::to_string(*e.step) +
                             " expected; steps are exchanged in order, one per CFD step");
  }
  return Status::success();
}

/// A GasFields or Sources message: declared on the configured mesh, its arrays (those of the
/// listed cells of a partial one) and, of a partial GasFields, the fluid volumes.
Status checkFields(const Message& message, const Expectation& e) {
  const auto& env = message.envelope();
  const v1::MessageType type = env.type();
  if (!e.cells || !e.species) {
    return Status::error(v1::ERROR_CODE_NOT_CONFIGURED,
                         messageTypeName(type) +
                             " received before Configure; send Hello and Configure first");
  }
  std::uint64_t bodyCells = type == v1::MESSAGE_TYPE_GAS_FIELDS ? env.gas_fields().cell_count()
                                                                : env.sources().cell_count();
  std::uint64_t bodySpecies = type == v1::MESSAGE_TYPE_GAS_FIELDS ? env.gas_fields().species_count()
                                                                  : env.sources().species_count();
  if (bodyCells != *e.cells || bodySpecies != *e.species) {
    return Status::error(v1::ERROR_CODE_SHAPE,
                         messageTypeName(type) + " declares " + std::to_string(bodyCells) +
                             " cells and " + std::to_string(bodySpecies) +
                             " species but the configured mesh has " + std::to_string(*e.cells) +
                             " cells and " + std::to_string(*e.species) +
                             " species; send fields on the configured coupling mesh");
  }
  const bool partial =
      type == v1::MESSAGE_TYPE_GAS_FIELDS ? env.gas_fields().partial() : env.sources().partial();
  std::uint64_t rows = *e.cells;
  if (partial) {
    rows = type == v1::MESSAGE_TYPE_GAS_FIELDS ? env.gas_fields().touched_count()
                                               : env.sources().touched_count();
    if (Status p = checkPartial(message, rows, *e.cells); !p.ok()) {
      return p;
    }
  }
  auto required =
      type == v1::MESSAGE_TYPE_GAS_FIELDS ? fields::gasFields() : fields::sourceFields();
  Status st = checkArrays(message, required, rows, *e.species, e.requireFinite);
  if (!st.ok()) {
    return st;
  }
  if (type == v1::MESSAGE_TYPE_GAS_FIELDS && partial) {
    // The fluid volumes: positive (finite was checked above).
    const auto fv = message.values<double>(fields::kFluidVolume);
    for (std::size_t i = 0; i < fv.size(); ++i) {
      if (!(fv[i] > 0.0)) {
        return Status::error(v1::ERROR_CODE_INVALID_CONFIGURATION,
                             "partial GasFields: fluid_volume[" + std::to_string(i) +
                                 "] = " + std::to_string(fv[i]) +
                                 " m3; list only coupling cells the rank's cells overlap "
                                 "(fluid volume > 0)");
      }
    }
  }
  // Optional arrays (Sources: v1.3 Q_rad, v1.5 mom_p; GasFields: fluid_fraction, v1.5 Q_split):
  // when present, float64 with one row per cell (or listed cell of a partial message);
  // finiteness was checked with every array above.
  const auto optional = type == v1::MESSAGE_TYPE_SOURCES ? fields::optionalSourceFields()
                                                         : fields::optionalGasFields();
  for (const auto& spec : optional) {
    const auto v = message.findArray(spec.name);
    if (!v) {
      continue;
    }
    if (partial && spec.name == fields::kFluidFraction) {
      return Status::error(v1::ERROR_CODE_INVALID_CONFIGURATION,
                           "partial GasFields carry fluid_volume; fluid_fraction is formed by "
                           "the DEM server from the ranks' fluid volumes, do not send it");
    }
    const auto expected = fields::shapeOf(spec.extent, rows, *e.species);
    if (v->dtype() != v1::DTYPE_FLOAT64 || v->shape() != expected) {
      return Status::error(v1::ERROR_CODE_SHAPE,
                           "array '" + std::string(spec.name) + "' has dtype " +
                               dtypeName(v->dtype()) + " and shape " + shapeString(v->shape()) +
                               " but float64 " + shapeString(expected) + " was expected for " +
                               std::to_string(rows) + (partial ? " listed" : " configured") +
                               " cells");
    }
  }
  return st;
}

} // namespace

Status validate(const Message& message, const Expectation& e) {
  if (Status s = structure(message); !s.ok()) {
    return s;
  }
  if (Status s = checkEnvelope(message, e); !s.ok()) {
    return s;
  }
  const v1::MessageType type = message.envelope().type();
  if (type == v1::MESSAGE_TYPE_GAS_FIELDS || type == v1::MESSAGE_TYPE_SOURCES) {
    return checkFields(message, e);
  }
  return checkArrays(message, {}, 0, 0, e.requireFinite);
}

namespace {

std::string num(double v) {
  std::ostringstream os;
  os.precision(6);
  os << v;
  return os.str();
}

Status outOfRange(std::string_view array, std::size_t cell, const std::string& what, double value,
                  double lo, double hi, std::string_view unit) {
  return Status::error(v1::ERROR_CODE_INVALID_CONFIGURATION,
                       "GasFields array '" + std::string(array) + "' cell " + std::to_string(cell) +
                           ": " + what + " = " + num(value) + " " + std::string(unit) +
                           " is outside the range [" + num(lo) + ", " + num(hi) + "] " +
                           std::string(unit) +
                           " (docs/protocol.md §3 'Ranges'); check the sender's units and "
                           "solution");
}

} // namespace

Status validateGasRanges(const Message& m, const GasRanges& r) {
  namespace f = fields;
  struct Scalar {
    std::string_view name;
    double lo, hi;
    std::string_view unit;
  };
  const Scalar scalars[] = {
      {f::kGasTemperature, r.temperatureMin, r.temperatureMax, "K"},
      {f::kGasDensity, r.densityMin, r.densityMax, "kg/m3"},
      {f::kGasViscosity, r.viscosityMin, r.viscosityMax, "Pa s"},
      {f::kGasConductivity, r.conductivityMin, r.conductivityMax, "W/m/K"},
      {f::kGasHeatCapacity, r.heatCapacityMin, r.heatCapacityMax, "J/kg/K"},
  };
  for (const Scalar& s : scalars) {
    const auto v = m.values<double>(s.name);
    for (std::size_t c = 0; c < v.size(); ++c) {
      if (!(v[c] >= s.lo && v[c] <= s.hi)) {
        return outOfRange(s.name, c, std::string(s.name), v[c], s.lo, s.hi, s.unit);
      }
    }
  }
  const auto magnitudes = [&](std::string_view name, double hi, std::string_view unit) -> Status {
    const auto v = m.values<double>(name);
    for (std::size_t c = 0; 3 * c + 2 < v.size(); ++c) {
      const double mag = std::hypot(v[3 * c], v[3 * c + 1], v[3 * c + 2]);
      if (!(mag <= hi)) {
        return outOfRange(name, c, std::string("|").append(name).append("|"), mag, 0.0, hi, unit);
      }
    }
    return {};
  };
  if (Status s = magnitudes(f::kGasVelocity, r.speedMax, "m/s"); !s.ok()) {
    return s;
  }
  if (Status s = magnitudes(f::kPressureGradient, r.pressureGradientMax, "Pa/m"); !s.ok()) {
    return s;
  }
  if (const auto ff = m.findArray(f::kFluidFraction); ff && ff->dtype() == v1::DTYPE_FLOAT64) {
    const auto v = ff->as<double>();
    for (std::size_t c = 0; c < v.size(); ++c) {
      if (!(v[c] >= 0.0 && v[c] <= 1.0)) {
        return outOfRange(f::kFluidFraction, c, std::string(f::kFluidFraction), v[c], 0.0, 1.0, "");
      }
    }
  }
  const auto& body = m.envelope().gas_fields();
  const std::size_t ns = body.species_count();
  const auto y = m.values<double>(f::kGasMassFractions);
  if (ns > 0 && y.size() == ns * body.cell_count()) {
    const double t = r.massFractionTolerance;
    for (std::size_t c = 0; c < body.cell_count(); ++c) {
      double sum = 0.0;
      for (std::size_t k = 0; k < ns; ++k) {
        const double v = y[c * ns + k];
        if (!(v >= -t && v <= 1.0 + t)) {
          return outOfRange(f::kGasMassFractions, c, "Y of species " + std::to_string(k), v, -t,
                            1.0 + t, "");
        }
        sum += v;
      }
      if (!(std::abs(sum - 1.0) <= r.massFractionSumTolerance)) {
        return outOfRange(f::kGasMassFractions, c, "sum of Y", sum,
                          1.0 - r.massFractionSumTolerance, 1.0 + r.massFractionSumTolerance, "");
      }
    }
  }
  return {};
}

namespace {
bool positive(const v1::Vec3& v) {
  return v.x() > 0 && v.y() > 0 && v.z() > 0;
}
bool finite3(const v1::Vec3& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z());
}
Status bad(const std::string& msg) {
  return Status::error(v1::ERROR_CODE_INVALID_CONFIGURATION, "Configure: " + msg);
}

/// coupling_mesh: a Cartesian grid of at most kMaxCells cells with a finite spacing > 0.
Status checkMesh(const v1::Configure& c) {
  if (c.coupling_mesh().kind_case() != v1::CouplingMesh::kCartesian) {
    return bad("coupling_mesh must be a CartesianGrid (the only mesh kind of protocol 1.0)");
  }
  const auto& g = c.coupling_mesh().cartesian();
  if (g.counts().x() == 0 || g.counts().y() == 0 || g.counts().z() == 0) {
    return bad("coupling_mesh.cartesian.counts must be >= 1 on every axis");
  }
  if (const std::uint64_t cells = cellCount(c.coupling_mesh()); cells > kMaxCells) {
    return bad("coupling_mesh.cartesian.counts " + std::to_string(g.counts().x()) + " x " +
               std::to_string(g.counts().y()) + " x " + std::to_string(g.counts().z()) + " = " +
               (cells == std::numeric_limits<std::uint64_t>::max() ? std::string("(overflow)")
                                                                   : std::to_string(cells)) +
               " cells exceeds the protocol limit of " + std::to_string(kMaxCells) + " cells");
  }
  if (!positive(g.spacing()) || !finite3(g.spacing()) || !finite3(g.origin())) {
    return bad("coupling_mesh.cartesian.spacing must be finite and > 0 on every axis");
  }
  return {};
}

/// Gas and solid species: unique names, molar masses > 0 (v1.1 chemistry: solid species).
Status checkSpecies(const v1::Configure& c) {
  std::set<std::string> names;
  for (const auto& s : c.species()) {
    if (s.name().empty() || !names.insert(s.name()).second) {
      return bad("species name '" + printable(s.name()) +
                 "' is empty or repeated; names must be unique");
    }
    if (!(s.molar_mass() > 0) || !std::isfinite(s.molar_mass())) {
      return bad("species '" + printable(s.name()) + "' has molar_mass " +
                 std::to_string(s.molar_mass()) + " kg/mol; it must be > 0 (e.g. 0.044 for CO2)");
    }
  }
  // v1.1 chemistry: solid species, unique among the gas species too.
  for (const auto& s : c.solid_species()) {
    if (s.name().empty() || !names.insert(s.name()).second) {
      return bad("solid_species name '" + printable(s.name()) +
                 "' is empty or repeated (also among the gas "
                 "species); names must be unique");
    }
    if (!(s.molar_mass() > 0) || !std::isfinite(s.molar_mass())) {
      return bad("solid_species '" + printable(s.name()) + "' has molar_mass " +
                 std::to_string(s.molar_mass()) + " kg/mol; it must be > 0");
    }
  }
  return {};
}

/// v1.1 chemistry: the reactions' terms and rate laws, the removal fraction (the DEM server
/// checks the species references and the models' needs when it builds the system).
Status checkReactions(const v1::Configure& c) {
  for (const auto& r : c.reactions()) {
    if (r.terms_size() < 1 || r.terms_size() > 6) {
      return bad("reaction '" + printable(r.name()) + "' has " + std::to_string(r.terms_size()) +
                 " terms; give 1 to 6");
    }
    for (const auto& t : r.terms()) {
      if (!(t.nu() != 0.0) || !std::isfinite(t.nu())) {
        return bad("reaction '" + printable(r.name()) + "': term '" + printable(t.species()) +
                   "' needs a finite nonzero nu");
      }
    }
    if (r.rate().law() != v1::RATE_LAW_CONSTANT && r.rate().law() != v1::RATE_LAW_ARRHENIUS) {
      return bad("reaction '" + printable(r.name()) +
                 "': rate.law must be RATE_LAW_CONSTANT or RATE_LAW_ARRHENIUS");
    }
    if (!(r.rate().a() >= 0.0) || !std::isfinite(r.rate().a()) || !std::isfinite(r.rate().beta()) ||
        !(r.rate().activation_energy() >= 0.0) || !std::isfinite(r.rate().activation_energy()) ||
        !std::isfinite(r.rate().order())) {
      return bad("reaction '" + printable(r.name()) +
                 "': rate needs finite a >= 0, beta, activation_energy >= 0, order");
    }
    if (r.heat_case() == v1::Reaction::kHeatOfReaction && !std::isfinite(r.heat_of_reaction())) {
      return bad("reaction '" + printable(r.name()) + "': heat_of_reaction is not finite");
    }
  }
  if (c.has_chemistry() && c.chemistry().has_removal_fraction() &&
      !(c.chemistry().removal_fraction() > 0.0 && c.chemistry().removal_fraction() < 1.0)) {
    return bad("chemistry.removal_fraction = " + std::to_string(c.chemistry().removal_fraction()) +
               " must be in (0, 1)");
  }
  return {};
}

/// sub_cycling: dt_cfd > 0, n_sub >= 1, dt_dem > 0 and dt_dem * n_sub = dt_cfd.
Status checkSubCycling(const v1::Configure& c) {
  const auto& sc = c.sub_cycling();
  if (!(sc.dt_cfd() > 0) || sc.n_sub() == 0 || !(sc.dt_dem() > 0)) {
    return bad("sub_cycling needs dt_cfd > 0, n_sub >= 1 and dt_dem > 0");
  }
  if (std::abs(sc.dt_dem() * sc.n_sub() - sc.dt_cfd()) > 1e-12 * sc.dt_cfd()) {
    std::ostringstream os;
    os.precision(17);
    os << "sub_cycling: dt_dem * n_sub = " << sc.dt_dem() * sc.n_sub()
       << " s differs from dt_cfd = " << sc.dt_cfd()
       << " s (relative tolerance 1e-12); set dt_dem = dt_cfd / n_sub";
    return bad(os.str());
  }
  return {};
}

/// Materials: unique ids (collected in materialIds) and valid contact parameters.
Status checkMaterials(const v1::Configure& c, std::set<std::uint32_t>& materialIds) {
  for (const auto& m : c.materials()) {
    if (!materialIds.insert(m.id()).second) {
      return bad("material id " + std::to_string(m.id()) + " is used twice");
    }
    // k_n: 0 = not given (v1.6: a hertz-mindlin material; the DEM refuses it for the linear
    // spring-dashpot law, naming the law).
    if (!(m.density() > 0) || !(m.k_n() >= 0) || !(m.e_n() > 0 && m.e_n() <= 1) ||
        !(m.friction() >= 0) || (m.has_kt_factor() && !(m.kt_factor() > 0)) ||
        (m.has_etat_factor() && !(m.etat_factor() >= 0)) ||
        (m.has_youngs_modulus() &&
         !(m.youngs_modulus() > 0 && std::isfinite(m.youngs_modulus()))) ||
        (m.has_poisson_ratio() && !(m.poisson_ratio() > -1 && m.poisson_ratio() < 0.5))) {
      return bad("material " + std::to_string(m.id()) + " ('" + printable(m.name()) +
                 "') needs density > 0, k_n >= 0, 0 < e_n <= 1, friction >= 0, kt_factor > 0, "
                 "etat_factor >= 0, youngs_modulus > 0, -1 < poisson_ratio < 0.5");
    }
  }
  return {};
}

/// v1.6: material pairs and the walls' contact materials name known materials, valid values.
Status checkContactMaterials(const v1::Configure& c, const std::set<std::uint32_t>& materialIds) {
  for (int i = 0; i < c.material_pairs_size(); ++i) {
    const auto& p = c.material_pairs(i);
    const std::string which = "material_pairs[" + std::to_string(i) + "]";
    if (!materialIds.count(p.material_a()) || !materialIds.count(p.material_b())) {
      return bad(which + " refers to a material id that is not among materials");
    }
    if ((p.has_e_n() && !(p.e_n() > 0 && p.e_n() <= 1)) ||
        (p.has_friction() && !(p.friction() >= 0 && std::isfinite(p.friction())))) {
      return bad(which + " needs 0 < e_n <= 1, friction >= 0");
    }
  }
  const auto wall = [&](bool has, std::uint32_t id, const std::string& which) -> Status {
    if (has && !materialIds.count(id)) {
      return bad(which + " has material_id " + std::to_string(id) +
                 ", which is not among materials");
    }
    return {};
  };
  const auto& w = c.walls();
  if (Status s = wall(w.box().has_material_id(), w.box().material_id(), "walls.box"); !s.ok()) {
    return s;
  }
  for (int i = 0; i < w.planes_size(); ++i) {
    const auto& p = w.planes(i);
    if (Status s =
            wall(p.has_material_id(), p.material_id(), "walls.planes[" + std::to_string(i) + "]");
        !s.ok()) {
      return s;
    }
  }
  for (int i = 0; i < w.revolved_size(); ++i) {
    const auto& r = w.revolved(i);
    if (Status s =
            wall(r.has_material_id(), r.material_id(), "walls.revolved[" + std::to_string(i) + "]");
        !s.ok()) {
      return s;
    }
  }
  for (int i = 0; i < w.meshes_size(); ++i) {
    const auto& m = w.meshes(i);
    if (Status s =
            wall(m.has_material_id(), m.material_id(), "walls.meshes[" + std::to_string(i) + "]");
        !s.ok()) {
      return s;
    }
  }
  return {};
}

/// Particle sets (of a case without initial_state_file): a known material, valid sizes,
/// packing and composition.
Status checkParticleSets(const v1::Configure& c, const std::set<std::uint32_t>& materialIds) {
  for (int i = 0; i < c.particle_sets_size(); ++i) {
    const auto& p = c.particle_sets(i);
    std::string which = "particle_sets[" + std::to_string(i) + "]";
    if (!materialIds.count(p.material_id())) {
      return bad(which + " refers to material " + std::to_string(p.material_id()) +
                 ", which is not among materials");
    }
    if (p.count() == 0 || !(p.diameter() > 0) || p.density() < 0 || !(p.temperature() > 0)) {
      return bad(which + " needs count >= 1, diameter > 0, density >= 0 (0 = material's) "
                         "and temperature > 0 K");
    }
    if (p.packing() == v1::PACKING_EXPLICIT) {
      if (static_cast<std::uint64_t>(p.positions_size()) != p.count()) {
        return bad(which + " explicit packing needs one position per particle (count " +
                   std::to_string(p.count()) + ", positions " + std::to_string(p.positions_size()) +
                   ")");
      }
    } else if (!(p.region_min().x() < p.region_max().x() &&
                 p.region_min().y() < p.region_max().y() &&
                 p.region_min().z() < p.region_max().z())) {
      return bad(which + " region_min must be below region_max on every axis");
    }
    if (p.packing() == v1::PACKING_UNSPECIFIED) {
      return bad(which + " packing must be LATTICE, RANDOM or EXPLICIT");
    }
    if (p.composition_size() > 0) {
      double sum = 0;
      for (const auto& nv : p.composition()) {
        if (!(nv.value() >= 0)) {
          return bad(which + " composition '" + printable(nv.name()) + "' is negative");
        }
        sum += nv.value();
      }
      if (std::abs(sum - 1.0) > 1e-9) {
        return bad(which + " composition mass fractions sum to " + std::to_string(sum) +
                   "; they must sum to 1 (tolerance 1e-9)");
      }
    }
  }
  return {};
}

/// Walls: box, planes and (v1.4) cylinders, cones and meshes.
Status checkWalls(const v1::Configure& c) {
  if (c.walls().has_box()) {
    const auto& b = c.walls().box();
    if (!(b.min().x() < b.max().x() && b.min().y() < b.max().y() && b.min().z() < b.max().z())) {
      return bad("walls.box min must be below max on every axis");
    }
  }
  for (const auto& p : c.walls().planes()) {
    const auto& n = p.normal();
    if (n.x() == 0 && n.y() == 0 && n.z() == 0) {
      return bad("a wall plane has a zero normal");
    }
  }
  // v1.4: cylinders, cones and meshes (the DEM server checks their geometry when it builds the
  // system; here the structure a reader relies on).
  for (int i = 0; i < c.walls().revolved_size(); ++i) {
    const auto& r = c.walls().revolved(i);
    const std::string which = "walls.revolved[" + std::to_string(i) + "]";
    if (!finite3(r.point()) || !finite3(r.axis()) ||
        (r.axis().x() == 0 && r.axis().y() == 0 && r.axis().z() == 0)) {
      return bad(which + " needs a finite point and a finite nonzero axis");
    }
    if (!(r.radius_start() >= 0) || !(r.radius_end() >= 0) || !std::isfinite(r.radius_start()) ||
        !std::isfinite(r.radius_end())) {
      return bad(which + " needs finite radii >= 0");
    }
    if (r.infinite()
            ? r.cone()
            : !(std::isfinite(r.start()) && std::isfinite(r.end()) && r.start() < r.end())) {
      return bad(which + (r.cone() ? " (a cone) needs a finite extent start < end"
                                   : " needs start < end, both finite, or infinite = true"));
    }
  }
  for (int i = 0; i < c.walls().meshes_size(); ++i) {
    const auto& m = c.walls().meshes(i);
    const std::string which =
        "walls.meshes[" + std::to_string(i) + "] ('" + printable(m.name()) + "')";
    if (m.vertices_size() == 0 || m.vertices_size() % 3 != 0 || m.triangles_size() == 0 ||
        m.triangles_size() % 3 != 0) {
      return bad(which + " needs vertices as x,y,z triples and triangles as index triples (" +
                 std::to_string(m.vertices_size()) + " vertex values, " +
                 std::to_string(m.triangles_size()) + " index values)");
    }
    const std::int64_t nv = m.vertices_size() / 3;
    for (int t = 0; t < m.triangles_size(); ++t) {
      if (m.triangles(t) < 0 || m.triangles(t) >= nv) {
        return bad(which + " triangle " + std::to_string(t / 3) + " names vertex " +
                   std::to_string(m.triangles(t)) + ", not one of its " + std::to_string(nv) +
                   " vertices");
      }
    }
  }
  return {};
}

} // namespace

Status validateConfigure(const v1::Configure& c) {
  if (Status s = checkMesh(c); !s.ok()) {
    return s;
  }
  if (Status s = checkSpecies(c); !s.ok()) {
    return s;
  }
  if (Status s = checkReactions(c); !s.ok()) {
    return s;
  }
  if (Status s = checkSubCycling(c); !s.ok()) {
    return s;
  }
  std::set<std::uint32_t> materialIds;
  if (Status s = checkMaterials(c, materialIds); !s.ok()) {
    return s;
  }
  if (Status s = checkContactMaterials(c, materialIds); !s.ok()) {
    return s;
  }
  if (c.initial_state_file().empty()) {
    if (Status s = checkParticleSets(c, materialIds); !s.ok()) {
      return s;
    }
  }
  return checkWalls(c);
}

} // namespace coredem::protocol
