#include "couplingGrid.H"

#include <cmath>
#include <vector>

namespace Foam
{

CoredemGrid::CoredemGrid
(
    const fvMesh& mesh,
    const vector& origin,
    const vector& spacing,
    const label nx, const label ny, const label nz
)
:
    o_(origin),
    h_(spacing),
    n_{nx, ny, nz},
    nGrid_(nx*ny*nz),
    gridIndex_(mesh.nCells(), -1),
    identity_(false)
{
    for (direction a = 0; a < 3; ++a)
    {
        if (!(h_[a] > 0) || n_[a] < 1)
        {
            FatalErrorInFunction
                << "invalid coupling grid from the orchestrator: spacing " << h_
                << ", counts (" << nx << ' ' << ny << ' ' << nz << ")" << exit(FatalError);
        }
    }
    if (Pstream::parRun())
    {
        FatalErrorInFunction
            << "coredemFoam v1 runs serially; the coupling map is written for decomposed cases "
            << "(global grid indices per cell) but the exchange is not. Run without -parallel."
            << exit(FatalError);
    }

    // Tolerance for cell corners: 1e-6 of the smallest spacing.
    const scalar tol = 1e-6*min(h_.x(), min(h_.y(), h_.z()));
    const pointField& pts = mesh.points();
    const cellList& cells = mesh.cells();
    std::vector<label> owner(nGrid_, -1);

    forAll(cells, celli)
    {
        const labelList cp(cells[celli].labels(mesh.faces()));
        const point& c = mesh.cellCentres()[celli];
        label ijk[3];
        for (direction a = 0; a < 3; ++a)
        {
            ijk[a] = label(std::floor((c[a] - o_[a])/h_[a]));
        }
        const bool inside =
            ijk[0] >= 0 && ijk[0] < n_[0] && ijk[1] >= 0 && ijk[1] < n_[1]
         && ijk[2] >= 0 && ijk[2] < n_[2];
        if (!inside)
        {
            FatalErrorInFunction
                << "mesh cell " << celli << " (centre " << c << ") lies outside the coupling "
                << "grid [" << o_ << ", " << (o_ + cmptMultiply(h_, vector(n_[0], n_[1], n_[2])))
                << "]: the OpenFOAM mesh must be the case's grid (case.yaml grid: origin, "
                << "spacing, cells)" << exit(FatalError);
        }
        if (cp.size() != 8 || cells[celli].size() != 6)
        {
            FatalErrorInFunction
                << "mesh cell " << celli << " (centre " << c << ") has " << cp.size()
                << " points and " << cells[celli].size() << " faces: coupling mesh v1 needs a "
                << "uniform Cartesian block of hexahedra (blockMesh, one block, simpleGrading 1)"
                << exit(FatalError);
        }
        boundBox bb(pts, cp, false);
        for (direction a = 0; a < 3; ++a)
        {
            const scalar lo = o_[a] + ijk[a]*h_[a];
            const scalar hi = lo + h_[a];
            if (mag(bb.min()[a] - lo) > tol || mag(bb.max()[a] - hi) > tol)
            {
                FatalErrorInFunction
                    << "mesh cell " << celli << " (centre " << c << ") spans " << bb
                    << " but coupling-grid cell (" << ijk[0] << ' ' << ijk[1] << ' ' << ijk[2]
                    << ") spans [" << (o_ + cmptMultiply(h_, vector(ijk[0], ijk[1], ijk[2])))
                    << ", " << (o_ + cmptMultiply(h_, vector(ijk[0]+1, ijk[1]+1, ijk[2]+1)))
                    << "]: the mesh must be a uniform Cartesian block equal to the case's "
                    << "grid (axis-aligned, spacing " << h_ << ")" << exit(FatalError);
            }
        }
        const label g = ijk[0] + n_[0]*(ijk[1] + n_[1]*ijk[2]);
        if (owner[g] >= 0)
        {
            FatalErrorInFunction
                << "mesh cells " << owner[g] << " and " << celli << " both lie in coupling-grid "
                << "cell (" << ijk[0] << ' ' << ijk[1] << ' ' << ijk[2] << ")" << exit(FatalError);
        }
        owner[g] = celli;
        gridIndex_[celli] = g;
    }
    if (mesh.nCells() != nGrid_)
    {
        label missing = 0;
        while (missing < nGrid_ && owner[missing] >= 0) ++missing;
        const label i = missing % n_[0];
        const label j = (missing/n_[0]) % n_[1];
        const label k = missing/(n_[0]*n_[1]);
        FatalErrorInFunction
            << "the mesh has " << mesh.nCells() << " cells but the coupling grid " << nGrid_
            << " (" << n_[0] << " x " << n_[1] << " x " << n_[2] << "); grid cell (" << i << ' '
            << j << ' ' << k << ") has no mesh cell. Make blockMeshDict match case.yaml's grid."
            << exit(FatalError);
    }
    identity_ = true;
    forAll(gridIndex_, celli)
    {
        if (gridIndex_[celli] != celli) identity_ = false;
    }
}


void CoredemGrid::gather
(
    const scalar* cellValues, label nComp, std::vector<double>& out
) const
{
    out.assign(std::size_t(nGrid_)*nComp, 0.0);
    forAll(gridIndex_, celli)
    {
        const label g = gridIndex_[celli];
        for (label q = 0; q < nComp; ++q)
        {
            out[std::size_t(g)*nComp + q] = cellValues[celli*nComp + q];
        }
    }
}


void CoredemGrid::scatter
(
    const double* gridValues, label nComp, scalar* cellValues
) const
{
    forAll(gridIndex_, celli)
    {
        const label g = gridIndex_[celli];
        for (label q = 0; q < nComp; ++q)
        {
            cellValues[celli*nComp + q] = gridValues[std::size_t(g)*nComp + q];
        }
    }
}

} // namespace Foam
