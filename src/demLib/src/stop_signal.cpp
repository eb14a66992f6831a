#include "demLib/stop_signal.hpp"

#include <csignal>

namespace dem {

namespace {

volatile std::sig_atomic_t received = 0;

extern "C" void recordStopSignal(int signal) {
    received = signal;
    std::signal(signal, SIG_DFL);
}

}  // namespace

void catchStopSignals() {
    std::signal(SIGINT, recordStopSignal);
    std::signal(SIGTERM, recordStopSignal);
}

int stopSignalReceived() { return received; }

const char* stopSignalName(int signal) { return signal == SIGINT ? "SIGINT (Ctrl-C)" : "SIGTERM"; }

}  // namespace dem
