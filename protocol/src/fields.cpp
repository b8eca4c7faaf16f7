#include <array>

#include <coredem/common/check.h>
#include <coredem/protocol/fields.h>

namespace coredem::protocol::fields {

namespace {
constexpr std::array<FieldSpec, 8> kGasFields{{
    {kGasVelocity, v1::EXTENT_VECTOR3, "m/s", "gas velocity (interstitial)"},
    {kPressureGradient, v1::EXTENT_VECTOR3, "Pa/m", "gas pressure gradient"},
    {kGasTemperature, v1::EXTENT_SCALAR, "K", "gas temperature"},
    {kGasDensity, v1::EXTENT_SCALAR, "kg/m3", "gas density"},
    {kGasViscosity, v1::EXTENT_SCALAR, "Pa s", "gas dynamic viscosity"},
    {kGasConductivity, v1::EXTENT_SCALAR, "W/m/K", "gas thermal conductivity"},
    {kGasHeatCapacity, v1::EXTENT_SCALAR, "J/kg/K", "gas specific heat capacity"},
    {kGasMassFractions, v1::EXTENT_SPECIES, "-", "gas species mass fractions"},
}};

constexpr std::array<FieldSpec, 2> kOptionalGasFields{{
    {kFluidFraction, v1::EXTENT_SCALAR, "-", "fluid fraction of the coupling cell's volume"},
    {kHeatToParticles, v1::EXTENT_SCALAR, "J/m3",
     "heat the gas removed beyond what the DEM booked, for the cell's particles (extensive)"},
}};

constexpr std::array<FieldSpec, 7> kSourceFields{{
    {kVoidFraction, v1::EXTENT_SCALAR, "-", "gas volume fraction eps_g"},
    {kDragCoefficient, v1::EXTENT_SCALAR, "kg/m3/s", "implicit drag coefficient K_sl"},
    {kDragCoefficientTimesUs, v1::EXTENT_VECTOR3, "N/m3", "K_sl times mean particle velocity"},
    {kHeatCoefficient, v1::EXTENT_SCALAR, "W/m3/K", "implicit gas-particle heat coefficient"},
    {kHeatCoefficientTimesTp, v1::EXTENT_SCALAR, "W/m3", "H times mean particle temperature"},
    {kSpeciesSources, v1::EXTENT_SPECIES, "kg/m3/s", "gas species mass sources"},
    {kHomogeneousHeat, v1::EXTENT_SCALAR, "W/m3", "homogeneous reaction heat release"},
}};

constexpr std::array<FieldSpec, 2> kOptionalSourceFields{{
    {kRadiationHeat, v1::EXTENT_SCALAR, "W/m3", "radiation heat the particles gave the gas"},
    {kReleasedMomentum, v1::EXTENT_VECTOR3, "N/m3",
     "momentum of the mass the particles give the gas (released mass rate times u_p)"},
}};
} // namespace

std::span<const FieldSpec> gasFields() {
  return kGasFields;
}
std::span<const FieldSpec> optionalGasFields() {
  return kOptionalGasFields;
}
std::span<const FieldSpec> sourceFields() {
  return kSourceFields;
}
std::span<const FieldSpec> optionalSourceFields() {
  return kOptionalSourceFields;
}

const FieldSpec* findField(std::string_view name) {
  for (const auto& f : kGasFields) {
    if (f.name == name) {
      return &f;
    }
  }
  for (const auto& f : kOptionalGasFields) {
    if (f.name == name) {
      return &f;
    }
  }
  for (const auto& f : kSourceFields) {
    if (f.name == name) {
      return &f;
    }
  }
  for (const auto& f : kOptionalSourceFields) {
    if (f.name == name) {
      return &f;
    }
  }
  return nullptr;
}

std::uint64_t componentsOf(v1::Extent extent, std::uint64_t species) {
  switch (extent) {
  case v1::EXTENT_SCALAR:
    return 1;
  case v1::EXTENT_VECTOR3:
    return 3;
  case v1::EXTENT_SPECIES:
    return species;
  default:
    throw UserError("unknown field extent " + std::to_string(static_cast<int>(extent)));
  }
}

std::vector<std::uint64_t> shapeOf(v1::Extent extent, std::uint64_t cells, std::uint64_t species) {
  if (extent == v1::EXTENT_SCALAR) {
    return {cells};
  }
  return {cells, componentsOf(extent, species)};
}

std::vector<std::uint64_t> shapeOf(std::string_view name, std::uint64_t cells,
                                   std::uint64_t species) {
  const FieldSpec* spec = findField(name);
  COREDEM_CHECK(spec != nullptr,
                "'{}' is not a coupling field; see coredem/protocol/fields.h for the names", name);
  return shapeOf(spec->extent, cells, species);
}

} // namespace coredem::protocol::fields
