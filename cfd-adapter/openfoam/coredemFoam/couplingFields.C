#include "couplingFields.H"

#include "fvcGrad.H"

namespace Foam
{

PressureGradient::PressureGradient(const volScalarField& p, const dimensionedScalar& rho)
:
    CouplingOutput("grad_p", 3),
    p_(p),
    rho_(rho)
{}


void PressureGradient::update()
{
    gradP_.clear();
    gradP_.reset(new volVectorField(fvc::grad(p_)*rho_));
}


::coredem::client::ConstView PressureGradient::cellValues() const
{
    return ::coredem::client::ConstView
    (
        reinterpret_cast<const double*>(gradP_().primitiveField().cdata()),
        3*std::size_t(gradP_().size())
    );
}


void GasMassFractions::update()
{
    const label nSpecies = Y_.size();
    cellY_.assign(std::size_t(nCells_)*nSpecies, 0.0);
    for (label k = 0; k < nSpecies; ++k)
    {
        const scalarField& yk = Y_[k].primitiveField();
        for (label c = 0; c < nCells_; ++c) cellY_[std::size_t(c)*nSpecies + k] = yk[c];
    }
}


void GasFraction::read(const double*)
{
    eps_ = max(min(eps_, scalar(1)), alphacMin_);
    if (settle_)
    {
        alphac_.primitiveFieldRef() = eps_;
        alphac_.correctBoundaryConditions();
        settle_ = false;
    }
}


void GasFraction::solidClipped(double volume)
{
    clipped_ = volume;
    if (volume > 0 && !warned_)
    {
        warned_ = true;
        Warning
            << "coupling: " << volume << " m3 of the particles' solid found no room in the fluid "
            << "(more than 1 - alphacMin = " << 1 - alphacMin_ << " of the fluid volume within 3 "
            << "coupling cells): the gas does not see it (ledger gas.solid_volume_clipped_m3; "
            << "first occurrence only)" << endl;
    }
}


void SpeciesSources::read(const double* r)
{
    // One field per species from the cell-major (cell, species) values.
    const label nSpecies = R_.size();
    Rsum_.primitiveFieldRef() = Zero;
    for (label k = 0; k < nSpecies; ++k)
    {
        scalarField& rk = R_[k].primitiveFieldRef();
        const label nCells = rk.size();
        for (label c = 0; c < nCells; ++c) rk[c] = r[std::size_t(c)*nSpecies + k];
        Rsum_.primitiveFieldRef() += rk;
    }
    Rsum_.correctBoundaryConditions();
}

} // namespace Foam
