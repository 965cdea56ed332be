#pragma once
// MPI for the command line: `mpirun -n N parcelscope compare ...` splits the
// run into N spatial shards (pipeline/Shards.h), one per rank; rank 0 merges
// them and writes what a single process writes. A build without MPI, or a
// program not started by mpirun, runs as one process.
#include <functional>
#include <string>
#include <vector>

#include "parcelscope/pipeline/Shards.h"

namespace parcelscope::cli {

/// Initialises MPI when the program was started by an MPI launcher (and the
/// build has MPI); finalises it on destruction.
class MpiSession {
public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

/// This process's rank and the number of ranks (0 and 1 without MPI).
int mpiRank();
int mpiSize();

/// The reading of a rank: its window only, the frame sample exchanged.
pipeline::ShardReading rankReading();

/// Sends this rank's encoded part to rank 0 (a rank other than 0).
void sendPart(const std::string& bytes);
/// On rank 0: every other rank's encoded part, handed to `take` one at a
/// time as it arrives, in rank order (each part's bytes are freed before the
/// next arrives).
void receiveParts(const std::function<void(int rank, std::string bytes)>& take);

/// Stops every rank at once after printing `message` (a rank's failure).
[[noreturn]] void abortRanks(const std::string& message);

}  // namespace parcelscope::cli
