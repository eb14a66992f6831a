/* The DEM step's exchange round between 2 MPI ranks, timed alone (docs/performance.md (f), "The
 * DEM's rounds"): one MPI_Irecv/MPI_Isend pair of N bytes, a blocking MPI_Allreduce of a flag,
 * MPI_Waitall, as demLib's Communicator::exchangeKnownSizesAndAnyTrue makes it each step; with the
 * argument 'iallreduce', the former round (an MPI_Iallreduce posted with the messages, one wait).
 *
 *     mpicc -O2 bench/mpiRound.c -o /tmp/mpiRound
 *     source etc/bashrc; diefill_mpirun -np 2 /tmp/mpiRound [iallreduce]
 *     diefill_mpirun -np 2 --mca btl_vader_eager_limit 65536 /tmp/mpiRound   # a transport setting
 */
#include <mpi.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

int main(int argc, char** argv) {
    MPI_Init(&argc, &argv);
    int rank, size;
    MPI_Comm_rank(MPI_COMM_WORLD, &rank);
    MPI_Comm_size(MPI_COMM_WORLD, &size);
    if (size != 2) {
        if (rank == 0) fprintf(stderr, "mpiRound: run on 2 ranks (mpirun -np 2), not %d\n", size);
        MPI_Finalize();
        return 2;
    }
    const int nonBlocking = argc > 1 && strcmp(argv[1], "iallreduce") == 0;
    if (argc > 1 && !nonBlocking) {
        if (rank == 0) fprintf(stderr, "mpiRound: unknown argument '%s' (expected none or 'iallreduce')\n", argv[1]);
        MPI_Finalize();
        return 2;
    }
    const int sizes[] = {64, 1024, 4096, 8192, 16384, 32768, 65536};
    const int rounds = 20000;
    char* out = calloc(65536, 1);
    char* in = calloc(65536, 1);
    for (int s = 0; s < 7; ++s) {
        MPI_Barrier(MPI_COMM_WORLD);
        const double start = MPI_Wtime();
        for (int k = 0; k < rounds; ++k) {
            MPI_Request requests[3];
            long long mine = 0, any = 0;
            MPI_Irecv(in, sizes[s], MPI_BYTE, 1 - rank, 7, MPI_COMM_WORLD, &requests[0]);
            MPI_Isend(out, sizes[s], MPI_BYTE, 1 - rank, 7, MPI_COMM_WORLD, &requests[1]);
            if (nonBlocking) {
                MPI_Iallreduce(&mine, &any, 1, MPI_LONG_LONG, MPI_LOR, MPI_COMM_WORLD, &requests[2]);
                MPI_Waitall(3, requests, MPI_STATUSES_IGNORE);
            } else {
                MPI_Allreduce(&mine, &any, 1, MPI_LONG_LONG, MPI_LOR, MPI_COMM_WORLD);
                MPI_Waitall(2, requests, MPI_STATUSES_IGNORE);
            }
        }
        const double seconds = MPI_Wtime() - start;
        if (rank == 0) printf("%6d bytes: %.2f us per round (%s)\n", sizes[s], 1e6 * seconds / rounds, nonBlocking ? "MPI_Iallreduce" : "MPI_Allreduce");
    }
    free(out);
    free(in);
    MPI_Finalize();
    return 0;
}
