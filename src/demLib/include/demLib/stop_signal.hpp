#pragma once
// SIGINT (Ctrl-C) and SIGTERM (a batch system's time limit, kill) as a request to
// stop: the programs (demRun, diefillFoam) finish what they are doing, write their
// restart state and exit with 128 + the signal.  A second signal ends the process
// at once (the handler restores the default action).

namespace dem {

// Installs the handlers for SIGINT and SIGTERM.
void catchStopSignals();

// The signal received since, 0 if none.
int stopSignalReceived();

// "SIGINT (Ctrl-C)" or "SIGTERM".
const char* stopSignalName(int signal);

}  // namespace dem
