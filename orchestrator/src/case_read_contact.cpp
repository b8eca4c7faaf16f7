// The contact materials (protocol v1.6; docs/case-schema.md "material_pairs" and the contact
// properties of `materials[i]`): material_pairs, and the check that every material has what the
// chosen contact law needs.
#include <string>

#include <yaml-cpp/yaml.h>

#include <coredem/dem/dem_config.h>
#include <coredem/dem/kernels/contact_law.h>
#include <coredem/dem/models.h>

#include "case_read.h"

namespace coredem::orchestrator::caseread {

/// material_pairs: [{materials: [a, b], e_n: …, friction: …}], each pair once.
void readMaterialPairs(CaseReading& r) {
  const Section& top = r.top;
  CaseConfig& c = r.c;
  if (!top.has("material_pairs")) {
    return;
  }
  for (const auto& p : top.list("material_pairs", {"materials", "e_n", "friction"},
                                "contact properties of pairs of materials")) {
    const YAML::Node names = p.raw("materials");
    if (!names.IsSequence() || names.size() != 2 || !names[0].IsScalar() || !names[1].IsScalar()) {
      p.fail(p.markOf("materials"), p.full("materials"),
             "expected the names of two materials, e.g. [glass, steel] (the same name twice for "
             "the pair of a material with itself)");
    }
    MaterialPairConfig pc;
    pc.a = names[0].Scalar();
    pc.b = names[1].Scalar();
    for (const std::string& n : {pc.a, pc.b}) {
      if (materialIndex(c, n) < 0) {
        std::vector<std::string> known;
        for (const auto& m : c.materials) {
          known.push_back(m.name);
        }
        p.fail(p.markOf("materials"), p.full("materials"),
               fmt::format("unknown material '{}'; allowed: {}", n, yaml::join(known)));
      }
    }
    if (!p.has("e_n") && !p.has("friction")) {
      p.fail(p.markOf("materials"), p.full("materials"),
             "a material pair needs e_n or friction (or both)");
    }
    if (p.has("e_n")) {
      pc.eN =
          p.number("e_n", std::nullopt, 0.0, 1.0, "normal restitution coefficient in (0, 1]", true);
    }
    if (p.has("friction")) {
      pc.friction = p.number("friction", std::nullopt, 0.0, kBig, "Coulomb friction, >= 0");
    }
    for (const auto& q : c.materialPairs) {
      if ((q.a == pc.a && q.b == pc.b) || (q.a == pc.b && q.b == pc.a)) {
        p.fail(p.markOf("materials"), p.full("materials"),
               fmt::format("the pair ({}, {}) is given twice", pc.a, pc.b));
      }
    }
    c.materialPairs.push_back(pc);
  }
}

/// Every material has the properties of the chosen contact law (`models: {contact: …}`):
/// k_n for linear-spring-dashpot, youngs_modulus for hertz-mindlin.
void checkContactMaterials(CaseReading& r) {
  const Section& top = r.top;
  const CaseConfig& c = r.c;
  dem::DemConfig d;
  for (const auto& [key, value] : c.models) {
    if (key == "contact") {
      dem::applyModelOption(d, key, value); // validated by readModels
    }
  }
  const bool hertz = d.contact == dem::kernels::ContactLaw::HertzMindlin;
  const std::string law(dem::contactModels().nameOf(d.contact));
  for (std::size_t i = 0; i < c.materials.size(); ++i) {
    const MaterialConfig& m = c.materials[i];
    const char* missing = nullptr;
    if (hertz && !m.youngsModulus) {
      missing = "youngs_modulus (Pa; poisson_ratio defaults to 0.3)";
    } else if (!hertz && !(m.kN > 0.0)) {
      missing = "k_n (N/m)";
    }
    if (missing != nullptr) {
      top.fail(top.markOf("materials"), fmt::format("materials[{}]", i),
               fmt::format("material '{}' has no {}, which the contact law {} needs "
                           "(models.contact)",
                           m.name, missing, law));
    }
  }
}

} // namespace coredem::orchestrator::caseread

namespace coredem::orchestrator {

std::string CaseConfig::contactMaterialsUsed() const {
  std::string what;
  const auto add = [&](const std::string& item) { what += (what.empty() ? "" : ", ") + item; };
  if (!materialPairs.empty()) {
    add(fmt::format("{} material_pairs", materialPairs.size()));
  }
  std::size_t walled = walls.boxMaterial.empty() ? 0 : 1;
  for (const auto& p : walls.planes) {
    walled += p.material.empty() ? 0 : 1;
  }
  for (const auto& w : walls.revolved) {
    walled += w.material.empty() ? 0 : 1;
  }
  for (const auto& w : walls.meshes) {
    walled += w.material.empty() ? 0 : 1;
  }
  if (walled > 0) {
    add(fmt::format("{} walls with a material", walled));
  }
  for (const auto& [key, value] : models) {
    if (key == "contact" && value.find("hertz") != std::string::npos) {
      add("models.contact: " + value);
    }
  }
  return what;
}

} // namespace coredem::orchestrator
