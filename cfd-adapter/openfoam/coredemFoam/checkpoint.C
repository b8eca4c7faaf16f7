#include "checkpoint.H"

#include "OFstream.H"
#include "OSspecific.H"
#include "Pstream.H"

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace Foam
{

namespace
{

std::string hexDouble(double v)
{
    char buf[64];
    std::snprintf(buf, sizeof buf, "%a", v);
    return buf;
}

// Writes a field as <dir>/<name> in binary (full precision) with its usual FoamFile header.
// The header's location is the time name (not where the field was read from), so a restarted
// run writes the same bytes as an uninterrupted one.
void writeBinary(regIOobject& f, const fileName& dir)
{
    f.instance() = f.time().timeName();
    OFstream os(dir/f.name(), IOstream::BINARY);
    f.writeHeader(os);
    f.writeData(os);
    IOobject::writeEndDivider(os);
    if (!os.good())
    {
        FatalErrorInFunction
            << "cannot write checkpoint file " << os.name() << exit(FatalError);
    }
}

} // namespace


std::vector<std::string> Checkpoint::write
(
    const fileName& dir,
    std::int64_t step,
    const GasLedgers& ledgers
) const
{
    const fileName base(dir/"openfoam");
    const word inst(runTime_.timeName());
    // Decomposed: each processor writes its fields into openfoam/processorN/<time> (the layout
    // of a decomposed case); the master the restart file and the list of every processor's.
    const word proc(Pstream::parRun() ? "processor" + Foam::name(Pstream::myProcNo()) : "");
    const fileName timeDir(Pstream::parRun() ? base/proc/inst : base/inst);
    mkDir(timeDir);
    for (regIOobject* f : fields_) writeBinary(*f, timeDir);
    if (Pstream::parRun())
    {
        // Every processor's files are closed before the master lists them: the orchestrator
        // checks each listed file as soon as the StepDone arrives (without this, a slower
        // processor was still writing when the master reported).
        bool written = true;
        reduce(written, andOp<bool>());
    }
    if (!Pstream::master())
    {
        return {};
    }

    const fileName tmp(base/"coredemFoam.restart.tmp");
    {
        std::ofstream out(tmp.c_str());
        out << "# coredemFoam checkpoint (times and ledgers as exact hex floats)\n"
            << "step " << step << "\n"
            << "time " << hexDouble(runTime_.value()) << "\n"
            << "timeIndex " << runTime_.timeIndex() << "\n"
            << "instance " << inst.c_str() << "\n";
        for (const GasLedgers::Ledger* l : ledgers.all())
        {
            out << "ledger " << l->name() << ' ' << hexDouble(l->value()) << ' '
                << hexDouble(l->compensation()) << "\n";
        }
        out.flush();
        if (!out)
        {
            FatalErrorInFunction << "cannot write " << tmp << exit(FatalError);
        }
    }
    Foam::mv(tmp, base/"coredemFoam.restart");

    std::vector<std::string> files{"openfoam/coredemFoam.restart"};
    for (label p = 0; p < (Pstream::parRun() ? Pstream::nProcs() : 1); ++p)
    {
        const std::string sub =
            Pstream::parRun() ? "processor" + std::to_string(p) + "/" : std::string();
        for (const regIOobject* f : fields_)
        {
            files.push_back("openfoam/" + sub + std::string(inst) + "/" + std::string(f->name()));
        }
    }
    Info<< "Checkpoint of step " << label(step) << " written to " << timeDir << endl;
    return files;
}


RestartInfo Checkpoint::read(const fileName& file)
{
    std::ifstream in(file.c_str());
    if (!in)
    {
        FatalErrorInFunction
            << "cannot read restart file " << file << " (pass the coredemFoam.restart of a "
            << "checkpoint that coredemFoam wrote)" << exit(FatalError);
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
        else if (key == "timeIndex") { r.timeIndex = label(std::stol(a)); }
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
            << "coredemFoam checkpoint" << exit(FatalError);
    }
    return r;
}


void Checkpoint::restoreLedgers(const RestartInfo& restart, GasLedgers& ledgers)
{
    for (std::size_t i = 0; i < restart.ledgerNames.size(); ++i)
    {
        GasLedgers::Ledger* l = ledgers.find(restart.ledgerNames[i]);
        if (l == nullptr)
        {
            FatalErrorInFunction
                << "the restart file has ledger " << restart.ledgerNames[i].c_str()
                << ", which this case does not produce (another species list?)"
                << exit(FatalError);
        }
        l->restore(restart.ledgerSum[i], restart.ledgerComp[i]);
    }
}

} // namespace Foam
