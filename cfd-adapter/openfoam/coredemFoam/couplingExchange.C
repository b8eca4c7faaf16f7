#include "couplingExchange.H"

#include <algorithm>
#include <cstdlib>
#include <string>

namespace Foam
{

namespace
{

CoredemGrid::Quantity quantity(const CouplingInput& in)
{
    return in.gasFraction()
        ? CoredemGrid::Quantity::GasFraction
        : CoredemGrid::Quantity::Density;
}

} // namespace


CouplingExchange::CouplingExchange
(
    ::coredem::client::Participant& coupling,
    const CoredemGrid& grid,
    label nCells,
    StageTimers& timers
)
:
    coupling_(coupling),
    grid_(grid),
    nCells_(nCells),
    timers_(timers),
    direct_(false),
    partial_(Pstream::parRun())
{
    if (partial_)
    {
        touched_.assign(grid_.touched().begin(), grid_.touched().end());
        Info<< "Exchange: decomposed, each processor with the DEM server (partial sums of the "
            << "coupling cells it touches)\n" << endl;
        return;
    }
    // Mesh cell order = grid order (one blockMesh block): the fields are sent from and the
    // sources received into the solver's own arrays, with no gather/scatter copies.
    // COREDEM_FOAM_EXCHANGE=copy forces the gather/scatter path (to measure the difference).
    const char* mode = std::getenv("COREDEM_FOAM_EXCHANGE");
    direct_ = grid_.identity() && !(mode != nullptr && std::string(mode) == "copy");
    Info<< "Exchange: "
        << (
               direct_ ? "in place (mesh cells in grid order)"
             : grid_.exact() ? "gather/scatter copies"
             : "overlap map (volume-weighted gather, conservative scatter)"
           )
        << nl << endl;
}


void CouplingExchange::readZeros(CouplingInput& in)
{
    const std::size_t n = std::size_t(nCells_)*in.nComponents();
    double* storage = in.cellStorage();
    if (storage != nullptr)
    {
        std::fill(storage, storage + n, 0.0);
        in.read(storage);
    }
    else
    {
        scattered_.assign(n, 0.0);
        in.read(scattered_.data());
    }
}


::coredem::client::ConstView CouplingExchange::limited
(
    CouplingInput& in,
    ::coredem::client::ConstView v,
    double* inPlace,
    label nRows,
    const label* rowGrid
)
{
    double* rows = inPlace;
    if (rows == nullptr)
    {
        limited_.assign(v.begin(), v.end());
        rows = limited_.data();
    }
    in.solidClipped(grid_.limitSolid(rows, nRows, rowGrid, in.solidLimit()));
    return ::coredem::client::ConstView(rows, v.size);
}


void CouplingExchange::packHeatToParticles(label step)
{
    if (heatToParticles_ == nullptr) return;
    if (!coupling_.takesHeatToParticles())
    {
        FatalErrorInFunction
            << "coupling, step " << step << ": the variable-density gas gives the particles the "
            << "heat of its implicit exchange (Q_split, protocol 1.5), which this DEM server "
            << "does not take: run a coredem-dem of protocol 1.5 or later" << exit(FatalError);
    }
    using ::coredem::client::ConstView;
    const scalarField& q = heatToParticles_->primitiveField();
    const double h3 = grid_.cellVolume();
    if (partial_)
    {
        // This processor's part: sum_{c here} A(c, g) q_c / h^3 per touched cell (the server
        // adds the processors' parts).
        grid_.sumTouched(q.cdata(), 1, splitTouched_);
        for (double& v : splitTouched_) v /= h3;
        coupling_.setHeatToParticles(ConstView(splitTouched_));
        return;
    }
    if (grid_.exact())
    {
        if (direct_)
        {
            coupling_.setHeatToParticles(ConstView(q.cdata(), std::size_t(q.size())));
            return;
        }
        grid_.gather(q.cdata(), 1, split_); // the exact map copies
        coupling_.setHeatToParticles(ConstView(split_));
        return;
    }
    grid_.sumTouched(q.cdata(), 1, splitTouched_);
    split_.assign(std::size_t(grid_.gridCells()), 0.0);
    const std::vector<label>& t = grid_.touched();
    for (std::size_t k = 0; k < t.size(); ++k) split_[std::size_t(t[k])] = splitTouched_[k]/h3;
    coupling_.setHeatToParticles(ConstView(split_));
}


void CouplingExchange::exchangePartial(label step, scalar dt)
{
    using ::coredem::client::ConstView;

    // Pack: volume-weighted sums over this processor's cells per touched coupling cell.
    std::vector<::coredem::client::NamedField> fields;
    fields.reserve(outputs_.size());
    for (std::size_t i = 0; i < outputs_.size(); ++i)
    {
        CouplingOutput& out = *outputs_[i];
        if (out.onGrid()) continue; // fluid_fraction: formed by the DEM server
        out.update();
        const ConstView v = out.cellValues();
        grid_.sumTouched(v.data, out.nComponents(), gathered_[i]);
        fields.push_back({out.name(), gathered_[i]});
    }
    packHeatToParticles(step);
    timers_.toc(StageTimers::Pack);

    const ::coredem::client::Sources* src = nullptr;
    try
    {
        src = &coupling_.exchangePartial
        (
            coupling_.step(), dt, touched_, grid_.partialVolume(), fields
        );
    }
    catch (const ::coredem::client::ClientError& e)
    {
        FatalErrorInFunction << "coupling, step " << step << ", processor "
            << Pstream::myProcNo() << ": " << e.what() << exit(FatalError);
    }
    {
        const ::coredem::client::ExchangeTimes xt = coupling_.lastExchangeTimes();
        timers_.add(StageTimers::Serialise, xt.serialise);
        timers_.add(StageTimers::Send, xt.send);
        timers_.add(StageTimers::Wait, xt.wait);
        timers_.add(StageTimers::Receive, xt.receive);
    }
    timers_.tic();

    // Unpack: the touched cells' sources -> this processor's cells -> inputs.
    const std::size_t nc = std::size_t(nCells_);
    for (const std::unique_ptr<CouplingInput>& in : inputs_)
    {
        const label nComp = in->nComponents();
        if (nComp == 0)
        {
            in->read(nullptr);
            continue;
        }
        if (in->optional())
        {
            in->present(src->has(in->name()));
        }
        if (in->optional() && !src->has(in->name()))
        {
            readZeros(*in);
            continue;
        }
        ConstView v = src->field(in->name());
        if (v.size != touched_.size()*nComp)
        {
            FatalErrorInFunction
                << "DEM source " << in->name().c_str() << " has " << label(v.size)
                << " values, expected " << label(touched_.size()*nComp) << exit(FatalError);
        }
        if (in->gasFraction())
        {
            v = limited(*in, v, nullptr, label(touched_.size()), grid_.touched().data());
        }
        double* storage = in->cellStorage();
        if (storage != nullptr)
        {
            grid_.scatterTouched(v.data, nComp, storage, quantity(*in));
            in->read(storage);
        }
        else
        {
            scattered_.assign(nc*nComp, 0.0);
            grid_.scatterTouched(v.data, nComp, scattered_.data(), quantity(*in));
            in->read(scattered_.data());
        }
    }
    timers_.toc(StageTimers::Unpack);
}


void CouplingExchange::exchange(label step, scalar dt)
{
    using ::coredem::client::ConstView;

    if (partial_)
    {
        exchangePartial(step, dt);
        return;
    }

    // Pack: the gas at the start of the step, in grid order.
    std::vector<::coredem::client::NamedField> fields;
    fields.reserve(outputs_.size());
    for (std::size_t i = 0; i < outputs_.size(); ++i)
    {
        CouplingOutput& out = *outputs_[i];
        out.update();
        ConstView v = out.cellValues();
        if (out.onGrid())
        {
            // Per grid cell already.
        }
        else if (!direct_ && !out.uniform())
        {
            grid_.gather(v.data, out.nComponents(), gathered_[i]);
            v = gathered_[i];
        }
        else if (!grid_.exact() && out.uniform())
        {
            // The same value in every grid cell.
            gathered_[i].assign
            (
                std::size_t(grid_.gridCells())*out.nComponents(),
                out.nComponents() > 0 && v.size > 0 ? v.data[0] : 0.0
            );
            v = gathered_[i];
        }
        fields.push_back({out.name(), v});
    }
    packHeatToParticles(step);
    timers_.toc(StageTimers::Pack);

    // Sources received straight into the fields (in place) or viewed in the received frames
    // and scattered below.
    const std::size_t nc = std::size_t(nCells_);
    std::vector<::coredem::client::NamedBuffer> into;
    if (direct_)
    {
        for (const std::unique_ptr<CouplingInput>& in : inputs_)
        {
            double* storage = in->cellStorage();
            if (storage != nullptr && in->nComponents() > 0)
            {
                into.push_back({in->name(), storage, nc*in->nComponents()});
            }
        }
    }
    const ::coredem::client::Sources* src = nullptr;
    try
    {
        src = &coupling_.exchange(coupling_.step(), dt, fields, into);
    }
    catch (const ::coredem::client::ClientError& e)
    {
        FatalErrorInFunction << "coupling, step " << step << ": " << e.what()
            << exit(FatalError);
    }
    {
        const ::coredem::client::ExchangeTimes xt = coupling_.lastExchangeTimes();
        timers_.add(StageTimers::Serialise, xt.serialise);
        timers_.add(StageTimers::Send, xt.send);
        timers_.add(StageTimers::Wait, xt.wait);
        timers_.add(StageTimers::Receive, xt.receive);
    }
    timers_.tic();

    // Unpack: sources -> cell values (a no-op for arrays received in place) -> inputs.
    for (const std::unique_ptr<CouplingInput>& in : inputs_)
    {
        const label nComp = in->nComponents();
        if (nComp == 0)
        {
            in->read(nullptr);
            continue;
        }
        if (in->optional())
        {
            in->present(src->has(in->name()));
        }
        if (in->optional() && !src->has(in->name()))
        {
            readZeros(*in);
            continue;
        }
        ConstView v = src->field(in->name());
        if (v.size != std::size_t(grid_.gridCells())*nComp)
        {
            FatalErrorInFunction
                << "DEM source " << in->name().c_str() << " has " << label(v.size)
                << " values, expected " << grid_.gridCells()*nComp << exit(FatalError);
        }
        double* storage = in->cellStorage();
        if (in->gasFraction())
        {
            // Received in place (the mesh is the grid in its order): limited there.
            v = limited
            (
                *in, v, v.data == storage ? storage : nullptr, grid_.gridCells(), nullptr
            );
        }
        if (storage != nullptr)
        {
            if (v.data != storage) grid_.scatter(v.data, nComp, storage, quantity(*in));
            in->read(storage);
        }
        else if (direct_)
        {
            in->read(v.data);
        }
        else
        {
            scattered_.assign(nc*nComp, 0.0);
            grid_.scatter(v.data, nComp, scattered_.data(), quantity(*in));
            in->read(scattered_.data());
        }
    }
    timers_.toc(StageTimers::Unpack);
}

} // namespace Foam
