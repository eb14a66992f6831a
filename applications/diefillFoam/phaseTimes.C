#include "phaseTimes.H"

#include "Pstream.H"
#include "ops.H"

#include <cstdio>

Foam::diefill::phaseTimes::phaseTimes()
:
    since_(clock::now()),
    loopStart_(since_)
{}


void Foam::diefill::phaseTimes::start(phase p)
{
    stop();
    current_ = p;
    since_ = clock::now();
}


void Foam::diefill::phaseTimes::stop()
{
    const clock::time_point now = clock::now();
    if (current_ >= 0)
    {
        seconds_[current_] += std::chrono::duration<double>(now - since_).count();
    }
    current_ = -1;
    since_ = now;
}


void Foam::diefill::phaseTimes::report
(
    Ostream& os,
    double demExchangeSeconds
) const
{
    const double loop =
        std::chrono::duration<double>(clock::now() - loopStart_).count();

    // The rows: the four phases, the DEM's exchanges, the rest of the loop
    // (Courant number, time-step control, progress line)
    const char* names[] =
    {
        "DEM (particle steps)",
        "  of which in the DEM's exchanges",
        "coupling (void fraction, drag)",
        "air (PIMPLE loop)",
        "output (fields, restart files)",
        "rest (time control, progress)"
    };
    double mine[6] =
    {
        seconds_[dem], demExchangeSeconds, seconds_[coupling], seconds_[air],
        seconds_[output], 0
    };
    mine[5] = loop - seconds_[dem] - seconds_[coupling] - seconds_[air]
        - seconds_[output];

    double least[6], most[6];
    for (int k = 0; k < 6; ++k)
    {
        least[k] = mine[k];
        most[k] = mine[k];
        if (Pstream::parRun())
        {
            reduce(least[k], minOp<double>());
            reduce(most[k], maxOp<double>());
        }
    }
    double wall = loop;
    if (Pstream::parRun())
    {
        reduce(wall, maxOp<double>());
    }
    if (!Pstream::master())
    {
        return;
    }

    char line[200];
    std::snprintf
    (
        line, sizeof(line), "Wall time of the time loop, %.4g s%s",
        wall,
        Pstream::parRun()
      ? (" (" + std::to_string(Pstream::nProcs())
          + " ranks: the most over ranks, and least - most):").c_str()
      : ":"
    );
    os << line << nl;
    for (int k = 0; k < 6; ++k)
    {
        // Undecomposed, the DEM has no exchanges
        if (k == 1 && most[k] == 0)
        {
            continue;
        }
        if (Pstream::parRun())
        {
            std::snprintf
            (
                line, sizeof(line), "    %-34s %9.4g s %5.1f %%  (%.4g - %.4g s)",
                names[k], most[k], wall > 0 ? 100*most[k]/wall : 0.0,
                least[k], most[k]
            );
        }
        else
        {
            std::snprintf
            (
                line, sizeof(line), "    %-34s %9.4g s %5.1f %%",
                names[k], mine[k], wall > 0 ? 100*mine[k]/wall : 0.0
            );
        }
        os << line << nl;
    }
    os << endl;
}
