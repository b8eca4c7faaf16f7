// coredemFoam — the OpenFOAM participant of a coupled CoReDEM run (DESIGN §5,
// docs/coredemFoam.md).
//
// Transient, incompressible, volume-averaged gas (PHYSICS §1, "Model A", constant properties)
// solved with PIMPLE in the DPMFoam manner: the particles reach the gas only through the gas
// volume fraction alphac and source fields. Every step the orchestrator grants (Δt, step):
//
//   1. send the gas at the start of the step (U, grad p, T, properties, Y) to the DEM server,
//      which sub-cycles its particles over Δt and answers with sub-step-averaged sources:
//      eps_g, K_sl, K_sl*U_s, H, H*T_p, R_k, Q_hom (PCM cells = this mesh's cells);
//   2. advance the gas over the same Δt with them: alphac (including d(alphac)/dt in
//      continuity), implicit drag Sp(K_sl/rho) + explicit K_sl U_s/rho, particle heat implicit
//      in T, species sources;
//   3. report the Courant number (for the next Δt) and the cumulative ledgers in StepDone, and
//      on a checkpoint grant write the state as a binary time directory and list it.
//
// Command line: coredemFoam -case DIR [-restart FILE] [-control EP] [-dem EP] [-session ID]
// [-timers] (endpoints default to COREDEM_CONTROL_ENDPOINT, COREDEM_DEM_ENDPOINT,
// COREDEM_SESSION). -timers: per-stage wall time per CFD step, a table at the end and
// DIR/../timers-cfd.json (the run folder under `coredem run`).

#include "fvCFD.H"
#include "singlePhaseTransportModel.H"
#include "PhaseIncompressibleTurbulenceModel.H"
#include "pimpleControl.H"
#include "fvOptions.H"
#include "OFstream.H"
#include "IFstream.H"

#include "couplingGrid.H"

#include "coredem/client/participant.h"

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace
{

// Cumulative ledgers with compensated (Kahan) summation, in a fixed order; saved bit-exactly
// in checkpoints so that a resumed run sums exactly as an uninterrupted one.
class Ledgers
{
public:
    enum Kind { Mass, Energy, Species, Diagnostic };

    void define(const std::string& name, Kind kind)
    {
        names_.push_back(name);
        kinds_.push_back(kind);
        sum_.push_back(0.0);
        comp_.push_back(0.0);
    }

    void add(std::size_t i, double v)
    {
        const double y = v - comp_[i];
        const double t = sum_[i] + y;
        comp_[i] = (t - sum_[i]) - y;
        sum_[i] = t;
    }

    void set(std::size_t i, double v)
    {
        sum_[i] = v;
        comp_[i] = 0.0;
    }

    std::size_t index(const std::string& name) const
    {
        for (std::size_t i = 0; i < names_.size(); ++i)
        {
            if (names_[i] == name) return i;
        }
        return names_.size();
    }

    ::coredem::client::Ledgers report() const
    {
        ::coredem::client::Ledgers l;
        for (std::size_t i = 0; i < names_.size(); ++i)
        {
            const std::pair<std::string, double> e(names_[i], sum_[i]);
            switch (kinds_[i])
            {
                case Mass: l.mass.push_back(e); break;
                case Energy: l.energy.push_back(e); break;
                case Species: l.species.push_back(e); break;
                case Diagnostic: l.diagnostics.push_back(e); break;
            }
        }
        return l;
    }

    std::size_t size() const { return names_.size(); }
    const std::string& name(std::size_t i) const { return names_[i]; }
    double& sum(std::size_t i) { return sum_[i]; }
    double& comp(std::size_t i) { return comp_[i]; }

private:
    std::vector<std::string> names_;
    std::vector<Kind> kinds_;
    std::vector<double> sum_, comp_;
};

std::string hexDouble(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return buf;
}

// Writes a field as <dir>/<name> in binary (full precision) with its usual FoamFile header.
// The header's location is the time name (not where the field was read from), so a restarted
// run writes the same bytes as an uninterrupted one.
template<class FieldType>
void writeBinary(FieldType& f, const Foam::fileName& dir)
{
    f.instance() = f.time().timeName();
    Foam::OFstream os(dir/f.name(), Foam::IOstream::BINARY);
    f.writeHeader(os);
    f.writeData(os);
    Foam::IOobject::writeEndDivider(os);
    if (!os.good())
    {
        FatalErrorInFunction
            << "cannot write checkpoint file " << os.name() << Foam::exit(Foam::FatalError);
    }
}

// What a checkpoint's coredemFoam.restart holds (besides the fields of its time directory).
struct RestartInfo
{
    long long step = 0;
    double time = 0.0;
    Foam::label timeIndex = 0;
    std::string instance;
    std::vector<std::string> ledgerNames;
    std::vector<double> ledgerSum, ledgerComp;
};

RestartInfo readRestart(const std::string& file)
{
    std::ifstream in(file);
    if (!in)
    {
        FatalErrorInFunction
            << "cannot read restart file " << file << " (pass the coredemFoam.restart of a "
            << "checkpoint that coredemFoam wrote)" << Foam::exit(Foam::FatalError);
    }
    RestartInfo r;
    std::string line;
    bool haveStep = false, haveTime = false, haveInstance = false;
    while (std::getline(in, line))
    {
        std::istringstream ls(line);
        std::string key;
        ls >> key;
        if (key.empty() || key[0] == '#') continue;
        std::string a, b, c;
        ls >> a >> b >> c;
        if (key == "step") { r.step = std::stoll(a); haveStep = true; }
        else if (key == "time") { r.time = std::strtod(a.c_str(), nullptr); haveTime = true; }
        else if (key == "timeIndex") { r.timeIndex = Foam::label(std::stol(a)); }
        else if (key == "instance") { r.instance = a; haveInstance = true; }
        else if (key == "ledger")
        {
            r.ledgerNames.push_back(a);
            r.ledgerSum.push_back(std::strtod(b.c_str(), nullptr));
            r.ledgerComp.push_back(std::strtod(c.c_str(), nullptr));
        }
    }
    if (!haveStep || !haveTime || !haveInstance)
    {
        FatalErrorInFunction
            << "restart file " << file << " lacks step, time or instance: it is not a "
            << "coredemFoam checkpoint" << Foam::exit(Foam::FatalError);
    }
    return r;
}

// -timers: wall time of each stage of a CFD step, summed over the run.
class StageTimers
{
public:
    enum Stage
    {
        Pack, Serialise, Send, Wait, Receive, Unpack, UEqn, PEqn, TEqn, YEqn, Advance, Rest,
        NStages
    };

    using Clock = std::chrono::steady_clock;

    static const char* name(int s)
    {
        static const char* names[NStages] =
        {
            "pack", "serialise", "send", "wait_dem", "receive", "unpack",
            "UEqn", "pEqn", "TEqn", "YEqn", "advance", "rest"
        };
        return names[s];
    }

    static double since(Clock::time_point t0)
    {
        return std::chrono::duration<double>(Clock::now() - t0).count();
    }

    void add(Stage s, double seconds) { step_[s] += seconds; }

    //- Closes a step of `seconds` wall time: what no stage took is "rest".
    void endStep(double seconds)
    {
        double staged = 0;
        for (int s = 0; s < Rest; ++s) staged += step_[s];
        step_[Rest] = seconds - staged;
        const double x = exchangeOf(step_);
        for (int s = 0; s < NStages; ++s)
        {
            total_[s] += step_[s];
            step_[s] = 0;
        }
        total_[NStages] += seconds;
        shareMin_ = steps_ == 0 ? x/seconds : std::min(shareMin_, x/seconds);
        shareMax_ = steps_ == 0 ? x/seconds : std::max(shareMax_, x/seconds);
        ++steps_;
    }

    //- pack + serialise + send + wait + receive + unpack (the wait includes the DEM's work).
    static double exchangeOf(const double* t)
    {
        return t[Pack] + t[Serialise] + t[Send] + t[Wait] + t[Receive] + t[Unpack];
    }

    //- The exchange without the wait for the DEM: what this side spends on coupling.
    static double ownOf(const double* t) { return exchangeOf(t) - t[Wait]; }

    std::string table(label nCells, bool direct) const
    {
        const double n = std::max<long>(steps_, 1);
        const double all = total_[NStages];
        std::ostringstream os;
        char line[160];
        std::snprintf
        (
            line, sizeof line, "coredemFoam timers: %ld CFD steps, %d cells, %.3f s in steps, "
            "receive %s\n", steps_, int(nCells), all,
            direct ? "into the fields" : "by scatter copies"
        );
        os << line;
        std::snprintf(line, sizeof line, "  %-10s %12s %12s %8s\n", "stage", "total s", "ms/step",
            "share");
        os << line;
        for (int s = 0; s < NStages; ++s)
        {
            std::snprintf(line, sizeof line, "  %-10s %12.4f %12.4f %7.2f%%\n", name(s),
                total_[s], 1e3*total_[s]/n, all > 0 ? 100*total_[s]/all : 0.0);
            os << line;
        }
        std::snprintf(line, sizeof line, "  exchange (pack..unpack, incl. wait) %.2f%% of the step "
            "time (per step %.2f%%..%.2f%%); without the wait %.2f%%\n",
            all > 0 ? 100*exchangeOf(total_)/all : 0.0, 100*shareMin_, 100*shareMax_,
            all > 0 ? 100*ownOf(total_)/all : 0.0);
        os << line;
        return os.str();
    }

    std::string json(label nCells, bool direct) const
    {
        const double n = std::max<long>(steps_, 1);
        const double all = total_[NStages];
        std::ostringstream os;
        os.precision(9);
        os << "{\n  \"participant\": \"coredemFoam\",\n  \"cells\": " << nCells
           << ",\n  \"steps\": " << steps_ << ",\n  \"receive_into_fields\": "
           << (direct ? "true" : "false") << ",\n  \"step_seconds\": " << all
           << ",\n  \"stages\": {";
        for (int s = 0; s < NStages; ++s)
        {
            os << (s ? "," : "") << "\n    \"" << name(s) << "\": {\"seconds\": " << total_[s]
               << ", \"per_step_s\": " << total_[s]/n << ", \"share\": "
               << (all > 0 ? total_[s]/all : 0.0) << "}";
        }
        os << "\n  },\n  \"exchange_share\": " << (all > 0 ? exchangeOf(total_)/all : 0.0)
           << ",\n  \"exchange_share_min\": " << shareMin_
           << ",\n  \"exchange_share_max\": " << shareMax_
           << ",\n  \"exchange_share_without_wait\": " << (all > 0 ? ownOf(total_)/all : 0.0)
           << "\n}\n";
        return os.str();
    }

private:
    double step_[NStages] = {};
    double total_[NStages + 1] = {};
    double shareMin_ = 0, shareMax_ = 0;
    long steps_ = 0;
};

} // namespace


int main(int argc, char* argv[])
{
    // Note: OpenFOAM's libraries read the etc tree while they load, before main: the
    // environment must already have WM_PROJECT_DIR (the orchestrator sets it).
    argList::addNote
    (
        "CoReDEM's OpenFOAM participant: volume-averaged incompressible PIMPLE gas coupled to"
        " the DEM server every step (docs/coredemFoam.md)."
    );
    argList::noParallel();
    argList::addOption("restart", "file", "coredemFoam.restart of a checkpoint to resume from");
    argList::addOption("control", "endpoint", "orchestrator endpoint (else COREDEM_CONTROL_ENDPOINT)");
    argList::addOption("dem", "endpoint", "DEM server endpoint (else COREDEM_DEM_ENDPOINT)");
    argList::addOption("session", "id", "session id (else COREDEM_SESSION)");
    argList::addOption("timeout", "s", "per-request deadline in s (else COREDEM_TIMEOUT_S or 60)");
    argList::addBoolOption
    (
        "timers",
        "per-stage wall time per CFD step (UEqn, pEqn, TEqn, YEqn, exchange split into pack,"
        " serialise, send, wait, receive, unpack; rest): table at the end, DIR/../timers-cfd.json"
    );

    #include "setRootCase.H"
    #include "createTime.H"

    // A case folder with a blockMeshDict but no mesh yet gets one from Debian's blockMesh.
    if
    (
        !isFile(runTime.constantPath()/"polyMesh"/"faces")
     && !isFile(runTime.constantPath()/"polyMesh"/"faces.gz")
    )
    {
        const fileName dict(runTime.path()/"system"/"blockMeshDict");
        if (!isFile(dict))
        {
            FatalErrorInFunction
                << "no mesh in " << runTime.constantPath()/"polyMesh" << " and no " << dict
                << " to make one" << exit(FatalError);
        }
        const std::string cmd =
            std::string(COREDEM_OPENFOAM_BIN_DIR) + "/blockMesh -case '" + runTime.path()
          + "' > '" + runTime.path() + "/log.blockMesh' 2>&1";
        Info<< "No mesh yet: " << cmd.c_str() << nl << endl;
        if (Foam::system(cmd) != 0)
        {
            FatalErrorInFunction
                << "blockMesh failed; see " << runTime.path()/"log.blockMesh" << exit(FatalError);
        }
    }

    #include "createMesh.H"
    pimpleControl pimple(mesh);
    #include "readGravitationalAcceleration.H"

    // ---- coupling: handshake, grid, restart ------------------------------------------------
    ::coredem::client::Options options;
    options.name = "coredemFoam";
    options.softwareVersion = "coredemFoam 0.1.0 (OpenFOAM " + std::to_string(OPENFOAM) + ")";
    {
        string s;
        if (args.readIfPresent("control", s)) options.controlEndpoint = s;
        if (args.readIfPresent("dem", s)) options.demEndpoint = s;
        if (args.readIfPresent("session", s)) options.sessionId = s;
        scalar t = 0;
        if (args.readIfPresent("timeout", t)) options.timeoutSeconds = t;
    }
    ::coredem::client::Participant coupling(options);
    try
    {
        coupling.initialize();
    }
    catch (const ::coredem::client::ClientError& e)
    {
        FatalErrorInFunction << "coupling: " << e.what() << exit(FatalError);
    }
    if (!coupling.isRunning())
    {
        Info<< "The orchestrator ended the run before the first step: "
            << coupling.shutdownReason().c_str() << nl << "End" << endl;
        coupling.finalize();
        return 0;
    }

    const ::coredem::client::Grid& grid = coupling.grid();
    const Foam::CoredemGrid couplingGrid
    (
        mesh,
        vector(grid.origin[0], grid.origin[1], grid.origin[2]),
        vector(grid.spacing[0], grid.spacing[1], grid.spacing[2]),
        label(grid.counts[0]), label(grid.counts[1]), label(grid.counts[2])
    );
    Info<< "Coupling grid: " << grid.counts[0] << " x " << grid.counts[1] << " x "
        << grid.counts[2] << " cells of " << couplingGrid.spacing() << " m, "
        << label(grid.species.size()) << " gas species; mesh checked (uniform Cartesian)\n"
        << endl;

    const bool restarting = args.found("restart");
    RestartInfo restart;
    fileName fieldInstance = runTime.timeName();
    if (restarting)
    {
        const fileName file(args.get<fileName>("restart"));
        restart = readRestart(file);
        if (restart.step != coupling.startStep())
        {
            FatalErrorInFunction
                << "restart file " << file << " is of step " << label(restart.step)
                << " but the orchestrator restarts from step " << label(coupling.startStep())
                << exit(FatalError);
        }
        fieldInstance = file.path()/restart.instance;
        runTime.setTime(restart.time, restart.timeIndex);
        Info<< "Restarting from " << fieldInstance << " (step " << label(restart.step)
            << ", t = " << restart.time << " s)\n" << endl;
    }
    else if (mag(coupling.startTime() - runTime.value()) > 1e-12*max(1.0, runTime.value()))
    {
        FatalErrorInFunction
            << "the orchestrator starts at t = " << coupling.startTime() << " s but the case "
            << "starts at " << runTime.value() << " s (controlDict startTime) and no -restart "
            << "was given" << exit(FatalError);
    }

    #include "createFields.H"

    // Old-time values exist from the start so that d(alphac)/dt of the first step after a
    // restart uses the checkpoint's fraction, as an uninterrupted run does.
    alphac.oldTime();

    turbulence->validate();

    // ---- ledgers (docs/coredemFoam.md) ---------------------------------------------------------
    Ledgers ledgers;
    ledgers.define("gas.heat_from_particles_J", Ledgers::Energy);
    ledgers.define("gas.heat_homogeneous_J", Ledgers::Energy);
    ledgers.define("gas.enthalpy_inflow_J", Ledgers::Energy);
    ledgers.define("gas.mass_from_particles_kg", Ledgers::Mass);
    for (const std::string& s : speciesNames)
    {
        ledgers.define("gas.species." + s + "_kg", Ledgers::Species);
    }
    const char* axes[3] = {"x", "y", "z"};
    for (const char* a : axes)
    {
        ledgers.define(std::string("gas.momentum_from_particles_") + a + "_Ns", Ledgers::Diagnostic);
    }
    ledgers.define("gas.solid_volume_m3", Ledgers::Diagnostic);
    ledgers.define("gas.enthalpy_J", Ledgers::Diagnostic);
    ledgers.define("gas.pressure_drop_Pa", Ledgers::Diagnostic);
    // Species leaving through the boundary (faces with outward flux), kg/s at the step end:
    // the outlet gas composition of reacting cases (docs/validation.md).
    for (const std::string& s : speciesNames)
    {
        ledgers.define("gas.outflow." + s + "_kg_per_s", Ledgers::Diagnostic);
    }
    const std::size_t lHeat = 0, lHom = 1, lInflow = 2, lMass = 3, lSpecies0 = 4;
    const std::size_t lMom0 = lSpecies0 + speciesNames.size();
    const std::size_t lSolid = lMom0 + 3, lEnthalpy = lSolid + 1, lDp = lSolid + 2;
    const std::size_t lOut0 = lDp + 1;
    if (restarting)
    {
        for (std::size_t i = 0; i < restart.ledgerNames.size(); ++i)
        {
            const std::size_t j = ledgers.index(restart.ledgerNames[i]);
            if (j == ledgers.size())
            {
                FatalErrorInFunction
                    << "the restart file has ledger " << restart.ledgerNames[i].c_str()
                    << ", which this case does not produce (another species list?)"
                    << exit(FatalError);
            }
            ledgers.sum(j) = restart.ledgerSum[i];
            ledgers.comp(j) = restart.ledgerComp[i];
        }
    }

    const label nCells = mesh.nCells();
    const label nSpecies = label(speciesNames.size());
    const scalar Vc = couplingGrid.cellVolume();
    const scalar rhoCp = rhog.value()*cpg.value();

    // Pressure-drop diagnostic: mean p over the inlet patches minus mean p over the outlets
    // (patches named in transportProperties: pressureDropPatches (inlet outlet)), in Pa.
    labelList dpPatches(2, -1);
    {
        wordList names(laminarTransport.getOrDefault<wordList>("pressureDropPatches", wordList()));
        if (names.size() == 2)
        {
            for (label i = 0; i < 2; ++i)
            {
                dpPatches[i] = mesh.boundaryMesh().findPatchID(names[i]);
                if (dpPatches[i] < 0)
                {
                    FatalErrorInFunction
                        << "pressureDropPatches: no patch " << names[i] << exit(FatalError);
                }
            }
        }
    }
    auto patchMeanP = [&](label patchi)
    {
        const scalarField& pb = p.boundaryField()[patchi];
        const scalarField& a = mesh.magSf().boundaryField()[patchi];
        return gSum(pb*a)/gSum(a);
    };

    std::vector<double> uG, gradPG, TG, rhoG, muG, kappaG, cpG, YG, cellY;
    std::vector<scalar> cellBuf;
    const volScalarField nuField(laminarTransport.nu());

    // Constant properties: sent every step, filled once.
    rhoG.assign(nCells, rhog.value());
    kappaG.assign(nCells, kappag.value());
    cpG.assign(nCells, cpg.value());
    // Mesh cell order = grid order (one blockMesh block): the fields are sent from and the
    // sources received into the solver's own arrays, with no gather/scatter copies.
    // COREDEM_FOAM_EXCHANGE=copy forces the gather/scatter path (to measure the difference).
    const char* exchangeMode = std::getenv("COREDEM_FOAM_EXCHANGE");
    const bool direct =
        couplingGrid.identity()
     && !(exchangeMode != nullptr && std::string(exchangeMode) == "copy");
    Info<< "Exchange: " << (direct ? "in place (mesh cells in grid order)" : "gather/scatter copies")
        << nl << endl;
    const bool timersOn = args.found("timers");
    StageTimers timers;
    scalarField epsNew(nCells);
    bool firstStep = true;
    scalar cumulativeContErr = 0;
    label steps = 0;

    Info<< "\nStarting time loop\n" << endl;

    while (coupling.isRunning())
    {
        const label step = label(coupling.step());
        const scalar dt = coupling.dt();

        // 1. gas at the start of the step -> DEM, sources of the step <- DEM.
        const StageTimers::Clock::time_point tStep = StageTimers::Clock::now();
        StageTimers::Clock::time_point tic = tStep;
        const volVectorField gradP(fvc::grad(p)*rhog);
        const scalarField mu(nuField.primitiveField()*rhog.value());
        cellY.assign(std::size_t(nCells)*nSpecies, 0.0);
        for (label k = 0; k < nSpecies; ++k)
        {
            const scalarField& yk = Y[k].primitiveField();
            for (label c = 0; c < nCells; ++c) cellY[std::size_t(c)*nSpecies + k] = yk[c];
        }
        using ::coredem::client::ConstView;
        const std::size_t nc = std::size_t(nCells);
        ConstView uV, gradPV, TV, muV, YV;
        if (direct)
        {
            uV = ConstView(reinterpret_cast<const double*>(U.primitiveField().cdata()), 3*nc);
            gradPV =
                ConstView(reinterpret_cast<const double*>(gradP.primitiveField().cdata()), 3*nc);
            TV = ConstView(T.primitiveField().cdata(), nc);
            muV = ConstView(mu.cdata(), nc);
            YV = ConstView(cellY.data(), cellY.size());
        }
        else
        {
            couplingGrid.gather(reinterpret_cast<const scalar*>(U.primitiveField().cdata()), 3, uG);
            couplingGrid.gather
            (
                reinterpret_cast<const scalar*>(gradP.primitiveField().cdata()), 3, gradPG
            );
            couplingGrid.gather(T.primitiveField().cdata(), 1, TG);
            couplingGrid.gather(mu.cdata(), 1, muG);
            couplingGrid.gather(cellY.data(), nSpecies, YG);
            uV = uG; gradPV = gradPG; TV = TG; muV = muG; YV = YG;
        }
        timers.add(StageTimers::Pack, StageTimers::since(tic));

        // Sources received straight into the fields (in place) or viewed in the received
        // frames and scattered below.
        std::vector<::coredem::client::NamedBuffer> into;
        if (direct)
        {
            into =
            {
                {"eps_g", epsNew.data(), nc},
                {"K_sl", Ksl.primitiveFieldRef().data(), nc},
                {"K_sl_Us", reinterpret_cast<double*>(KslUs.primitiveFieldRef().data()), 3*nc},
                {"H", Hheat.primitiveFieldRef().data(), nc},
                {"H_Tp", HTp.primitiveFieldRef().data(), nc},
                {"Q_hom", Qhom.primitiveFieldRef().data(), nc}
            };
        }
        const ::coredem::client::Sources* src = nullptr;
        try
        {
            src = &coupling.exchange
            (
                coupling.step(), dt,
                {
                    {"u_g", uV}, {"grad_p", gradPV}, {"T_g", TV}, {"rho_g", rhoG},
                    {"mu_g", muV}, {"kappa_g", kappaG}, {"cp_g", cpG}, {"Y_g", YV}
                },
                into
            );
        }
        catch (const ::coredem::client::ClientError& e)
        {
            FatalErrorInFunction << "coupling, step " << step << ": " << e.what()
                << exit(FatalError);
        }
        {
            const ::coredem::client::ExchangeTimes xt = coupling.lastExchangeTimes();
            timers.add(StageTimers::Serialise, xt.serialise);
            timers.add(StageTimers::Send, xt.send);
            timers.add(StageTimers::Wait, xt.wait);
            timers.add(StageTimers::Receive, xt.receive);
        }
        tic = StageTimers::Clock::now();

        // Sources -> cell fields (a no-op for arrays received in place).
        auto toCells = [&](const char* name, label nComp, scalar* dest)
        {
            const ConstView v = src->field(name);
            if (v.size != std::size_t(couplingGrid.gridCells())*nComp)
            {
                FatalErrorInFunction
                    << "DEM source " << name << " has " << label(v.size) << " values, expected "
                    << couplingGrid.gridCells()*nComp << exit(FatalError);
            }
            if (v.data != dest) couplingGrid.scatter(v.data, nComp, dest);
        };
        toCells("eps_g", 1, epsNew.data());
        // The gas fraction is clipped to [alphacMin, 1].
        epsNew = max(min(epsNew, scalar(1)), alphacMin);
        if (firstStep && !restarting)
        {
            // The particles were there before the first step: no d(alphac)/dt from "1 -> eps".
            alphac.primitiveFieldRef() = epsNew;
            alphac.correctBoundaryConditions();
        }
        toCells("K_sl", 1, Ksl.primitiveFieldRef().data());
        toCells("K_sl_Us", 3, reinterpret_cast<scalar*>(KslUs.primitiveFieldRef().data()));
        toCells("H", 1, Hheat.primitiveFieldRef().data());
        toCells("H_Tp", 1, HTp.primitiveFieldRef().data());
        toCells("Q_hom", 1, Qhom.primitiveFieldRef().data());
        Rsum.primitiveFieldRef() = Zero;
        if (nSpecies > 0)
        {
            // Cell-major (cell, species) -> one field per species: read from the received
            // array (grid order = cell order) or scattered first.
            const double* r = src->field("R_species").data;
            if (src->field("R_species").size != nc*nSpecies)
            {
                FatalErrorInFunction
                    << "DEM source R_species has " << label(src->field("R_species").size)
                    << " values, expected " << nCells*nSpecies << exit(FatalError);
            }
            if (!direct)
            {
                cellBuf.assign(nc*nSpecies, 0.0);
                toCells("R_species", nSpecies, cellBuf.data());
                r = cellBuf.data();
            }
            for (label k = 0; k < nSpecies; ++k)
            {
                scalarField& rk = Rspecies[k].primitiveFieldRef();
                for (label c = 0; c < nCells; ++c) rk[c] = r[std::size_t(c)*nSpecies + k];
                Rsum.primitiveFieldRef() += rk;
            }
        }
        for (volScalarField* f : {&Ksl, &Hheat, &HTp, &Qhom, &Rsum})
        {
            f->correctBoundaryConditions();
        }
        KslUs.correctBoundaryConditions();
        timers.add(StageTimers::Unpack, StageTimers::since(tic));

        runTime.setDeltaT(dt, false);
        ++runTime;
        Info<< "Step " << step << "  Time = " << runTime.timeName() << "  deltaT = " << dt
            << nl << endl;

        alphac.primitiveFieldRef() = epsNew;
        alphac.correctBoundaryConditions();
        alphacf = fvc::interpolate(alphac);

        // 2. the gas over the same step.
        while (pimple.loop())
        {
            tic = StageTimers::Clock::now();
            #include "UEqn.H"
            timers.add(StageTimers::UEqn, StageTimers::since(tic));

            while (pimple.correct())
            {
                tic = StageTimers::Clock::now();
                #include "pEqn.H"
                timers.add(StageTimers::PEqn, StageTimers::since(tic));
            }

            if (pimple.turbCorr())
            {
                laminarTransport.correct();
                turbulence->correct();
            }
        }
        tic = StageTimers::Clock::now();
        #include "TEqn.H"
        timers.add(StageTimers::TEqn, StageTimers::since(tic));
        tic = StageTimers::Clock::now();
        #include "YEqn.H"
        timers.add(StageTimers::YEqn, StageTimers::since(tic));
        #include "alphacContinuityErrs.H"

        // 3. ledgers (cumulative) and the Courant number of this step.
        {
            const scalarField& Tc = T.primitiveField();
            const scalarField& ac = alphac.primitiveField();
            const vectorField& Uc = U.primitiveField();
            double heat = 0, hom = 0, solid = 0, enthalpy = 0;
            double mom[3] = {0, 0, 0};
            std::vector<double> spec(nSpecies, 0.0);
            for (label c = 0; c < nCells; ++c)
            {
                heat += HTp[c] - Hheat[c]*Tc[c];
                hom += Qhom[c];
                solid += 1.0 - ac[c];
                enthalpy += ac[c]*Tc[c];
                for (direction a = 0; a < 3; ++a)
                {
                    mom[a] += KslUs[c][a] - Ksl[c]*Uc[c][a];
                }
                for (label k = 0; k < nSpecies; ++k) spec[k] += Rspecies[k][c];
            }
            ledgers.add(lHeat, heat*Vc*dt);
            ledgers.add(lHom, hom*Vc*dt);
            double mass = 0;
            for (label k = 0; k < nSpecies; ++k)
            {
                ledgers.add(lSpecies0 + k, spec[k]*Vc*dt);
                mass += spec[k];
            }
            ledgers.add(lMass, mass*Vc*dt);
            for (direction a = 0; a < 3; ++a) ledgers.add(lMom0 + a, mom[a]*Vc*dt);
            ledgers.set(lSolid, solid*Vc);
            ledgers.set(lEnthalpy, rhoCp*enthalpy*Vc);

            // Enthalpy entering through the boundary (J, relative to 0 K): advected, plus
            // conducted (the discrete flux of the laplacian term, a fixed-temperature inlet
            // heats the first cells by conduction too).
            double inflow = 0;
            forAll(mesh.boundary(), patchi)
            {
                const scalarField& ap = alphaPhi.boundaryField()[patchi];
                const fvPatchScalarField& Tp = T.boundaryField()[patchi];
                const scalarField snGradT(Tp.snGrad());
                const scalarField& af = alphacf.boundaryField()[patchi];
                const scalarField& magSf = mesh.magSf().boundaryField()[patchi];
                forAll(ap, facei)
                {
                    inflow -= ap[facei]*Tp[facei];
                    inflow += af[facei]*DT.value()*snGradT[facei]*magSf[facei];
                }
            }
            ledgers.add(lInflow, rhoCp*inflow*dt);
            for (label k = 0; k < nSpecies; ++k)
            {
                double out = 0;
                forAll(mesh.boundary(), patchi)
                {
                    const scalarField& ap = alphaPhi.boundaryField()[patchi];
                    const scalarField& yp = Y[k].boundaryField()[patchi];
                    forAll(ap, facei)
                    {
                        if (ap[facei] > 0) out += ap[facei]*yp[facei];
                    }
                }
                ledgers.set(lOut0 + k, rhog.value()*out);
            }
            if (dpPatches[0] >= 0)
            {
                ledgers.set
                (
                    lDp, rhog.value()*(patchMeanP(dpPatches[0]) - patchMeanP(dpPatches[1]))
                );
            }
        }
        scalar CoNum = 0;
        {
            const scalarField sumPhi(fvc::surfaceSum(mag(phi))().primitiveField());
            CoNum = 0.5*gMax(sumPhi/mesh.V().field())*dt;
        }
        Info<< "Courant Number max: " << CoNum << endl;

        // 4. checkpoint: binary time directory <dir>/openfoam/<time>/ + coredemFoam.restart.
        std::vector<std::string> files;
        if (coupling.requiresCheckpoint())
        {
            const fileName base(fileName(coupling.checkpointDir())/"openfoam");
            const word inst(runTime.timeName());
            const fileName dir(base/inst);
            mkDir(dir);
            writeBinary(U, dir);
            writeBinary(p, dir);
            writeBinary(T, dir);
            writeBinary(phi, dir);
            writeBinary(alphac, dir);
            forAll(Y, k) writeBinary(Y[k], dir);
            std::vector<std::string> names{"U", "p", "T", "phi", "alphac"};
            for (const std::string& s : speciesNames) names.push_back(s);

            const fileName tmp(base/"coredemFoam.restart.tmp");
            {
                std::ofstream out(tmp.c_str());
                out << "# coredemFoam checkpoint (times and ledgers as exact hex floats)\n"
                    << "step " << coupling.step() << "\n"
                    << "time " << hexDouble(runTime.value()) << "\n"
                    << "timeIndex " << runTime.timeIndex() << "\n"
                    << "instance " << inst.c_str() << "\n";
                for (std::size_t i = 0; i < ledgers.size(); ++i)
                {
                    out << "ledger " << ledgers.name(i) << ' ' << hexDouble(ledgers.sum(i))
                        << ' ' << hexDouble(ledgers.comp(i)) << "\n";
                }
                out.flush();
                if (!out)
                {
                    FatalErrorInFunction << "cannot write " << tmp << exit(FatalError);
                }
            }
            Foam::mv(tmp, base/"coredemFoam.restart");
            // The restart file first: coredem resume passes the first file back (-restart).
            files.push_back("openfoam/coredemFoam.restart");
            for (const std::string& n : names)
            {
                files.push_back("openfoam/" + std::string(inst) + "/" + n);
            }
            Info<< "Checkpoint of step " << step << " written to " << dir << endl;
        }

        try
        {
            // StepDone and the wait for the next grant (the orchestrator's side of the step).
            tic = StageTimers::Clock::now();
            coupling.advance(CoNum, ledgers.report(), files);
            timers.add(StageTimers::Advance, StageTimers::since(tic));
        }
        catch (const ::coredem::client::ClientError& e)
        {
            FatalErrorInFunction << "coupling, step " << step << ": " << e.what()
                << exit(FatalError);
        }

        runTime.write();
        runTime.printExecutionTime(Info);
        firstStep = false;
        ++steps;
        timers.endStep(StageTimers::since(tStep));
    }

    if (timersOn)
    {
        Info<< nl << timers.table(nCells, direct).c_str() << endl;
        const fileName file(runTime.path().path()/"timers-cfd.json");
        {
            std::ofstream out(file.c_str());
            out << timers.json(nCells, direct);
            if (!out)
            {
                FatalErrorInFunction << "cannot write " << file << exit(FatalError);
            }
        }
        Info<< "Timers written to " << file << endl;
    }

    runTime.writeNow();
    Info<< "Run finished after " << steps << " steps: " << coupling.shutdownReason().c_str()
        << nl << "End\n" << endl;
    coupling.finalize();
    return 0;
}
