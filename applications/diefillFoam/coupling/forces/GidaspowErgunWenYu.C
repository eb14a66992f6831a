#include "GidaspowErgunWenYu.H"
#include "addToRunTimeSelectionTable.H"
#include "checkKeywords.H"

namespace Foam
{
namespace diefill
{
    defineTypeNameAndDebug(GidaspowErgunWenYu, 0);
    addToRunTimeSelectionTable(particleForce, GidaspowErgunWenYu, dictionary);
}
}

Foam::diefill::GidaspowErgunWenYu::GidaspowErgunWenYu(const dictionary& coeffs)
:
    dragForce(coeffs),
    switchVoidFraction_(coeffs.getOrDefault<scalar>("switchVoidFraction", 0.8))
{
    checkKeywords(coeffs, {"switchVoidFraction"});
    if (switchVoidFraction_ <= 0 || switchVoidFraction_ >= 1)
    {
        FatalIOErrorInFunction(coeffs)
            << "switchVoidFraction must lie in (0, 1), got "
            << switchVoidFraction_ << exit(FatalIOError);
    }
}


Foam::scalar Foam::diefill::GidaspowErgunWenYu::beta
(
    const particleFluidState& s
) const
{
    const scalar d = s.diameter;
    const scalar alpha = s.voidFraction;
    const scalar alphaS = 1 - alpha;
    const scalar slip = mag(s.slipVelocity());
    const scalar rho = s.fluidDensity;
    const scalar mu = s.fluidViscosity;

    if (alpha <= switchVoidFraction_)
    {
        // Ergun per unit volume: 150 alphaS^2 mu/(alpha d^2) + 1.75 alphaS rho |u-v|/d;
        // per particle: times V_p/alphaS
        return s.volume*(150*alphaS*mu/(alpha*sqr(d)) + 1.75*rho*slip/d);
    }

    // Wen & Yu: 3/4 C_D rho alpha^-1.65 |u-v| V_p/d with the Schiller-Naumann
    // C_D = 24/Re (1 + 0.15 Re^0.687) (Re < 1000), 0.44 above;
    // C_D |u-v| written without dividing by Re so that slip -> 0 stays finite.
    const scalar Re = s.reynolds();
    const scalar CdSlip =
        Re < 1000
      ? 24*mu/(alpha*rho*d)*(1 + 0.15*pow(Re, 0.687))
      : 0.44*slip;

    return 0.75*CdSlip*rho*pow(alpha, -1.65)*s.volume/d;
}
