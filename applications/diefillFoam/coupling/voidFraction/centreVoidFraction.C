#include "centreVoidFraction.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(centreVoidFraction, 0);
    addToRunTimeSelectionTable(voidFractionModel, centreVoidFraction, dictionary);
}
}

Foam::diefill::centreVoidFraction::centreVoidFraction
(
    const fvMesh& mesh,
    const dictionary& coeffs
)
:
    voidFractionModel(mesh, coeffs)
{
    checkKeywords(coeffs, wordList());  // no coefficients
}


void Foam::diefill::centreVoidFraction::distribute
(
    const point& centre,
    scalar radius,
    label& hint,
    DynamicList<label>& cells,
    DynamicList<scalar>& weights
) const
{
    if (outsideLocalBounds(centre, 0))
    {
        return;
    }
    const label celli = findCell(centre, hint);
    if (celli >= 0)
    {
        hint = celli;
        cells.append(celli);
        weights.append(1);
    }
}
