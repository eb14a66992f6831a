#include "progressReport.H"

#include <cmath>
#include <sstream>

Foam::string Foam::diefill::progressReport::formatSeconds(scalar s)
{
    const long total = std::lround(s);
    std::ostringstream out;
    if (total >= 3600)
    {
        out << total/3600 << " h " << (total % 3600)/60 << " min";
    }
    else if (total >= 60)
    {
        out << total/60 << " min " << total % 60 << " s";
    }
    else
    {
        out << total << " s";
    }
    return out.str();
}


Foam::diefill::progressReport::progressReport
(
    const Time& runTime,
    scalar reportInterval
)
:
    runTime_(runTime),
    startTime_(runTime.value()),
    reportInterval_(reportInterval),
    clock_(),
    lastReport_(0)
{}


void Foam::diefill::progressReport::update()
{
    const scalar elapsed = clock_.elapsedTime();
    const scalar endTime = runTime_.endTime().value();
    const bool atEnd = runTime_.value() >= endTime - 0.5*runTime_.deltaTValue();

    if (!atEnd && elapsed - lastReport_ < reportInterval_)
    {
        return;
    }
    lastReport_ = elapsed;

    const scalar done = runTime_.value() - startTime_;
    const scalar left = endTime - runTime_.value();
    const scalar span = max(endTime - startTime_, SMALL);

    Info<< "Progress: t = " << runTime_.timeName() << " s of " << endTime
        << " s (" << std::round(1000*done/span)/10 << " %), elapsed "
        << formatSeconds(elapsed).c_str();
    if (done > 0)
    {
        Info<< ", ETA " << formatSeconds(elapsed*left/done).c_str();
    }
    Info<< endl;
}
