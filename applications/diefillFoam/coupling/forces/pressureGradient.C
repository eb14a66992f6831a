#include "pressureGradient.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(pressureGradient, 0);
    addToRunTimeSelectionTable(particleForce, pressureGradient, dictionary);
}
}

Foam::diefill::pressureGradient::pressureGradient(const dictionary& coeffs)
:
    particleForce(coeffs)
{
    checkKeywords(coeffs, wordList());  // no coefficients
}


Foam::vector Foam::diefill::pressureGradient::explicitForce
(
    const particleFluidState& s
) const
{
    if (s.model == momentumCouplingModel::A)
    {
        return -s.volume*s.pressureGradient;
    }
    return -s.fluidDensity*s.volume*s.gravity;
}
