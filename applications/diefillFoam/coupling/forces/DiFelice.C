#include "DiFelice.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"
#include "mathematicalConstants.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(DiFelice, 0);
    addToRunTimeSelectionTable(particleForce, DiFelice, dictionary);
}
}

Foam::diefill::DiFelice::DiFelice(const dictionary& coeffs)
:
    dragForce(coeffs)
{
    checkKeywords(coeffs, wordList());  // no coefficients
}


Foam::scalar Foam::diefill::DiFelice::beta(const particleFluidState& s) const
{
    const scalar d = s.diameter;
    const scalar alpha = s.voidFraction;
    const scalar slip = mag(s.slipVelocity());

    // C_D |u - v| without dividing by Re, so that slip -> 0 stays finite:
    // sqrt(C_D |u-v|) = 0.63 sqrt|u-v| + 4.8 sqrt(mu/(alpha rho d))
    const scalar sqrtCdSlip =
        0.63*sqrt(slip) + 4.8*sqrt(s.fluidViscosity/(alpha*s.fluidDensity*d));

    const scalar Re = max(s.reynolds(), VSMALL);
    const scalar chi = 3.7 - 0.65*exp(-0.5*sqr(1.5 - log10(Re)));

    // Projected area of the particles of diameter d in the volume V_p:
    // pi d^2/4 times V_p/(pi d^3/6) (one particle unless coarse grained)
    const scalar area = 1.5*s.volume/d;

    // F = 1/2 C_D rho A alpha^2 |u-v| (u-v) alpha^-chi
    return 0.5*sqr(sqrtCdSlip)*s.fluidDensity*area*pow(alpha, 2 - chi);
}
