#include "couplingGrid.H"

// tetrahedron.H before tetPoints.H: it includes tetPoints.H after declaring tetrahedron (the
// other order leaves tetPoints incomplete where tetrahedronI.H uses it).
#include "tetrahedron.H"
#include "tetPoints.H"

#include "boundBox.H"
#include "plane.H"

#include <algorithm>
#include <cmath>
#include <vector>

namespace Foam
{

namespace
{

//- sliceWithPlane operations: keep the pieces on one side, drop the others.
struct KeepTets
{
    std::vector<tetPoints>& kept;
    void operator()(const tetPoints& t) { kept.push_back(t); }
};

struct DropTets
{
    void operator()(const tetPoints&) {}
};


//- Volume of tetrahedron `tet` inside the axis-aligned box [lo, hi]: the tetrahedron clipped by
//  the box's six planes (normals into the box; sliceWithPlane's "above" side is kept).
scalar tetBoxOverlap
(
    const tetPoints& tet,
    const point& lo,
    const point& hi,
    std::vector<tetPoints>& a,
    std::vector<tetPoints>& b
)
{
    a.assign(1, tet);
    DropTets drop;
    for (direction axis = 0; axis < 3; ++axis)
    {
        for (int side = 0; side < 2; ++side)
        {
            vector n(Zero);
            n[axis] = side == 0 ? 1 : -1;
            const plane pl(side == 0 ? lo : hi, n, false);
            b.clear();
            KeepTets keep{b};
            for (const tetPoints& t : a) t.tet().sliceWithPlane(pl, keep, drop);
            a.swap(b);
            if (a.empty()) return 0;
        }
    }
    scalar v = 0;
    for (const tetPoints& t : a) v += t.tet().mag();
    return v;
}

} // namespace


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
    exact_(false),
    identity_(false),
    nPartial_(0),
    nEmpty_(0),
    gridIndex_(mesh.nCells(), -1),
    cellVol_(mesh.V().field()),
    cellWeight_(mesh.nCells(), 1.0),
    fluidVolume_(std::size_t(nGrid_), cellVolume()),
    fluidScale_(std::size_t(nGrid_), 1.0)
{
    for (direction a = 0; a < 3; ++a)
    {
        if (!(h_[a] > 0) || n_[a] < 1)
        {
            FatalErrorInFunction
                << "invalid coupling grid from the orchestrator: spacing " << h_
                << ", counts (" << nx << ' ' << ny << ' ' << nz << ")" << exit(FatalError, 2);
        }
    }
    // Is the mesh the grid? Every cell a hexahedron whose bounding box is one grid cell
    // (tolerance 1e-6 of the smallest spacing), every grid cell covered once.
    const scalar tol = 1e-6*min(h_.x(), min(h_.y(), h_.z()));
    const pointField& pts = mesh.points();
    const cellList& cells = mesh.cells();
    // A processor's share of a decomposed mesh is never the whole grid: overlap map.
    exact_ = mesh.nCells() == nGrid_ && !Pstream::parRun();
    std::vector<label> owner(exact_ ? nGrid_ : 0, -1);
    for (label celli = 0; exact_ && celli < mesh.nCells(); ++celli)
    {
        const labelList cp(cells[celli].labels(mesh.faces()));
        const point& c = mesh.cellCentres()[celli];
        label ijk[3];
        for (direction a = 0; a < 3; ++a)
        {
            ijk[a] = label(std::floor((c[a] - o_[a])/h_[a]));
            if (ijk[a] < 0 || ijk[a] >= n_[a]) exact_ = false;
        }
        if (!exact_ || cp.size() != 8 || cells[celli].size() != 6)
        {
            exact_ = false;
            break;
        }
        boundBox bb(pts, cp, false);
        for (direction a = 0; a < 3; ++a)
        {
            const scalar lo = o_[a] + ijk[a]*h_[a];
            const scalar hi = lo + h_[a];
            if (mag(bb.min()[a] - lo) > tol || mag(bb.max()[a] - hi) > tol) exact_ = false;
        }
        const label g = ijk[0] + n_[0]*(ijk[1] + n_[1]*ijk[2]);
        if (!exact_ || owner[g] >= 0)
        {
            exact_ = false;
            break;
        }
        owner[g] = celli;
        gridIndex_[celli] = g;
    }
    if (exact_)
    {
        identity_ = true;
        forAll(gridIndex_, celli)
        {
            if (gridIndex_[celli] != celli) identity_ = false;
        }
        return;
    }
    gridIndex_.clear();
    computeOverlaps(mesh);
}


void CoredemGrid::computeOverlaps(const fvMesh& mesh)
{
    const pointField& pts = mesh.points();
    const cellList& cells = mesh.cells();
    const faceList& faces = mesh.faces();
    const vectorField& cc = mesh.cellCentres();
    const vectorField& fc = mesh.faceCentres();
    const label nCells = mesh.nCells();
    const point top(o_ + cmptMultiply(h_, vector(n_[0], n_[1], n_[2])));

    rowStart_.assign(std::size_t(nCells) + 1, 0);
    overlapGrid_.clear();
    overlapVol_.clear();
    std::vector<tetPoints> cellTets, a, b;
    std::vector<std::pair<label, double>> row;

    for (label celli = 0; celli < nCells; ++celli)
    {
        const labelList cp(cells[celli].labels(faces));
        const boundBox bb(pts, cp, false);
        label lo[3], hi[3];
        bool outside = false;
        for (direction d = 0; d < 3; ++d)
        {
            lo[d] = label(std::floor((bb.min()[d] - o_[d])/h_[d]));
            hi[d] = label(std::floor((bb.max()[d] - o_[d])/h_[d]));
            // A cell face on a grid plane touches the next grid cell with zero volume.
            if (hi[d] > lo[d] && o_[d] + hi[d]*h_[d] >= bb.max()[d]) --hi[d];
            if (lo[d] < 0 || hi[d] >= n_[d]) outside = true;
            lo[d] = max(lo[d], label(0));
            hi[d] = min(hi[d], n_[d] - 1);
        }
        row.clear();
        if (!outside && lo[0] == hi[0] && lo[1] == hi[1] && lo[2] == hi[2])
        {
            // Inside one grid cell: all of its volume there.
            row.emplace_back(lo[0] + n_[0]*(lo[1] + n_[1]*lo[2]), cellVol_[celli]);
        }
        else
        {
            // Tetrahedra (cell centre, face centre, edge) clipped by every grid cell in reach.
            cellTets.clear();
            for (const label facei : cells[celli])
            {
                const face& f = faces[facei];
                forAll(f, pi)
                {
                    // Positive orientation (mag() > 0): sliceWithPlane's prism splits
                    // assume it.
                    const point& p0 = pts[f[pi]];
                    const point& p1 = pts[f[f.fcIndex(pi)]];
                    const tetPoints t(cc[celli], fc[facei], p0, p1);
                    const scalar v = t.tet().mag();
                    if (v > 0) cellTets.push_back(t);
                    else if (v < 0) cellTets.push_back(tetPoints(cc[celli], fc[facei], p1, p0));
                }
            }
            scalar covered = 0;
            for (label k = lo[2]; k <= hi[2]; ++k)
            {
                for (label j = lo[1]; j <= hi[1]; ++j)
                {
                    for (label i = lo[0]; i <= hi[0]; ++i)
                    {
                        const point blo(o_ + cmptMultiply(h_, vector(i, j, k)));
                        const point bhi(o_ + cmptMultiply(h_, vector(i + 1, j + 1, k + 1)));
                        scalar v = 0;
                        for (const tetPoints& t : cellTets)
                        {
                            v += tetBoxOverlap(t, blo, bhi, a, b);
                        }
                        if (v > 0)
                        {
                            row.emplace_back(i + n_[0]*(j + n_[1]*k), v);
                            covered += v;
                        }
                    }
                }
            }
            // The grid must cover the cell (its tetrahedra: mag of their volumes).
            scalar tetVol = 0;
            for (const tetPoints& t : cellTets) tetVol += t.tet().mag();
            if (!(covered >= (1 - 1e-6)*tetVol) || row.empty())
            {
                FatalErrorInFunction
                    << "mesh cell " << celli << " (centre " << cc[celli] << ", bounds " << bb
                    << ") lies " << 100*(1 - covered/tetVol) << "% outside the coupling grid ["
                    << o_ << ", " << top << "]: the coupling grid must cover the fluid domain "
                    << "(case.yaml grid: origin, spacing, cells)" << exit(FatalError, 2);
            }
            // Scale the row to the cell's volume: sum_g A(c, g) = V_c.
            const scalar s = cellVol_[celli]/covered;
            for (auto& e : row) e.second *= s;
        }
        for (const auto& e : row)
        {
            overlapGrid_.push_back(e.first);
            overlapVol_.push_back(e.second);
        }
        rowStart_[celli + 1] = label(overlapVol_.size());
    }

    sumFluidVolumes();
}


void CoredemGrid::sumFluidVolumes()
{
    // Fluid volume of every grid cell and the correction of the DEM's per-h^3 values.
    const scalar vg = cellVolume();
    std::fill(fluidVolume_.begin(), fluidVolume_.end(), 0.0);
    for (std::size_t e = 0; e < overlapVol_.size(); ++e)
    {
        fluidVolume_[overlapGrid_[e]] += overlapVol_[e];
    }
    // The grid cells this processor's cells touch, with its part of their fluid volume.
    for (label g = 0; g < nGrid_; ++g)
    {
        if (fluidVolume_[g] > 0)
        {
            touched_.push_back(g);
            partialVolume_.push_back(fluidVolume_[g]);
        }
    }
    {
        std::vector<label> pos(std::size_t(nGrid_), -1);
        for (std::size_t t = 0; t < touched_.size(); ++t) pos[touched_[t]] = label(t);
        overlapTouched_.resize(overlapGrid_.size());
        for (std::size_t e = 0; e < overlapGrid_.size(); ++e)
        {
            overlapTouched_[e] = pos[overlapGrid_[e]];
        }
    }
    if (Pstream::parRun())
    {
        // Decomposed: the fluid volume is the sum of the processors' parts (once per mesh).
        List<scalar> total(nGrid_);
        for (label g = 0; g < nGrid_; ++g) total[g] = fluidVolume_[g];
        Pstream::listCombineGather(total, plusEqOp<scalar>());
        Pstream::listCombineScatter(total);
        for (label g = 0; g < nGrid_; ++g) fluidVolume_[g] = total[g];
    }
    for (label g = 0; g < nGrid_; ++g)
    {
        const double vf = fluidVolume_[g];
        if (vf <= 1e-12*vg)
        {
            fluidVolume_[g] = 0;
            fluidScale_[g] = 0;
            ++nEmpty_;
        }
        else if (mag(vf - vg) <= 1e-12*vg)
        {
            // All fluid (to round-off).
            fluidVolume_[g] = vg;
            fluidScale_[g] = 1;
        }
        else
        {
            if (vf > vg*(1 + 1e-6))
            {
                FatalErrorInFunction
                    << "coupling-grid cell " << describe(g) << " overlaps " << vf << " m3 of mesh "
                    << "cells, more than its volume " << vg << " m3: the mesh has overlapping "
                    << "cells" << exit(FatalError, 2);
            }
            fluidScale_[g] = vg/vf;
            ++nPartial_;
        }
    }
    forAll(cellWeight_, celli) cellWeight_[celli] = cellVol_[celli]/vg;
}


string CoredemGrid::describe(label g) const
{
    const label i = g % n_[0];
    const label j = (g/n_[0]) % n_[1];
    const label k = g/(n_[0]*n_[1]);
    OStringStream os;
    os  << '(' << i << ' ' << j << ' ' << k << ") ["
        << (o_ + cmptMultiply(h_, vector(i, j, k))) << ", "
        << (o_ + cmptMultiply(h_, vector(i + 1, j + 1, k + 1))) << ']';
    return os.str();
}


void CoredemGrid::gather
(
    const scalar* cellValues, label nComp, std::vector<double>& out
) const
{
    out.assign(std::size_t(nGrid_)*nComp, 0.0);
    if (exact_)
    {
        forAll(gridIndex_, celli)
        {
            const label g = gridIndex_[celli];
            for (label q = 0; q < nComp; ++q)
            {
                out[std::size_t(g)*nComp + q] = cellValues[celli*nComp + q];
            }
        }
        return;
    }
    // Overlap-weighted averages; grid cells without fluid get the domain's average. Decomposed,
    // each processor's values are its contributions sum_{c here} A u_c / V_f,g, which add up
    // over the processors to the average (the domain average of empty cells is the master's).
    std::vector<double> total(std::size_t(nComp), 0.0);
    double volume = 0;
    const label nCells = label(rowStart_.size()) - 1;
    for (label celli = 0; celli < nCells; ++celli)
    {
        const scalar* v = cellValues + std::size_t(celli)*nComp;
        for (label e = rowStart_[celli]; e < rowStart_[celli + 1]; ++e)
        {
            const double w = overlapVol_[e];
            double* o = out.data() + std::size_t(overlapGrid_[e])*nComp;
            for (label q = 0; q < nComp; ++q) o[q] += w*v[q];
        }
        for (label q = 0; q < nComp; ++q) total[q] += cellVol_[celli]*v[q];
        volume += cellVol_[celli];
    }
    if (Pstream::parRun())
    {
        for (label q = 0; q < nComp; ++q) reduce(total[q], sumOp<scalar>());
        reduce(volume, sumOp<scalar>());
        if (!Pstream::master()) volume = -1;
    }
    for (label g = 0; g < nGrid_; ++g)
    {
        double* o = out.data() + std::size_t(g)*nComp;
        const double vf = fluidVolume_[g];
        for (label q = 0; q < nComp; ++q)
        {
            o[q] = vf > 0 ? o[q]/vf : (volume > 0 ? total[q]/volume : 0.0);
        }
    }
}


void CoredemGrid::gatherTouched
(
    const scalar* cellValues, label nComp, std::vector<double>& out
) const
{
    std::vector<double> full;
    gather(cellValues, nComp, full);
    out.resize(touched_.size()*std::size_t(nComp));
    for (std::size_t t = 0; t < touched_.size(); ++t)
    {
        for (label q = 0; q < nComp; ++q)
        {
            out[t*nComp + q] = full[std::size_t(touched_[t])*nComp + q];
        }
    }
}


void CoredemGrid::scatter
(
    const double* gridValues, label nComp, scalar* cellValues, Quantity quantity
) const
{
    if (exact_)
    {
        forAll(gridIndex_, celli)
        {
            const label g = gridIndex_[celli];
            for (label q = 0; q < nComp; ++q)
            {
                cellValues[celli*nComp + q] = gridValues[std::size_t(g)*nComp + q];
            }
        }
        return;
    }
    scatterRows(gridValues, nComp, cellValues, quantity, nGrid_, nullptr, overlapGrid_);
}

void CoredemGrid::sumTouched
(
    const scalar* cellValues, label nComp, std::vector<double>& out
) const
{
    out.assign(touched_.size()*std::size_t(nComp), 0.0);
    const label nCells = label(rowStart_.size()) - 1;
    for (label celli = 0; celli < nCells; ++celli)
    {
        const scalar* v = cellValues + std::size_t(celli)*nComp;
        for (label e = rowStart_[celli]; e < rowStart_[celli + 1]; ++e)
        {
            const label t = overlapTouched_[e];
            if (t < 0) continue;
            const double w = overlapVol_[e];
            double* o = out.data() + std::size_t(t)*nComp;
            for (label q = 0; q < nComp; ++q) o[q] += w*v[q];
        }
    }
}


void CoredemGrid::scatterTouched
(
    const double* touchedValues, label nComp, scalar* cellValues, Quantity quantity
) const
{
    scatterRows
    (
        touchedValues, nComp, cellValues, quantity, label(touched_.size()), touched_.data(),
        overlapTouched_
    );
}


double CoredemGrid::limitSolid
(
    double* rowValues,
    label nRows,
    const label* rowGrid,
    const scalar epsMin
) const
{
    // Solid volume of every grid cell (decomposed: of every grid cell a processor touches; each
    // one receives the DEM server's same value for it).
    const scalar vg = cellVolume();
    std::vector<double> vs(std::size_t(nGrid_), 0.0);
    for (label t = 0; t < nRows; ++t)
    {
        vs[rowGrid ? rowGrid[t] : t] = (1 - rowValues[t])*vg;
    }
    if (Pstream::parRun())
    {
        List<scalar> all(nGrid_);
        for (label g = 0; g < nGrid_; ++g) all[g] = vs[g];
        Pstream::listCombineGather(all, maxEqOp<scalar>());
        Pstream::listCombineScatter(all);
        for (label g = 0; g < nGrid_; ++g) vs[g] = all[g];
    }
    // Room of a grid cell: (1 - epsMin) V_f,g. The excess of a cell goes to the free room of the
    // grid cells with fluid around it, in cubes of 3^3, 5^3, .. (2 kSpreadReach + 1)^3 cells,
    // shared in proportion to the free room; cells in ascending order.
    const double fill = 1 - epsMin;
    double clipped = 0;
    // The grid cells whose solid changed (the others keep the DEM's value bit for bit).
    std::vector<char> moved(std::size_t(nGrid_), 0);
    for (label g = 0; g < nGrid_; ++g)
    {
        const double room = fill*fluidVolume_[g];
        double excess = vs[g] - room;
        if (!(excess > 0) || fluidVolume_[g] == 0) continue;
        const label gi = g % n_[0];
        const label gj = (g/n_[0]) % n_[1];
        const label gk = g/(n_[0]*n_[1]);
        for (label r = 1; r <= kSpreadReach && excess > 0; ++r)
        {
            const label lo[3] =
                {max(gi - r, label(0)), max(gj - r, label(0)), max(gk - r, label(0))};
            const label hi[3] =
                {min(gi + r, n_[0] - 1), min(gj + r, n_[1] - 1), min(gk + r, n_[2] - 1)};
            double freeRoom = 0;
            for (int pass = 0; pass < 2; ++pass)
            {
                const double share = pass == 1 ? min(excess, freeRoom)/freeRoom : 0;
                for (label k = lo[2]; k <= hi[2]; ++k)
                {
                    for (label j = lo[1]; j <= hi[1]; ++j)
                    {
                        for (label i = lo[0]; i <= hi[0]; ++i)
                        {
                            const label n = i + n_[0]*(j + n_[1]*k);
                            const double f = fill*fluidVolume_[n] - vs[n];
                            if (n == g || !(f > 0)) continue;
                            if (pass == 0) freeRoom += f;
                            else
                            {
                                vs[n] += share*f;
                                moved[n] = 1;
                            }
                        }
                    }
                }
                if (!(freeRoom > 0)) break;
                if (pass == 1) excess -= min(excess, freeRoom);
            }
        }
        // What finds no room is clipped (booked by the caller).
        if (excess > 0) clipped += excess;
        vs[g] = room;
        moved[g] = 1;
    }
    for (label t = 0; t < nRows; ++t)
    {
        const label g = rowGrid ? rowGrid[t] : t;
        if (moved[g]) rowValues[t] = 1 - vs[g]/vg;
    }
    return clipped;
}


void CoredemGrid::scatterRows
(
    const double* rowValues,
    label nComp,
    scalar* cellValues,
    Quantity quantity,
    label nRows,
    const label* rowGrid,
    const std::vector<label>& overlapRow
) const
{
    const bool fraction = quantity == Quantity::GasFraction;
    if (fraction)
    {
        // Solid in a grid cell without fluid: a particle outside the fluid domain.
        for (label t = 0; t < nRows; ++t)
        {
            const label g = rowGrid ? rowGrid[t] : t;
            if (fluidScale_[g] == 0 && rowValues[t] < 1)
            {
                FatalErrorInFunction
                    << "coupling-grid cell " << describe(g) << " holds particles ("
                    << (1 - rowValues[t])*cellVolume() << " m3 of solid) but no fluid: a "
                    << "particle lies outside the CFD domain (check the walls against the mesh)"
                    << exit(FatalError);
            }
        }
    }
    const label nCells = label(rowStart_.size()) - 1;
    for (label celli = 0; celli < nCells; ++celli)
    {
        scalar* c = cellValues + std::size_t(celli)*nComp;
        for (label q = 0; q < nComp; ++q) c[q] = 0;
        for (label e = rowStart_[celli]; e < rowStart_[celli + 1]; ++e)
        {
            const label t = overlapRow[e];
            if (t < 0) continue;
            const double w = overlapVol_[e];
            const double r = fluidScale_[overlapGrid_[e]];
            const double* s = rowValues + std::size_t(t)*nComp;
            for (label q = 0; q < nComp; ++q)
            {
                c[q] += w*(fraction ? 1 - (1 - s[q])*r : s[q]*r);
            }
        }
        for (label q = 0; q < nComp; ++q) c[q] /= cellVol_[celli];
    }
}

} // namespace Foam
