#include "cellLocator.H"

#include <algorithm>
#include <cmath>

// * * * * * * * * * * * * * Private Member Functions  * * * * * * * * * * * //

Foam::label Foam::diefill::cellLocator::binIndex
(
    scalar x,
    scalar origin,
    scalar perMetre,
    label n
)
{
    const scalar s = (x - origin)*perMetre;
    if (!(s > 0))  // also NaN
    {
        return 0;
    }
    return s >= n ? n - 1 : label(s);
}


// * * * * * * * * * * * * * * * * Constructors  * * * * * * * * * * * * * * //

Foam::diefill::cellLocator::cellLocator(const polyMesh& mesh)
:
    mesh_(mesh),
    bounds_(boundBox::invertedBox),
    cellBounds_(mesh.nCells())
{
    const label nCells = mesh.nCells();
    if (nCells == 0)
    {
        binStart_.setSize(1, 0);
        return;
    }

    const pointField& points = mesh.points();
    const labelListList& cellPoints = mesh.cellPoints();
    forAll(cellBounds_, celli)
    {
        cellBounds_[celli] = boundBox(points, cellPoints[celli], false);
        bounds_.add(cellBounds_[celli]);
    }
    // Points on a cell's box count as inside it, after round-off
    const vector tolerance(vector::one*1e-9*mag(bounds_.span()));
    for (boundBox& bb : cellBounds_)
    {
        bb.min() -= tolerance;
        bb.max() += tolerance;
    }
    bounds_.min() -= tolerance;
    bounds_.max() += tolerance;

    // About one cell per bin: the bin edge is the mean cell size, at most
    // 4 bins per cell in all (thin or sparse meshes)
    const vector span = bounds_.span();
    scalar edge = std::cbrt(span.x()*span.y()*span.z()/nCells);
    label n[3];
    for (label attempt = 0; ; ++attempt)
    {
        for (direction d = 0; d < 3; ++d)
        {
            n[d] = edge > 0 ? max(label(1), label(std::lround(span[d]/edge))) : 1;
        }
        if (scalar(n[0])*n[1]*n[2] <= 4.0*nCells + 8 || attempt > 60)
        {
            break;
        }
        edge *= 1.25;
    }
    nx_ = n[0];
    ny_ = n[1];
    nz_ = n[2];
    for (direction d = 0; d < 3; ++d)
    {
        binsPerMetre_[d] = n[d]/span[d];
    }

    // Count, then fill (compressed rows)
    const point& o = bounds_.min();
    auto binRange = [&](const boundBox& bb, label lo[3], label hi[3])
    {
        for (direction d = 0; d < 3; ++d)
        {
            lo[d] = binIndex(bb.min()[d], o[d], binsPerMetre_[d], n[d]);
            hi[d] = binIndex(bb.max()[d], o[d], binsPerMetre_[d], n[d]);
        }
    };
    binStart_.setSize(nBins() + 1, 0);
    for (const boundBox& bb : cellBounds_)
    {
        label lo[3], hi[3];
        binRange(bb, lo, hi);
        for (label k = lo[2]; k <= hi[2]; ++k)
            for (label j = lo[1]; j <= hi[1]; ++j)
                for (label i = lo[0]; i <= hi[0]; ++i)
                    ++binStart_[(k*ny_ + j)*nx_ + i + 1];
    }
    for (label b = 0; b < nBins(); ++b)
    {
        binStart_[b + 1] += binStart_[b];
    }
    binCells_.setSize(binStart_[nBins()]);
    labelList next(SubList<label>(binStart_, nBins()));
    forAll(cellBounds_, celli)
    {
        label lo[3], hi[3];
        binRange(cellBounds_[celli], lo, hi);
        for (label k = lo[2]; k <= hi[2]; ++k)
            for (label j = lo[1]; j <= hi[1]; ++j)
                for (label i = lo[0]; i <= hi[0]; ++i)
                    binCells_[next[(k*ny_ + j)*nx_ + i]++] = celli;
    }
}


// * * * * * * * * * * * * * * * Member Functions  * * * * * * * * * * * * * //

Foam::label Foam::diefill::cellLocator::findCell(const point& p) const
{
    if (nBins() == 0 || !bounds_.contains(p))
    {
        return -1;
    }
    const point& o = bounds_.min();
    const label b =
        (binIndex(p.z(), o.z(), binsPerMetre_.z(), nz_)*ny_
       + binIndex(p.y(), o.y(), binsPerMetre_.y(), ny_))*nx_
       + binIndex(p.x(), o.x(), binsPerMetre_.x(), nx_);
    for (label k = binStart_[b]; k < binStart_[b + 1]; ++k)
    {
        const label celli = binCells_[k];
        if
        (
            cellBounds_[celli].contains(p)
         && mesh_.pointInCell(p, celli, polyMesh::CELL_TETS)
        )
        {
            return celli;
        }
    }
    return -1;
}


Foam::scalar Foam::diefill::cellLocator::cellsPerBin() const
{
    return nBins() ? scalar(binCells_.size())/nBins() : 0;
}


// ************************************************************************* //
