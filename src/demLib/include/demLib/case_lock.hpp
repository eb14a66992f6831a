#pragma once
// One run at a time in a case folder: an advisory lock (flock) on <case>/.diefill.lock,
// held for the length of the run.  The kernel drops it when the process ends, however it
// ends (kill -9 included), so a lock is never stale; the file keeps the holder's pid and
// command so that a refused second run can name it.
//
// A script that locks the case itself and then starts demRun or diefillFoam in it (a
// tutorial's Allrun, tools/tutorialFunctions.sh) exports DIEFILL_CASE_LOCK=<lock file>:<pid>;
// a run whose case lock is held by that pid runs under its lock.
#include <string>

#include "demLib/error.hpp"

namespace dem {

// The case is locked by another run.  Neither an input error nor a filesystem failure.
class CaseBusyError : public RuntimeError {
public:
    using RuntimeError::RuntimeError;
};

class CaseLock {
public:
    static constexpr const char* fileName = ".diefill.lock";

    // Locks caseDir for `tool` (e.g. "demRun"); throws CaseBusyError naming the holder
    // when another process holds it, RuntimeError when the lock file cannot be created.
    CaseLock(const std::string& caseDir, const std::string& tool);
    ~CaseLock();
    CaseLock(const CaseLock&) = delete;
    CaseLock& operator=(const CaseLock&) = delete;

    // False when the run goes on under the lock of the script that started it.
    bool ownsLock() const { return fd_ >= 0; }

private:
    int fd_ = -1;
};

}  // namespace dem
