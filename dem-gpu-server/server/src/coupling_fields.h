#pragma once
// The coupling arrays of the DEM server bound to the DEM core's structures by the field table of
// protocol/src/fields.cpp (fields::gasFields(), fields::sourceFields() and their optional ones):
// a GasFields message is read into a dem::GasFieldsView and a dem::CellSources is written into
// Sources in the table's order. A field is bound to its member once, here.
#include <span>
#include <string_view>
#include <vector>

#include "coredem/dem/dem_system.h"
#include "coredem/protocol/protocol.h"

namespace coredem::server {

/// The GasFieldsView member of a GasFields field (nullptr: not bound).
std::span<const double> dem::GasFieldsView::*gasFieldMember(std::string_view name);
/// The CellSources member of a Sources field (nullptr: not bound).
std::vector<double> dem::CellSources::*sourceFieldMember(std::string_view name);

/// Views of a validated whole-grid GasFields: every field of fields::gasFields(), and each of
/// fields::optionalGasFields() that the message carries. InternalError for a field without its
/// member.
dem::GasFieldsView gasFieldsView(const protocol::Message& gas);

/// The values of the Sources field `name`. InternalError for a field without its member.
const std::vector<double>& sourceValues(const dem::CellSources& s, std::string_view name);

} // namespace coredem::server
