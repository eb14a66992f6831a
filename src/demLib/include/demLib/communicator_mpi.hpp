#pragma once
// The MPI side of dem::Communicator: include this (and so mpi.h) only where an
// MPI_Comm is at hand.  Available when demLib was built with MPI
// (DEMLIB_HAS_MPI in demLib/config.hpp).
#include "demLib/communicator.hpp"

#if !DEMLIB_HAS_MPI
#error "demLib was built without MPI (DEMLIB_MPI=OFF or MPI not found): communicator_mpi.hpp is unavailable"
#endif

#include <mpi.h>

namespace dem {

struct Communicator::MpiHandle {
    MPI_Comm comm;
};

// A demLib communicator over `comm` (not duplicated: demLib's messages use their
// own tags on it and never leave any pending).  MPI must already be initialised
// by the caller -- demLib never calls MPI_Init or MPI_Finalize -- otherwise this
// throws dem::RuntimeError saying so.
Communicator communicatorFromMpi(MPI_Comm comm);

// The MPI_Comm behind an MPI communicator (MPI_COMM_SELF for a serial one).
MPI_Comm mpiCommOf(const Communicator& communicator);

}  // namespace dem
