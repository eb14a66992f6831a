#include "dividedVoidFraction.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(dividedVoidFraction, 0);
    addToRunTimeSelectionTable(voidFractionModel, dividedVoidFraction, dictionary);
}
}

Foam::diefill::dividedVoidFraction::dividedVoidFraction
(
    const fvMesh& mesh,
    const dictionary& coeffs
)
:
    voidFractionModel(mesh, coeffs)
{
    checkKeywords(coeffs, {"pointsPerDiameter"});
    const label n = coeffs.getOrDefault<label>("pointsPerDiameter", 4);
    // n^3 lattice points per particle, every fluid step: 100000 hung the run.
    if (n < 2 || n > 32)
    {
        FatalIOErrorInFunction(coeffs)
            << "pointsPerDiameter must lie in [2, 32] (about n^3/2 points per"
            << " particle), got " << n << exit(FatalIOError);
    }

    // Lattice points at -1 + (i + 1/2) 2/n in each direction of the unit cube
    // around the unit sphere; keep those inside.
    DynamicList<vector> pts;
    const scalar h = 2.0/n;
    for (label i = 0; i < n; ++i)
    {
        for (label j = 0; j < n; ++j)
        {
            for (label k = 0; k < n; ++k)
            {
                const vector x
                (
                    -1 + (i + 0.5)*h,
                    -1 + (j + 0.5)*h,
                    -1 + (k + 0.5)*h
                );
                if (magSqr(x) <= 1)
                {
                    pts.append(x);
                }
            }
        }
    }
    unitPoints_.transfer(pts);

    Info<< "        " << unitPoints_.size() << " satellite points per particle"
        << endl;
}


void Foam::diefill::dividedVoidFraction::distribute
(
    const point& centre,
    scalar radius,
    label& hint,
    DynamicList<label>& cells,
    DynamicList<scalar>& weights
) const
{
    if (outsideLocalBounds(centre, radius))
    {
        return;
    }

    const scalar share = 1.0/unitPoints_.size();
    label near = findCell(centre, hint);
    if (near >= 0)
    {
        hint = near;
    }
    const label first = cells.size();

    for (const vector& u : unitPoints_)
    {
        const label celli = findCell(centre + radius*u, near);
        if (celli < 0)
        {
            continue;
        }
        near = celli;

        // Merge with an entry of the same cell (few cells per particle)
        bool merged = false;
        for (label k = first; k < cells.size(); ++k)
        {
            if (cells[k] == celli)
            {
                weights[k] += share;
                merged = true;
                break;
            }
        }
        if (!merged)
        {
            cells.append(celli);
            weights.append(share);
        }
    }
}
