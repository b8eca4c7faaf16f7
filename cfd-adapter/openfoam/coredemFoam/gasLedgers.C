#include "gasLedgers.H"

namespace Foam
{

GasLedgers::GasLedgers(const std::vector<std::string>& species)
{
    for (const std::string& s : species)
    {
        speciesFromParticles.emplace_back("gas.species." + s + "_kg", Species);
        // Species leaving through the boundary (faces with outward flux), kg/s at the step
        // end: the outlet gas composition of reacting cases (docs/validation.md).
        speciesOutflow.emplace_back("gas.outflow." + s + "_kg_per_s", Diagnostic);
    }
    for (const char* a : {"x", "y", "z"})
    {
        momentumFromParticles.emplace_back
        (
            std::string("gas.momentum_from_particles_") + a + "_Ns", Diagnostic
        );
    }

    // The order of StepDone and of the restart file (the vectors above no longer grow).
    all_ = {&heatFromParticles, &heatHomogeneous, &enthalpyInflow, &massFromParticles};
    for (Ledger& l : speciesFromParticles) all_.push_back(&l);
    for (Ledger& l : momentumFromParticles) all_.push_back(&l);
    all_.push_back(&solidVolume);
    all_.push_back(&enthalpy);
    all_.push_back(&pressureDrop);
    for (Ledger& l : speciesOutflow) all_.push_back(&l);
}


GasLedgers::Ledger* GasLedgers::find(const std::string& name)
{
    for (Ledger* l : all_)
    {
        if (l->name() == name) return l;
    }
    return nullptr;
}


::coredem::client::Ledgers GasLedgers::report() const
{
    ::coredem::client::Ledgers r;
    for (const Ledger* l : all_)
    {
        const std::pair<std::string, double> e(l->name(), l->value());
        switch (l->kind())
        {
            case Mass: r.mass.push_back(e); break;
            case Energy: r.energy.push_back(e); break;
            case Species: r.species.push_back(e); break;
            case Diagnostic: r.diagnostics.push_back(e); break;
        }
    }
    return r;
}

} // namespace Foam
