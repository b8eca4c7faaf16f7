#pragma once
// Helpers shared by the protocol unit tests.
#include <vector>

#include <coredem/protocol/fields.h>
#include <coredem/protocol/message.h>

namespace coredem::protocol::test {

/// A valid GasFields message for `cells` cells and `species` species: value of field f at
/// flat index i = 1 + f + 0.001 i.
inline Message gasFieldsMessage(std::uint64_t cells, std::uint32_t species, std::int64_t step = 0,
                                std::uint64_t sequence = 1) {
  Message m = makeGasFields(step, 0.0, 1e-3, cells, species);
  m.setSequence(sequence);
  std::size_t f = 0;
  for (const auto& spec : fields::gasFields()) {
    std::vector<double> v(cells * fields::componentsOf(spec.extent, species));
    for (std::size_t i = 0; i < v.size(); ++i) {
      v[i] = 1.0 + static_cast<double>(f) + 0.001 * static_cast<double>(i);
    }
    m.addArray<double>(spec.name, v, fields::shapeOf(spec.extent, cells, species));
    ++f;
  }
  return m;
}

} // namespace coredem::protocol::test
