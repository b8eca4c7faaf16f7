#include "coupling_fields.h"

#include <array>

#include "coredem/common/check.h"

namespace coredem::server {

namespace f = coredem::protocol::fields;

namespace {

struct GasBinding {
  std::string_view name;
  std::span<const double> dem::GasFieldsView::*member;
};

constexpr std::array<GasBinding, 10> kGasBindings{{
    {f::kGasVelocity, &dem::GasFieldsView::ug},
    {f::kPressureGradient, &dem::GasFieldsView::gradP},
    {f::kGasTemperature, &dem::GasFieldsView::Tg},
    {f::kGasDensity, &dem::GasFieldsView::rhoG},
    {f::kGasViscosity, &dem::GasFieldsView::muG},
    {f::kGasConductivity, &dem::GasFieldsView::kappaG},
    {f::kGasHeatCapacity, &dem::GasFieldsView::cpG},
    {f::kGasMassFractions, &dem::GasFieldsView::Yg},
    {f::kFluidFraction, &dem::GasFieldsView::fluidFraction},
    {f::kHeatToParticles, &dem::GasFieldsView::heatToParticles},
}};

struct SourceBinding {
  std::string_view name;
  std::vector<double> dem::CellSources::*member;
};

constexpr std::array<SourceBinding, 9> kSourceBindings{{
    {f::kVoidFraction, &dem::CellSources::epsG},
    {f::kDragCoefficient, &dem::CellSources::kSl},
    {f::kDragCoefficientTimesUs, &dem::CellSources::kSlUs},
    {f::kHeatCoefficient, &dem::CellSources::heatH},
    {f::kHeatCoefficientTimesTp, &dem::CellSources::heatHTp},
    {f::kSpeciesSources, &dem::CellSources::rSpecies},
    {f::kHomogeneousHeat, &dem::CellSources::qHom},
    {f::kRadiationHeat, &dem::CellSources::qRad},
    {f::kReleasedMomentum, &dem::CellSources::momP},
}};

std::span<const double> dem::GasFieldsView::*boundGasMember(std::string_view name) {
  const auto member = gasFieldMember(name);
  if (member == nullptr) { // a row added to the field table without its member here
    throw InternalError(fmt::format(
        "GasFields field '{}' has no dem::GasFieldsView member (coupling_fields.cpp)", name));
  }
  return member;
}

} // namespace

std::span<const double> dem::GasFieldsView::*gasFieldMember(std::string_view name) {
  for (const GasBinding& b : kGasBindings) {
    if (b.name == name) {
      return b.member;
    }
  }
  return nullptr;
}

std::vector<double> dem::CellSources::*sourceFieldMember(std::string_view name) {
  for (const SourceBinding& b : kSourceBindings) {
    if (b.name == name) {
      return b.member;
    }
  }
  return nullptr;
}

dem::GasFieldsView gasFieldsView(const protocol::Message& gas) {
  dem::GasFieldsView view;
  for (const f::FieldSpec& spec : f::gasFields()) {
    view.*boundGasMember(spec.name) = gas.values<double>(spec.name);
  }
  for (const f::FieldSpec& spec : f::optionalGasFields()) {
    if (const auto array = gas.findArray(spec.name)) {
      view.*boundGasMember(spec.name) = array->as<double>();
    }
  }
  return view;
}

const std::vector<double>& sourceValues(const dem::CellSources& s, std::string_view name) {
  const auto member = sourceFieldMember(name);
  if (member == nullptr) {
    throw InternalError(fmt::format(
        "Sources field '{}' has no dem::CellSources member (coupling_fields.cpp)", name));
  }
  return s.*member;
}

} // namespace coredem::server
