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
    reportInterval_(reportInterval),
    clock_(),
    lastReport_(0),
    // A gap of more than three report intervals between reports is a stop
    // (fullRun pause): left out of the pace, so the ETA is right at once.
    estimate_(runTime.value(), runTime.endTime().value(), 600, reportInterval)
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

    estimate_.add(elapsed, runTime_.value());
    const scalar left = estimate_.secondsLeft();

    Info<< "Progress: t = " << runTime_.timeName() << " s of " << endTime
        << " s (" << std::round(1000*estimate_.fractionDone())/10 << " %), elapsed "
        << formatSeconds(elapsed).c_str();
    if (left >= 0)
    {
        Info<< ", ETA " << formatSeconds(left).c_str();
    }
    Info<< endl;
}
