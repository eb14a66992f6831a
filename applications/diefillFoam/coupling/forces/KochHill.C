#include "KochHill.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(KochHill, 0);
    addToRunTimeSelectionTable(particleForce, KochHill, dictionary);
}
}

Foam::diefill::KochHill::KochHill(const dictionary& coeffs)
:
    dragForce(coeffs)
{
    checkKeywords(coeffs, wordList());  // no coefficients
}


Foam::scalar Foam::diefill::KochHill::beta(const particleFluidState& s) const
{
    const scalar d = s.diameter;
    const scalar alpha = s.voidFraction;
    const scalar phi = max(1 - alpha, SMALL);

    // F0: Stokes-flow resistance of the array (dilute fit below phi = 0.4)
    const scalar F0 =
        phi < 0.4
      ? (1 + 3*sqrt(0.5*phi) + 135.0/64.0*phi*log(phi) + 16.14*phi)
       /(1 + 0.681*phi - 8.48*sqr(phi) + 8.16*pow3(phi))
      : 10*phi/pow3(alpha);

    const scalar F3 = 0.0673 + 0.212*phi + 0.0232/pow5(alpha);

    // Reynolds number on the particle radius
    const scalar ReRadius = 0.5*s.reynolds();

    // beta per unit volume 18 mu alpha^2 phi/d^2 (F0 + F3 Re/2); per particle
    // times V_p/phi
    return 18*s.fluidViscosity*sqr(alpha)*s.volume/sqr(d)*(F0 + 0.5*F3*ReRadius);
}
