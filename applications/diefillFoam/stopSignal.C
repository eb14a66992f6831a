#include "stopSignal.H"

#include "label.H"
#include "scalar.H"
#include "Pstream.H"
#include "PstreamReduceOps.H"

#include <csignal>

namespace
{
    volatile std::sig_atomic_t received = 0;

    extern "C" void requestStop(int signal)
    {
        received = signal;
        std::signal(signal, SIG_DFL);
    }
}


Foam::diefill::stopSignal::stopSignal()
{
    std::signal(SIGINT, requestStop);
    std::signal(SIGTERM, requestStop);
}


bool Foam::diefill::stopSignal::requested() const
{
    return returnReduce(received != 0, orOp<bool>());
}


int Foam::diefill::stopSignal::signal() const
{
    return returnReduce(label(received), maxOp<label>());
}


Foam::word Foam::diefill::stopSignal::name() const
{
    return signal() == SIGINT ? word("SIGINT (Ctrl-C)") : word("SIGTERM");
}
