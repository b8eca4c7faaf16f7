// CaseConfig chemistry -> v1.1 Configure fields (needs the protocol library, so not in the
// protocol-free case_config.cpp).
#include <coredem/orchestrator/case_config.h>
#include <coredem/protocol/message.h>
#include <coredem/v1/configure.pb.h>

namespace coredem::orchestrator {

void addChemistryToConfigure(const CaseConfig& c, v1::Configure& cfg) {
  for (const auto& sp : c.solidSpecies) {
    auto* s = cfg.add_solid_species();
    s->set_name(sp.name);
    s->set_molar_mass(sp.molarMass);
  }
  for (const auto& r : c.reactions) {
    auto* m = cfg.add_reactions();
    m->set_name(r.name);
    for (const auto& t : r.terms) {
      auto* term = m->add_terms();
      term->set_species(t.species);
      term->set_nu(t.nu);
    }
    auto* rate = m->mutable_rate();
    rate->set_law(r.law == "arrhenius" ? v1::RATE_LAW_ARRHENIUS : v1::RATE_LAW_CONSTANT);
    rate->set_a(r.A);
    rate->set_beta(r.beta);
    rate->set_activation_energy(r.E);
    rate->set_order_species(r.orderSpecies);
    rate->set_order(r.order);
    if (r.heatFromNasa7) {
      m->set_heat_from_nasa7(true);
    } else {
      m->set_heat_of_reaction(r.heatOfReaction);
    }
  }
  if (c.chemistry.present) {
    const ChemistryConfig& ch = c.chemistry;
    auto* m = cfg.mutable_chemistry();
    auto* clg = m->mutable_clg();
    clg->set_char_gasification(ch.charGasification);
    clg->set_char_stoichiometry(ch.charStoichiometry == "seed" ? v1::CHAR_STOICHIOMETRY_SEED
                                                               : v1::CHAR_STOICHIOMETRY_CARBON);
    clg->set_oc_reduction(ch.ocReduction);
    clg->set_wgs(ch.wgs);
    clg->set_wgs_equilibrium(ch.wgsEquilibrium == "seed" ? v1::WGS_EQUILIBRIUM_SEED
                             : ch.wgsEquilibrium == "thermodynamic"
                                 ? v1::WGS_EQUILIBRIUM_THERMODYNAMIC
                                 : v1::WGS_EQUILIBRIUM_YOON_DENN);
    for (const auto& [name, value] : ch.kinetics) {
      protocol::addNamedValue(clg->mutable_kinetics(), name, value);
    }
    if (ch.removalFraction) {
      m->set_removal_fraction(*ch.removalFraction);
    }
    if (ch.reactionHeat) {
      m->set_reaction_heat(*ch.reactionHeat);
    }
  }
}

} // namespace coredem::orchestrator
