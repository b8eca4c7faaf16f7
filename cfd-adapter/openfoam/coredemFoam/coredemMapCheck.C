// coredemMapCheck: builds coredemFoam's map between an OpenFOAM mesh and a coupling grid
// (couplingGrid.H) and checks it with synthetic fields, without a coupled run
// (tests/e2e/openfoam, docs/coredemFoam.md "Any mesh"):
//
//   volume      sum_g V_f,g = sum_c V_c
//   sources     DEM values s_g per grid-cell volume h^3 -> mesh: sum_c s_c V_c = sum_g s_g h^3
//               over the grid cells with fluid (3 components, pseudo-random values)
//   fraction    DEM PCM gas fractions e_g = 1 - V_s,g/h^3 -> mesh: sum_c (1 - e_c) V_c =
//               sum_g V_s,g, and a solid volume of phi V_f,g in every grid cell (partly filled
//               ones included) gives e_c = 1 - phi in every mesh cell
//   gather      a constant field stays constant; sum_g u_g V_f,g = sum_c u_c V_c (linear field)
//
// Each relative error is printed ("check <name>: <error>") and compared with -tol (default
// 1e-12): exit 1 when one exceeds it. A mesh the grid does not cover exits 2 (couplingGrid.C).
//
// Decomposed (mpirun -np K coredemMapCheck -parallel ...): each processor maps its own cells;
// the sums are over all processors and the gathered values are the processors' contributions
// added up (as the DEM server would add them in an M:1 exchange). "figure ..." lines give
// totals to compare with a serial run of the same mesh; each processor prints the grid cells its
// cells touch.
//
// Command line: coredemMapCheck -case DIR -origin '(x y z)' -spacing '(dx dy dz)'
//   -counts '(nx ny nz)' [-tol T] [-parallel]

#include "fvCFD.H"

#include "couplingGrid.H"
#include "IOmanip.H"

#include <cmath>
#include <vector>

namespace
{

//- Deterministic values in [0, 1).
double hash01(Foam::label i, Foam::label q)
{
    const double x = std::sin(12.9898*double(i) + 78.233*double(q + 1))*43758.5453;
    return x - std::floor(x);
}


//- The relative errors of the checks, and whether all are within the tolerance.
struct Checks
{
    double tol;
    bool ok = true;

    void report(const char* name, double err)
    {
        Foam::Info<< "check " << name << ": " << err << Foam::endl;
        if (!(err <= tol)) ok = false;
    }
};

//- The mesh's cell shapes and the map's size, printed before the checks.
void describe(const Foam::fvMesh& mesh, const CoredemGrid& grid, double seconds)
{
    using namespace Foam;
    if (Pstream::parRun())
    {
        Pout<< "touched: " << label(grid.touched().size()) << " of " << grid.gridCells()
            << " grid cells, " << mesh.nCells() << " mesh cells" << endl;
    }
    label nPoly = 0;
    forAll(mesh.cells(), c)
    {
        if (mesh.cells()[c].size() != 6 || mesh.cellPoints()[c].size() != 8) ++nPoly;
    }
    scalar minWidth = GREAT;
    forAll(mesh.cells(), c)
    {
        const boundBox bb(mesh.points(), mesh.cellPoints()[c], false);
        minWidth = min(minWidth, cmptMin(bb.span()));
    }
    reduce(nPoly, sumOp<label>());
    reduce(minWidth, minOp<scalar>());
    Info<< "mesh: " << nPoly << " cells not hexahedra, smallest cell width " << minWidth
        << " m" << endl;
    Info<< "map: " << returnReduce(mesh.nCells(), sumOp<label>()) << " mesh cells, "
        << grid.gridCells() << " grid cells, " << (grid.exact() ? "exact" : "overlap") << ", "
        << returnReduce(grid.overlapEntries(), sumOp<label>())
        << " overlaps, " << grid.partialCells() << " partial, " << grid.emptyCells()
        << " empty, weights in " << seconds << " s" << endl;
}

//- Sources (3 components): sum_c s_c V_c = sum_g s_g h^3 over the grid cells with fluid.
void checkSources(const Foam::fvMesh& mesh, const CoredemGrid& grid, Checks& checks)
{
    using namespace Foam;
    const label nCells = mesh.nCells();
    const label nGrid = grid.gridCells();
    const scalarField& V = mesh.V().field();
    const scalar vg = grid.cellVolume();
    const std::vector<double>& Vf = grid.fluidVolume();
    std::vector<double> s(std::size_t(nGrid)*3);
    for (label g = 0; g < nGrid; ++g)
    {
        for (label q = 0; q < 3; ++q) s[3*g + q] = (q == 2 ? -1 : 1)*hash01(g, q);
    }
    std::vector<double> cell(std::size_t(nCells)*3);
    grid.scatter(s.data(), 3, cell.data());
    double worst = 0;
    for (label q = 0; q < 3; ++q)
    {
        double dem = 0, abs = 0, cfd = 0;
        for (label g = 0; g < nGrid; ++g)
        {
            if (Vf[g] > 0)
            {
                dem += s[3*g + q]*vg;
                abs += mag(s[3*g + q])*vg;
            }
        }
        for (label c = 0; c < nCells; ++c) cfd += cell[3*c + q]*V[c];
        reduce(cfd, sumOp<scalar>());
        worst = max(worst, mag(cfd - dem)/abs);
    }
    checks.report("sources", worst);
}

//- Gas fraction: random solid volumes, then phi V_f in every grid cell.
void checkFraction(const Foam::fvMesh& mesh, const CoredemGrid& grid, Checks& checks)
{
    using namespace Foam;
    const label nCells = mesh.nCells();
    const label nGrid = grid.gridCells();
    const scalarField& V = mesh.V().field();
    const scalar vg = grid.cellVolume();
    const std::vector<double>& Vf = grid.fluidVolume();
    std::vector<double> eps(nGrid);
    double solid = 0;
    for (label g = 0; g < nGrid; ++g)
    {
        const double vs = 0.6*hash01(g, 7)*Vf[g];
        solid += vs;
        eps[g] = 1 - vs/vg;
    }
    scalarField e(nCells);
    grid.scatter(eps.data(), 1, e.data(), CoredemGrid::Quantity::GasFraction);
    double cfd = 0;
    forAll(e, c) cfd += (1 - e[c])*V[c];
    reduce(cfd, sumOp<scalar>());
    checks.report("fraction_solid_volume", mag(cfd - solid)/solid);
    checks.report("fraction_range", (gMin(e) > 0 && gMax(e) <= 1) ? 0 : 1);

    const double phi = 0.4;
    for (label g = 0; g < nGrid; ++g) eps[g] = 1 - phi*Vf[g]/vg;
    grid.scatter(eps.data(), 1, e.data(), CoredemGrid::Quantity::GasFraction);
    checks.report("fraction_uniform", gMax(mag(e - (1 - phi))));
}

//- Packed solid (clip epsMin): a bed of solid volume 0.45 min(V_f,g + h^3/4, h^3) in every grid
//  cell with fluid (more than its fluid volume's share 1 - epsMin in the slivers a wall leaves,
//  room to spare in the full cells around them), then a domain overfilled everywhere (0.7 V_f,g):
//  the solid volume the gas sees, plus what is booked as clipped, equals the DEM's deposit, and
//  only the overfilled domain clips ((0.7 - (1 - epsMin)) sum V_f,g).
void checkPacked
(
    const Foam::fvMesh& mesh, const CoredemGrid& grid, double epsMin, Checks& checks
)
{
    using namespace Foam;
    const label nGrid = grid.gridCells();
    const scalarField& V = mesh.V().field();
    const scalar vg = grid.cellVolume();
    const std::vector<double>& Vf = grid.fluidVolume();
    for (const char* which : {"packed", "overfilled"})
    {
        const bool packed = which[0] == 'p';
        std::vector<double> eps(nGrid);
        double solid = 0, fluid = 0;
        for (label g = 0; g < nGrid; ++g)
        {
            const double vs = Vf[g] > 0
                ? (packed ? 0.45*min(Vf[g] + 0.25*vg, vg) : 0.7*Vf[g])
                : 0.0;
            solid += vs;
            fluid += Vf[g];
            eps[g] = 1 - vs/vg;
        }
        // coredemFoam's pipeline: the solid limited on the grid (CouplingExchange), the scatter,
        // the round-off clip of GasFraction::read.
        const double clipped = grid.limitSolid(eps.data(), nGrid, nullptr, epsMin);
        scalarField e(mesh.nCells());
        grid.scatter(eps.data(), 1, e.data(), CoredemGrid::Quantity::GasFraction);
        checks.report((std::string(which) + "_below_clip").c_str(), max(epsMin - gMin(e), 0.0));
        e = max(min(e, scalar(1)), epsMin);
        double seen = 0;
        forAll(e, c) seen += (1 - e[c])*V[c];
        reduce(seen, sumOp<scalar>());
        const std::string name(which);
        checks.report((name + "_solid_volume").c_str(), mag(seen + clipped - solid)/solid);
        const double expected = packed ? 0.0 : (0.7 - (1 - epsMin))*fluid;
        checks.report((name + "_clipped").c_str(), mag(clipped - expected)/solid);
    }
}


//- Gather (decomposed: the processors' contributions added up, as the DEM server would): a
//  constant stays constant, and sum_g u_g V_f,g = sum_c u_c V_c for a linear field.
void checkGather(const Foam::fvMesh& mesh, const CoredemGrid& grid, double vFluid,
                 Checks& checks)
{
    using namespace Foam;
    const label nCells = mesh.nCells();
    const label nGrid = grid.gridCells();
    const scalarField& V = mesh.V().field();
    const std::vector<double>& Vf = grid.fluidVolume();
    auto combine = [&](std::vector<double>& out)
    {
        if (!Pstream::parRun()) return;
        List<scalar> sum(label(out.size()));
        forAll(sum, i) sum[i] = out[i];
        Pstream::listCombineGather(sum, plusEqOp<scalar>());
        Pstream::listCombineScatter(sum);
        forAll(sum, i) out[i] = sum[i];
    };
    std::vector<double> u(nCells, 3.5), out;
    grid.gather(u.data(), 1, out);
    combine(out);
    double worst = 0;
    for (const double v : out) worst = max(worst, mag(v - 3.5)/3.5);
    checks.report("gather_constant", worst);
    const vectorField& C = mesh.C().field();
    double cfd = 0, abs = 0;
    for (label c = 0; c < nCells; ++c)
    {
        u[c] = 1 + 100*C[c].x() - 50*C[c].y() + 20*C[c].z();
        cfd += u[c]*V[c];
        abs += mag(u[c])*V[c];
    }
    reduce(cfd, sumOp<scalar>());
    reduce(abs, sumOp<scalar>());
    grid.gather(u.data(), 1, out);
    combine(out);
    double dem = 0, umax = 0;
    for (label g = 0; g < nGrid; ++g)
    {
        dem += out[g]*Vf[g];
        umax = max(umax, out[g]);
    }
    checks.report("gather_conservative", mag(dem - cfd)/abs);
    // Figures to compare between a serial and a decomposed run of the same mesh.
    Info<< "figure fluid_volume: " << setprecision(17) << vFluid << nl
        << "figure gathered_total: " << dem << nl
        << "figure gathered_max: " << umax << setprecision(6) << endl;
}

} // namespace


int main(int argc, char* argv[])
{
    argList::addNote("checks coredemFoam's map between this mesh and a coupling grid");
    argList::addOption("origin", "vector", "coupling grid origin, m");
    argList::addOption("spacing", "vector", "coupling grid spacing, m");
    argList::addOption("counts", "vector", "coupling grid cells per axis");
    argList::addOption("tol", "scalar", "relative tolerance of every check (default 1e-12)");
    argList::addOption("epsMin", "scalar", "gas-fraction clip of the packed checks (default 0.35)");
    #include "setRootCase.H"
    #include "createTime.H"
    #include "createMesh.H"

    const vector origin(args.get<vector>("origin"));
    const vector spacing(args.get<vector>("spacing"));
    const vector counts(args.get<vector>("counts"));
    const scalar tol = args.getOrDefault<scalar>("tol", 1e-12);
    const scalar epsMin = args.getOrDefault<scalar>("epsMin", 0.35);

    const clock_t t0 = std::clock();
    const CoredemGrid grid
    (
        mesh, origin, spacing,
        label(counts.x() + 0.5), label(counts.y() + 0.5), label(counts.z() + 0.5)
    );
    describe(mesh, grid, double(std::clock() - t0)/CLOCKS_PER_SEC);

    Checks checks{tol};
    // Volume.
    const double vMesh = gSum(mesh.V().field());
    double vFluid = 0;
    for (const double v : grid.fluidVolume()) vFluid += v;
    checks.report("volume", mag(vFluid - vMesh)/vMesh);
    checkSources(mesh, grid, checks);
    checkFraction(mesh, grid, checks);
    checkPacked(mesh, grid, epsMin, checks);
    checkGather(mesh, grid, vFluid, checks);

    Info<< (checks.ok ? "map checks passed" : "map checks FAILED") << nl << "End" << endl;
    return checks.ok ? 0 : 1;
}
