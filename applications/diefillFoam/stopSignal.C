#include "stopSignal.H"

#include "label.H"
#include "scalar.H"
#include "Pstream.H"
#include "PstreamReduceOps.H"

#include "demLib/stop_signal.hpp"


Foam::diefill::stopSignal::stopSignal()
{
    dem::catchStopSignals();
}


bool Foam::diefill::stopSignal::requested() const
{
    return returnReduce(dem::stopSignalReceived() != 0, orOp<bool>());
}


int Foam::diefill::stopSignal::signal() const
{
    return returnReduce(label(dem::stopSignalReceived()), maxOp<label>());
}


Foam::word Foam::diefill::stopSignal::name() const
{
    return word(dem::stopSignalName(signal()));
}
